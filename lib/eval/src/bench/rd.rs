//! `pis-bench rd`: compression ratio against PSNR on one set, for PIS and the baselines
//! (thesis 4.8, figures 4.9–4.13, table 4.2).
//!
//! Curves: PIS with the wavelet and the DCT codec; PIS with the full instead of the adaptive
//! pyramid; PIS with one combined lighting layer instead of separate diffuse and specular
//! layers; MPEG-texture (the inferred textures as x265 videos along the zig-zag path,
//! rendered through the hardware model); and view-based video of the gold-standard images
//! along the zig-zag path with x265 and AV1. Every method gets the byte budget raw image
//! bytes / ratio; the chart's x axis is the ratio each method achieved.
//!
//! PIS and MPEG-texture PSNR is predicted through the hardware model over the pixels the
//! objects cover (as `pis-pack` reports it); view-based PSNR is over the whole image. Both
//! are on display values (crate::metrics) against the gold standard.

use std::path::{Path, PathBuf};
use std::time::Instant;

use crate::baselines::video::{available, VideoCodec};
use crate::chart::{Chart, Series};
use crate::report::{Csv, Stamp};
use anyhow::anyhow;
use pis_codec::CodecId;
use serde::Serialize;

use super::mpeg_texture::texture_point;
use super::output::{ensure_dir, record, write_chart};
use super::view_video::{view_frames, view_point};
use pis_pack::{Exit, Failure};
use pis_pack::{Inferred, LayerMode, PackRequest, PackSettings, PyramidMode, StderrProgress};

/// What to measure.
#[derive(Clone, Debug)]
pub struct RdRequest {
    /// A ray-traced set directory or a scene.toml (traced first, as pis-pack does).
    pub input: PathBuf,
    pub scene: Option<PathBuf>,
    pub ratios: Vec<f64>,
    pub out: PathBuf,
    pub resolution: Option<(u32, u32)>,
    pub spp: Option<u32>,
    /// Largest texture side of the PIS inference.
    pub max_texture: u32,
    /// Tracing a scene.toml: a `[preset.NAME]`.
    pub preset: Option<String>,
    /// Record a row in docs/benchmarks/bench.md.
    pub record: bool,
    /// The methods to run (empty: all of [`METHODS`]).
    pub methods: Vec<String>,
    /// The PIS packs' max-MSE constraint (thesis 4.8), as `pis-pack --max-mse-ratio`.
    pub max_mse: pis_pack::MaxMse,
    /// The PIS packs' block staggering, as `pis-pack --stagger`.
    pub stagger: pis_pack::Stagger,
}

/// One measured point.
#[derive(Clone, Debug, Serialize)]
pub struct RdRow {
    pub method: String,
    pub target_ratio: f64,
    /// Raw image bytes / bytes spent (PIS: level images; video: elementary streams).
    pub ratio: f64,
    pub bytes: usize,
    pub budget: usize,
    pub psnr_db: f64,
    /// `whole-image-played` (PIS: the file played by the player, whole frames against the
    /// set's images), `covered-predicted` (through the hardware model over covered pixels;
    /// PIS without a GPU adapter, and MPEG-texture) or `whole-image` (decoded video).
    pub psnr_scope: String,
    /// PIS: the PSNR pis-pack predicts through the hardware model over covered pixels.
    pub psnr_db_predicted: Option<f64>,
    /// PIS played: PSNR over the pixels the objects cover.
    pub psnr_db_covered: Option<f64>,
    /// PIS: raw / whole container bytes; null for the others.
    pub file_ratio: Option<f64>,
    /// The encoder setting that met the budget (CRF), when one was searched.
    pub crf: Option<f64>,
    /// False when the method could not spend as little as the budget.
    pub reached: bool,
    pub ms: f64,
}

/// The report (`--json`).
#[derive(Clone, Debug, Serialize)]
pub struct RdReport {
    pub scene: String,
    pub points: usize,
    pub resolution: [u32; 2],
    pub raw_image_bytes: u64,
    pub rows: Vec<RdRow>,
    /// Methods left out and why.
    pub skipped: Vec<String>,
    pub csv: String,
    pub svg: String,
    pub stamp: Stamp,
    pub notes: Vec<String>,
}

