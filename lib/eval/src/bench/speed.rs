//! `pis-bench speed`: what time buys in quality. Compile (inference) time per parameter
//! point against PSNR across conjugate-gradient iteration caps: the whole set inferred once
//! per cap (texture-coordinate optimization, render matrices and every solve, wall clock),
//! then packed at one ratio; PSNR predicted through the hardware model over covered pixels,
//! for the textures as solved and after coding.
//!
//! Playback: the set packed at that ratio with each codec, played by the player runtime
//! along the zig-zag path at texture-resolution reduction factors 1, 2 and 4: mean and worst
//! frame time against the played frames' PSNR (see [`super::playback`]). Without a GPU
//! adapter the report says why and charts compile time only.

use std::path::PathBuf;

use crate::chart::{Chart, Series};
use crate::report::{Csv, Stamp};
use anyhow::anyhow;
use pis_codec::CodecId;
use serde::Serialize;

use super::output::{ensure_dir, record, write_chart};
use super::playback::{gpu, measure, PlaybackRow};
use pis_pack::{Exit, Failure};
use pis_pack::{Inferred, PackRequest, PackSettings, StderrProgress};

#[derive(Clone, Debug)]
pub struct SpeedRequest {
    pub input: PathBuf,
    pub scene: Option<PathBuf>,
    /// Iteration caps per colour channel of every solve.
    pub caps: Vec<u32>,
    /// Ratio of the packs whose PSNR is reported.
    pub ratio: f64,
    pub out: PathBuf,
    pub resolution: Option<(u32, u32)>,
    pub spp: Option<u32>,
    pub preset: Option<String>,
    pub max_texture: u32,
    pub record: bool,
}