/// Every method's curve name, in chart order.
pub const METHODS: [&str; 7] = [
    "pis-wavelet",
    "pis-dct",
    "pis-wavelet-full-pyramid",
    "pis-wavelet-combined-layers",
    "mpeg-texture-x265",
    "view-x265",
    "view-av1",
];

fn pack_request(req: &RdRequest) -> PackRequest {
    let settings = PackSettings {
        max_texture: req.max_texture,
        resolution: req.resolution,
        spp: req.spp,
        preset: req.preset.clone(),
        max_mse: req.max_mse,
        stagger: req.stagger,
        ..super::pack_defaults()
    };
    PackRequest {
        scene: req.scene.clone(),
        ..PackRequest::new(req.input.clone(), req.out.join("unused.pis"), settings)
    }
}

fn runtime(e: anyhow::Error) -> Failure {
    Failure::new(Exit::Runtime, e)
}

/// Checks the request before any work.
pub fn check(req: &RdRequest) -> Result<(), Failure> {
    if !req.input.exists() {
        return Err(Failure::new(
            Exit::Io,
            anyhow!("{}: no such set directory or scene file", req.input.display()),
        ));
    }
    if req.ratios.is_empty() {
        return Err(Failure::new(Exit::Usage, anyhow!("--ratios needs at least one ratio")));
    }
    if let Some(r) = req.ratios.iter().find(|r| !(r.is_finite() && **r >= 1.0)) {
        return Err(Failure::new(
            Exit::Usage,
            anyhow!("--ratios: every ratio must be at least 1, got {r}"),
        ));
    }
    if let Some(m) = req.methods.iter().find(|m| !METHODS.contains(&m.as_str())) {
        return Err(Failure::new(
            Exit::Usage,
            anyhow!("--methods: unknown method {m:?} (one of {})", METHODS.join(", ")),
        ));
    }
    if req.max_texture == 0 || req.max_texture > 16384 {
        return Err(Failure::new(Exit::Usage, anyhow!("--max-texture must be in 1..=16384")));
    }
    Ok(())
}

/// Whether the video baselines may be skipped when ffmpeg lacks an encoder: locally yes
/// (with a message), never under CI (env `CI` set).
fn video_or_skip(
    codec: VideoCodec,
    skipped: &mut Vec<String>,
    method: &str,
) -> Result<bool, Failure> {
    match available(codec) {
        Ok(()) => Ok(true),
        Err(e) if std::env::var_os("CI").is_none() => {
            let why = format!("{method}: skipped: {e} (install ffmpeg with {})", codec.encoder());
            eprintln!("pis-bench: {why}");
            skipped.push(why);
            Ok(false)
        }
        Err(e) => Err(Failure::new(
            Exit::NotSupported,
            anyhow!("{method}: {e}; CI requires it (add ffmpeg to the CI packages)"),
        )),
    }
}

/// Runs every method at every ratio and writes rd.csv and rd.svg into the output folder.
pub fn run(req: &RdRequest) -> Result<RdReport, Failure> {
    check(req)?;
    ensure_dir(&req.out).map_err(|e| Failure::new(Exit::Io, e))?;
    let base = pack_request(req);
    eprintln!("pis-bench: rd: loading and inferring (separate lighting layers)");
    let separate = Inferred::new(&base, &StderrProgress)?;
    let raw = separate.raw_image_bytes();
    let mut rows = Vec::new();
    let mut skipped = Vec::new();
    let budget = |r: f64| (raw as f64 / r) as usize;
    let wanted = |m: &str| req.methods.is_empty() || req.methods.iter().any(|x| x == m);
    let gpu = match super::playback::gpu() {
        Ok(g) => Some(g),
        Err(e) => {
            let why = format!("PIS points: {e}; PSNR predicted through the hardware model over covered pixels instead of played");
            eprintln!("pis-bench: rd: {why}");
            skipped.push(why);
            None
        }
    };
    let pis = |name: &str,
               inf: &Inferred,
               codec: CodecId,
               pyramid: PyramidMode,
               rows: &mut Vec<RdRow>,
               skipped: &mut Vec<String>|
     -> Result<(), Failure> {
        if !wanted(name) {
            return Ok(());
        }
        for &r in &req.ratios {
            let preq = base.with(|s| {
                s.target = pis_pack::Target::Ratio(r);
                s.codec = codec;
                s.pyramid = pyramid;
            });
            // A budget below what the level images' headers need is a point the method
            // cannot reach: reported, not fatal.
            let p = match inf.pack_point(&preq) {
                Ok(p) => p,
                Err(f) if f.exit == Exit::Runtime => {
                    let why = format!("{name} at {r}:1: not packed: {}", f.error);
                    eprintln!("pis-bench: rd: {why}");
                    skipped.push(why);
                    continue;
                }
                Err(f) => return Err(f),
            };
            let played = match &gpu {
                Some(g) => {
                    let file = req.out.join(format!(".rd-{name}-{r}.pis"));
                    inf.write(&PackRequest { output: file.clone(), ..preq.clone() })?;
                    let c = super::playback::played_psnr(g, &file, inf.set_dir());
                    let _ = std::fs::remove_file(&file);
                    Some(c.map_err(runtime)?)
                }
                None => None,
            };
            let (psnr, scope) =
                played.map_or((p.psnr_db, "covered-predicted"), |c| (c.0, "whole-image-played"));
            eprintln!("pis-bench: rd: {name:<28} {r:>7.1}:1 → {:>7.1}:1  {psnr:6.2} dB {scope} (predicted {:.2} dB)", p.ratio(), p.psnr_db);
            rows.push(RdRow {
                method: name.into(),
                target_ratio: r,
                ratio: p.ratio(),
                bytes: p.texture_bytes,
                budget: budget(r),
                psnr_db: psnr,
                psnr_scope: scope.into(),
                psnr_db_predicted: Some(p.psnr_db),
                psnr_db_covered: played.map(|c| c.1),
                file_ratio: Some(p.file_ratio()),
                crf: None,
                reached: p.texture_bytes <= budget(r) + budget(r) / 20,
                ms: p.encode_ms,
            });
        }
        Ok(())
    };
    pis(
        "pis-wavelet",
        &separate,
        CodecId::Wavelet,
        PyramidMode::Adaptive,
        &mut rows,
        &mut skipped,
    )?;
    pis("pis-dct", &separate, CodecId::Dct, PyramidMode::Adaptive, &mut rows, &mut skipped)?;
    pis(
        "pis-wavelet-full-pyramid",
        &separate,
        CodecId::Wavelet,
        PyramidMode::Full,
        &mut rows,
        &mut skipped,
    )?;
    if wanted("pis-wavelet-combined-layers") {
        eprintln!("pis-bench: rd: inferring again with one combined lighting layer");
        let combined =
            Inferred::new(&base.with(|s| s.layers = LayerMode::Combined), &StderrProgress)?;
        pis(
            "pis-wavelet-combined-layers",
            &combined,
            CodecId::Wavelet,
            PyramidMode::Adaptive,
            &mut rows,
            &mut skipped,
        )?;
    }

    video_points(req, &separate, &wanted, &mut rows, &mut skipped)?;
    let set = &separate.set;
    let scene = format!(
        "{} ({} points, {}x{})",
        set.scene.name,
        set.samples.len(),
        set.resolution.0,
        set.resolution.1
    );
    let stamp = Stamp::here(&scene);
    let (c, s) = write_rd(&req.out, &rows, &scene, &stamp, gpu.is_some())?;
    let notes = vec![
        "budget = raw image bytes (points × width × height × 3) / target ratio; ratio = raw / bytes spent".into(),
        "PIS bytes: level images (as pis-pack's --ratio counts them); file_ratio adds geometry, tables and headers".into(),
        "videos: 8-bit yuv420p, BT.601 limited range, elementary streams (HEVC Annex B, AV1 OBUs), one common CRF searched per point".into(),
        "PIS PSNR: the file played by the player (crate::compare), whole image (psnr_db_covered: covered pixels); without a GPU adapter pis-pack's prediction over covered pixels. mpeg-texture: predicted through the hardware model over covered pixels; view-based: whole image".into(),
    ];
    let report = RdReport {
        scene,
        points: set.samples.len(),
        resolution: [set.resolution.0, set.resolution.1],
        raw_image_bytes: raw,
        rows,
        skipped,
        csv: c.display().to_string(),
        svg: s.display().to_string(),
        stamp,
        notes,
    };
    if req.record {
        record("rd", &report.stamp, &summary(&report)).map_err(|e| Failure::new(Exit::Io, e))?;
    }
    Ok(report)
}