#[derive(Clone, Debug, Serialize)]
pub struct CompileRow {
    pub max_iterations: u32,
    /// Inference wall clock per parameter point.
    pub ms_per_point: f64,
    pub solver_iterations: u64,
    pub psnr_db_solved: f64,
    pub psnr_db: f64,
    pub ratio: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct SpeedReport {
    pub scene: String,
    pub points: usize,
    pub compile: Vec<CompileRow>,
    pub playback: Vec<PlaybackRow>,
    /// Why playback is not measured, when it is not.
    pub playback_skipped: Option<String>,
    pub csv: String,
    pub svg: String,
    pub stamp: Stamp,
}

pub fn check(req: &SpeedRequest) -> Result<(), Failure> {
    if !req.input.exists() {
        return Err(Failure::new(
            Exit::Io,
            anyhow!("{}: no such set directory or scene file", req.input.display()),
        ));
    }
    if req.caps.is_empty() || req.caps.contains(&0) {
        return Err(Failure::new(
            Exit::Usage,
            anyhow!("--caps needs iteration caps of at least 1"),
        ));
    }
    if !(req.ratio.is_finite() && req.ratio >= 1.0) {
        return Err(Failure::new(
            Exit::Usage,
            anyhow!("--ratio must be at least 1, got {}", req.ratio),
        ));
    }
    Ok(())
}

/// The codecs whose files are played.
const PLAYED: [CodecId; 2] = [CodecId::Wavelet, CodecId::Dct];

/// Writes speed.csv and speed.svg: a row per CG cap and per playback measurement, the
/// compile points and the playback frame times as series.
fn write_speed(
    req: &SpeedRequest,
    scene: &str,
    stamp: &Stamp,
    rows: &[CompileRow],
    playback: &[PlaybackRow],
) -> Result<(PathBuf, PathBuf), Failure> {
    let mut csv = Csv::new(&[
        "measure",
        "max_iterations",
        "ms_per_point",
        "solver_iterations",
        "psnr_db_solved",
        "psnr_db",
        "ratio",
    ]);
    for r in rows {
        csv.push(vec![
            "compile".into(),
            r.max_iterations.to_string(),
            format!("{:.2}", r.ms_per_point),
            r.solver_iterations.to_string(),
            format!("{:.3}", r.psnr_db_solved),
            format!("{:.3}", r.psnr_db),
            format!("{:.2}", r.ratio),
        ]);
    }
    for p in playback {
        csv.push(vec![
            format!("playback {} reduction {}", p.codec, p.reduction),
            String::new(),
            format!("mean {:.2} worst {:.2}", p.frame_ms_mean, p.frame_ms_worst),
            p.frames.to_string(),
            String::new(),
            format!("{:.3}", p.psnr_db),
            format!("{}", req.ratio),
        ]);
    }
    let mut series = vec![
        Series {
            name: "compile: textures as solved (ms per point)".into(),
            points: rows.iter().map(|r| (r.ms_per_point, r.psnr_db_solved)).collect(),
        },
        Series {
            name: format!("compile: wavelet at {}:1 (ms per point)", req.ratio),
            points: rows.iter().map(|r| (r.ms_per_point, r.psnr_db)).collect(),
        },
    ];
    for codec in PLAYED.map(CodecId::name) {
        let mine: Vec<&PlaybackRow> = playback.iter().filter(|p| p.codec == codec).collect();
        if !mine.is_empty() {
            series.push(Series {
                name: format!("playback {codec}: mean frame ms (reduction 1, 2, 4)"),
                points: mine.iter().map(|p| (p.frame_ms_mean, p.psnr_db)).collect(),
            });
            series.push(Series {
                name: format!("playback {codec}: worst frame ms"),
                points: mine.iter().map(|p| (p.frame_ms_worst, p.psnr_db)).collect(),
            });
        }
    }
    let caps: Vec<String> = req.caps.iter().map(u32::to_string).collect();
    let chart = Chart {
        title: format!("Time vs PSNR — {scene}"),
        subtitle: format!("compile: inference per point across CG caps {}, PSNR predicted over covered pixels; playback: player frames, whole-image PSNR vs the set", caps.join(", ")),
        x_label: "milliseconds (compile: per parameter point; playback: per frame), log".into(),
        y_label: "PSNR (dB)".into(),
        x_log: true,
        stamp: stamp.lines(),
    };
    write_chart(&req.out, "speed", &csv, &chart, &series).map_err(|e| Failure::new(Exit::Io, e))
}

pub fn run(req: &SpeedRequest) -> Result<SpeedReport, Failure> {
    check(req)?;
    ensure_dir(&req.out).map_err(|e| Failure::new(Exit::Io, e))?;
    let settings = PackSettings {
        max_texture: req.max_texture,
        resolution: req.resolution,
        spp: req.spp,
        preset: req.preset.clone(),
        ..super::pack_defaults().with_ratio(req.ratio)
    };
    let base = PackRequest {
        scene: req.scene.clone(),
        ..PackRequest::new(req.input.clone(), req.out.join("unused.pis"), settings)
    };
    let mut rows = Vec::new();
    let mut scene = String::new();
    let mut points = 0;
    let mut last = None;
    for &cap in &req.caps {
        let inf = Inferred::new(&base.with(|s| s.max_iterations = Some(cap)), &StderrProgress)?;
        let p = inf.pack_point(&base)?;
        points = inf.points();
        let set = &inf.set;
        scene = format!(
            "{} ({} points, {}x{})",
            set.scene.name,
            set.samples.len(),
            set.resolution.0,
            set.resolution.1
        );
        let row = CompileRow {
            max_iterations: cap,
            ms_per_point: inf.infer_ms / points.max(1) as f64,
            solver_iterations: inf.solver_iterations(),
            psnr_db_solved: p.psnr_db_solved,
            psnr_db: p.psnr_db,
            ratio: p.ratio(),
        };
        eprintln!("pis-bench: speed: cap {cap:>5}: {:8.1} ms per point, {} iterations, {:.2} dB solved, {:.2} dB at {:.0}:1",
                  row.ms_per_point, row.solver_iterations, row.psnr_db_solved, row.psnr_db, row.ratio);
        rows.push(row);
        last = Some(inf);
    }
    let (mut playback, mut playback_skipped) = (Vec::new(), None);
    match (gpu(), last) {
        (Ok(g), Some(inf)) => {
            for codec in PLAYED {
                let file = req.out.join(format!("speed-{}.pis", codec.name()));
                inf.write(&PackRequest { output: file.clone(), ..base.with(|s| s.codec = codec) })?;
                playback.extend(
                    measure(&g, &file, inf.set_dir(), codec.name(), &[1, 2, 4])
                        .map_err(|e| Failure::new(Exit::Runtime, e))?,
                );
            }
        }
        (Err(e), _) => {
            eprintln!("pis-bench: speed: playback skipped: {e}");
            playback_skipped = Some(e.to_string());
        }
        (_, None) => {}
    }
    let stamp = Stamp::here(&scene);
    let (c, s) = write_speed(req, &scene, &stamp, &rows, &playback)?;
    let report = SpeedReport {
        scene,
        points,
        compile: rows,
        csv: c.display().to_string(),
        svg: s.display().to_string(),
        stamp,
        playback,
        playback_skipped,
    };
    if req.record {
        let mut summary: Vec<String> = report
            .compile
            .iter()
            .map(|r| {
                format!(
                    "cap {}: {:.0} ms/point, {:.2} dB",
                    r.max_iterations, r.ms_per_point, r.psnr_db
                )
            })
            .collect();
        summary.extend(report.playback.iter().map(|p| {
            format!(
                "play {} r{}: {:.1}/{:.1} ms mean/worst, {:.2} dB",
                p.codec, p.reduction, p.frame_ms_mean, p.frame_ms_worst, p.psnr_db
            )
        }));
        record("speed", &report.stamp, &summary.join("; "))
            .map_err(|e| Failure::new(Exit::Io, e))?;
    }
    Ok(report)
}

pub fn print(r: &SpeedReport, out: &mut impl std::io::Write) -> std::io::Result<()> {
    writeln!(out, "speed: {}", r.scene)?;
    for c in &r.compile {
        writeln!(out, "  cap {:>5}: {:9.1} ms/point  {:>9} iterations  solved {:6.2} dB  coded {:6.2} dB at {:.0}:1",
                 c.max_iterations, c.ms_per_point, c.solver_iterations, c.psnr_db_solved, c.psnr_db, c.ratio)?;
    }
    for p in &r.playback {
        writeln!(out, "  playback {:<8} reduction {}: {:8.2} ms mean, {:8.2} ms worst over {} frames, {:6.2} dB ({:.2} dB covered)",
                 p.codec, p.reduction, p.frame_ms_mean, p.frame_ms_worst, p.frames, p.psnr_db, p.covered_psnr_db)?;
    }
    if let Some(p) = &r.playback_skipped {
        writeln!(out, "  playback skipped: {p}")?;
    }
    writeln!(out, "  wrote {} and {}", r.csv, r.svg)
}