/// The video baselines' points: MPEG-coded textures (x265) and MPEG-coded views (x265, AV1),
/// each skipped (and said so) when its encoder is missing outside CI.
fn video_points(
    req: &RdRequest,
    separate: &Inferred,
    wanted: &dyn Fn(&str) -> bool,
    rows: &mut Vec<RdRow>,
    skipped: &mut Vec<String>,
) -> Result<(), Failure> {
    let raw = separate.raw_image_bytes();
    let budget = |r: f64| (raw as f64 / r) as usize;
    if wanted("mpeg-texture-x265") && video_or_skip(VideoCodec::X265, skipped, "mpeg-texture-x265")?
    {
        for &r in &req.ratios {
            let t = Instant::now();
            let p = texture_point(separate, budget(r)).map_err(runtime)?;
            eprintln!(
                "pis-bench: rd: {:<28} {r:>7.1}:1 → {:>7.1}:1  {:6.2} dB  ({} videos, CRF {:.2})",
                "mpeg-texture-x265",
                raw as f64 / p.bytes as f64,
                p.psnr_db,
                p.videos,
                p.matched.crf
            );
            rows.push(RdRow {
                method: "mpeg-texture-x265".into(),
                target_ratio: r,
                ratio: raw as f64 / p.bytes.max(1) as f64,
                bytes: p.bytes,
                budget: budget(r),
                psnr_db: p.psnr_db,
                psnr_scope: "covered-predicted".into(),
                psnr_db_predicted: None,
                psnr_db_covered: None,
                file_ratio: None,
                crf: Some(p.matched.crf),
                reached: p.matched.reached,
                ms: t.elapsed().as_secs_f64() * 1e3,
            });
        }
    }
    let frames = view_frames(separate).map_err(runtime)?;
    for (codec, name) in [(VideoCodec::X265, "view-x265"), (VideoCodec::Av1, "view-av1")] {
        if !wanted(name) || !video_or_skip(codec, skipped, name)? {
            continue;
        }
        for &r in &req.ratios {
            let t = Instant::now();
            let p = view_point(&frames, codec, budget(r)).map_err(runtime)?;
            eprintln!(
                "pis-bench: rd: {name:<28} {r:>7.1}:1 → {:>7.1}:1  {:6.2} dB  (CRF {:.2})",
                raw as f64 / p.matched.bytes as f64,
                p.psnr_db,
                p.matched.crf
            );
            rows.push(RdRow {
                method: name.into(),
                target_ratio: r,
                ratio: raw as f64 / p.matched.bytes.max(1) as f64,
                bytes: p.matched.bytes,
                budget: budget(r),
                psnr_db: p.psnr_db,
                psnr_scope: "whole-image".into(),
                psnr_db_predicted: None,
                psnr_db_covered: None,
                file_ratio: None,
                crf: Some(p.matched.crf),
                reached: p.matched.reached,
                ms: t.elapsed().as_secs_f64() * 1e3,
            });
        }
    }

    Ok(())
}

/// Writes rd.csv and rd.svg into `out`: a row per point, a series per method; `played`: the
/// PIS points' PSNR was measured by playing the files.
fn write_rd(
    out: &Path,
    rows: &[RdRow],
    scene: &str,
    stamp: &Stamp,
    played: bool,
) -> Result<(PathBuf, PathBuf), Failure> {
    let mut csv = Csv::new(&[
        "method",
        "target_ratio",
        "ratio",
        "bytes",
        "budget",
        "psnr_db",
        "psnr_scope",
        "psnr_db_predicted",
        "psnr_db_covered",
        "file_ratio",
        "crf",
        "reached",
        "ms",
    ]);
    let opt = |v: Option<f64>| v.map_or(String::new(), |x| format!("{x:.3}"));
    for r in rows {
        csv.push(vec![
            r.method.clone(),
            format!("{}", r.target_ratio),
            format!("{:.2}", r.ratio),
            r.bytes.to_string(),
            r.budget.to_string(),
            format!("{:.3}", r.psnr_db),
            r.psnr_scope.clone(),
            opt(r.psnr_db_predicted),
            opt(r.psnr_db_covered),
            r.file_ratio.map_or(String::new(), |f| format!("{f:.2}")),
            r.crf.map_or(String::new(), |c| format!("{c:.2}")),
            r.reached.to_string(),
            format!("{:.0}", r.ms),
        ]);
    }
    let series: Vec<Series> = METHODS
        .iter()
        .filter(|m| rows.iter().any(|r| &r.method == *m))
        .map(|m| Series {
            name: m.to_string(),
            points: rows.iter().filter(|r| &r.method == m).map(|r| (r.ratio, r.psnr_db)).collect(),
        })
        .collect();
    let chart = Chart {
        title: format!("Compression ratio vs PSNR — {scene}"),
        subtitle: if played {
            "PIS: files played by the player, whole image; mpeg-texture: predicted through the hardware model over covered pixels; view-*: whole decoded image".into()
        } else {
            "PIS and mpeg-texture: PSNR predicted through the hardware model over covered pixels (no GPU adapter); view-*: whole decoded image".into()
        },
        x_label: "compression ratio (raw image bytes / bytes), log".into(),
        y_label: "PSNR (dB)".into(),
        x_log: true,
        stamp: stamp.lines(),
    };
    write_chart(out, "rd", &csv, &chart, &series).map_err(|e| Failure::new(Exit::Io, e))
}

/// PSNR per method at the ratio closest to 384:1 (or the middle ratio).
pub fn summary(r: &RdReport) -> String {
    let target = r
        .rows
        .iter()
        .map(|x| x.target_ratio)
        .min_by(|a, b| (a.ln() - 384f64.ln()).abs().total_cmp(&(b.ln() - 384f64.ln()).abs()))
        .unwrap_or(384.0);
    let parts: Vec<String> = METHODS
        .iter()
        .filter_map(|m| {
            r.rows
                .iter()
                .find(|x| &x.method == m && x.target_ratio == target)
                .map(|x| format!("{m} {:.2} dB @ {:.0}:1", x.psnr_db, x.ratio))
        })
        .collect();
    format!("target {target}:1 — {}", parts.join("; "))
}

/// Human-readable lines.
pub fn print(r: &RdReport, out: &mut impl std::io::Write) -> std::io::Result<()> {
    writeln!(out, "rd: {} — raw image bytes {}", r.scene, r.raw_image_bytes)?;
    writeln!(
        out,
        "  {:<28} {:>8} {:>8} {:>9} {:>8} {:>7}  scope",
        "method", "target", "ratio", "bytes", "PSNR dB", "CRF"
    )?;
    for x in &r.rows {
        writeln!(
            out,
            "  {:<28} {:>8.1} {:>8.1} {:>9} {:>8.2} {:>7}  {}{}",
            x.method,
            x.target_ratio,
            x.ratio,
            x.bytes,
            x.psnr_db,
            x.crf.map_or("-".into(), |c| format!("{c:.2}")),
            x.psnr_scope,
            if x.reached { "" } else { "  (budget not reachable)" }
        )?;
    }
    for s in &r.skipped {
        writeln!(out, "  {s}")?;
    }
    writeln!(out, "  wrote {} and {}", r.csv, r.svg)
}
