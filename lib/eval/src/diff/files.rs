//! `pis-diff A.pis B.pis`: how two containers differ, in structure and in what they decode to.
//!
//! Structure: parameter space, cameras, objects, layers, shells, blocks, pyramid levels,
//! codecs, settings and provenance (one line per difference), and bytes per chunk kind.
//! Content: both files decoded at every parameter sample, per object, layer and parameter
//! block: MSE, PSNR and largest error on display values ([`crate::metrics`]), and the
//! whole file's PSNR. Quality gates turn the comparison into a pass or a fail. With a
//! ray-traced set instead of a second file, [`super::gold`] measures the file against it.

use std::fmt::Write;
use std::path::{Path, PathBuf};

use crate::diff::{compare, differences, ChunkBytes, ObjectDiff, Score};
use crate::heatmap::write_heatmap;
use anyhow::anyhow;
use serde::Serialize;

use crate::reencode::{in_file, open};
use pis_pack::{Exit, Failure};

/// What to compare.
#[derive(Clone, Debug, Default)]
pub struct DiffRequest {
    pub a: PathBuf,
    pub b: PathBuf,
    /// Write per object and layer error heatmaps (PNG) into this folder.
    pub heatmaps: Option<PathBuf>,
    /// Gate: the whole-file PSNR must reach this many dB.
    pub min_psnr: Option<f64>,
    /// The memory budget in bytes for both files' decoded blocks ([`crate::budget`]): a pair
    /// that would take more is refused before decoding (exit 5).
    pub memory: u64,
}

/// A quality gate and how it went.
#[derive(Clone, Debug, Serialize)]
pub struct Gate {
    pub name: String,
    pub limit_db: f64,
    /// The measured value; null for an infinite PSNR (identical textures).
    pub value_db: Option<f64>,
    pub passed: bool,
}

/// Bytes per chunk kind of both files.
#[derive(Clone, Debug, Serialize)]
pub struct BytesPair {
    pub a: ChunkBytes,
    pub b: ChunkBytes,
}

/// One heatmap written.
#[derive(Clone, Debug, Serialize)]
pub struct Heatmap {
    pub object: String,
    pub layer: usize,
    /// The layer's blocks the map covers: those sharing one texture placement.
    pub blocks: Vec<usize>,
    pub file: String,
    /// The RMS display error the ramp's top colour stands for.
    pub scale: f32,
}

/// The report (`--json` prints it). Field names are documented in README.md.
#[derive(Clone, Debug, Serialize)]
pub struct DiffReport {
    pub a: String,
    pub b: String,
    /// Same structure and the same decoded textures.
    pub identical: bool,
    /// The two files hold the same bytes.
    pub bytes_identical: bool,
    /// Structural differences, one line each.
    pub structure: Vec<String>,
    /// Whole-file PSNR (display values, every parameter point); null when the textures are
    /// identical.
    pub psnr_db: Option<f64>,
    pub mse: f64,
    pub max_error: f64,
    /// Every decoded texture equal.
    pub textures_identical: bool,
    /// Every layer of the first file could be compared with one of the second.
    pub complete: bool,
    pub objects: Vec<ObjectDiff>,
    pub bytes: BytesPair,
    pub heatmaps: Vec<Heatmap>,
    pub gates: Vec<Gate>,
    /// `identical`, `different`, `within gates` or `gate failed`.
    pub verdict: String,
}

impl DiffReport {
    /// The exit code the report stands for.
    pub fn exit(&self) -> Exit {
        match self.verdict.as_str() {
            "identical" | "within gates" => Exit::Ok,
            _ => Exit::Different,
        }
    }
}

fn same_bytes(a: &Path, b: &Path) -> Result<bool, Failure> {
    let io = |p: &Path, e: std::io::Error| Failure::new(Exit::Io, anyhow!("{}: {e}", p.display()));
    let (ma, mb) =
        (std::fs::metadata(a).map_err(|e| io(a, e))?, std::fs::metadata(b).map_err(|e| io(b, e))?);
    if ma.len() != mb.len() {
        return Ok(false);
    }
    Ok(std::fs::read(a).map_err(|e| io(a, e))? == std::fs::read(b).map_err(|e| io(b, e))?)
}

/// A file name from an object name: letters, digits, `-` and `_` kept.
fn file_part(s: &str) -> String {
    s.chars()
        .map(|c| if c.is_ascii_alphanumeric() || c == '-' || c == '_' { c } else { '_' })
        .collect()
}

/// Evaluates the gates on a whole-file PSNR (`None`: infinite).
pub fn min_psnr_gate(limit: f64, psnr: Option<f64>) -> Gate {
    Gate {
        name: "min-psnr".into(),
        limit_db: limit,
        value_db: psnr,
        passed: psnr.is_none_or(|p| p >= limit),
    }
}

/// Compares two containers.
pub fn diff(req: &DiffRequest) -> Result<DiffReport, Failure> {
    crate::budget::check_diff(&req.a, &req.b, req.memory)?;
    if let Some(p) = req.min_psnr {
        if !p.is_finite() {
            return Err(Failure::new(
                Exit::Usage,
                anyhow!("--min-psnr must be a number of dB, got {p}"),
            ));
        }
    }
    let a = open(&req.a)?;
    let b = open(&req.b)?;
    let mut structure = differences(a.container(), b.container());
    // The lossless master changes nothing a player decodes, but it is part of the file.
    match (a.has_master(), b.has_master()) {
        (true, false) => structure.push("lossless master only in the first file".into()),
        (false, true) => structure.push("lossless master only in the second file".into()),
        _ => {}
    }
    let bytes_identical = same_bytes(&req.a, &req.b)?;
    let (content, maps) =
        compare(&a, &b, req.heatmaps.is_some(), &mut |line| eprintln!("pis-diff: {line}"))
            .map_err(|e| in_file(&e.path, e.error))?;
    let mut heatmaps = Vec::new();
    if let Some(dir) = &req.heatmaps {
        std::fs::create_dir_all(dir)
            .map_err(|e| Failure::new(Exit::Io, anyhow!("{}: {e}", dir.display())))?;
        for m in &maps {
            let scale = m.values.iter().fold(0.0f32, |a, &v| a.max(v));
            // A layer whose blocks place the texture differently gets a map per placement,
            // named by its first block.
            let part = if m.placements > 1 {
                format!("-block{}", m.blocks.first().copied().unwrap_or(0))
            } else {
                String::new()
            };
            let file =
                dir.join(format!("{}-layer{}-{}{part}.png", file_part(&m.object), m.layer, m.kind));
            write_heatmap(&file, m.width, m.height, &m.values, scale)
                .map_err(|e| Failure::new(Exit::Io, e))?;
            heatmaps.push(Heatmap {
                object: m.object.clone(),
                layer: m.layer,
                blocks: m.blocks.clone(),
                file: file.display().to_string(),
                scale,
            });
        }
    }
    let textures_identical = content.score.exact && content.complete;
    let identical = structure.is_empty() && textures_identical;
    let gates: Vec<Gate> =
        req.min_psnr.map(|l| min_psnr_gate(l, content.score.psnr_db)).into_iter().collect();
    let verdict = match (identical, gates.is_empty(), gates.iter().all(|g| g.passed)) {
        (true, true, _) => "identical",
        (false, true, _) => "different",
        (_, false, true) => "within gates",
        (_, false, false) => "gate failed",
    };
    Ok(DiffReport {
        a: req.a.display().to_string(),
        b: req.b.display().to_string(),
        identical,
        bytes_identical,
        structure,
        psnr_db: content.score.psnr_db,
        mse: content.score.mse,
        max_error: content.score.max_error,
        textures_identical,
        complete: content.complete,
        objects: content.objects,
        bytes: BytesPair { a: ChunkBytes::of(&a), b: ChunkBytes::of(&b) },
        heatmaps,
        gates,
        verdict: verdict.to_string(),
    })
}

/// A PSNR for reports: `identical` for an exact match.
pub fn db(s: &Score) -> String {
    match (s.psnr_db, s.exact) {
        (Some(p), _) => format!("{p:.2} dB"),
        (None, true) => "identical".into(),
        (None, false) => "no error measured".into(),
    }
}

/// The readable report.
pub fn render(r: &DiffReport) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "A: {}\nB: {}", r.a, r.b);
    if r.structure.is_empty() {
        let _ = writeln!(s, "Structure: the same");
    } else {
        let _ = writeln!(s, "Structure: {} difference(s)", r.structure.len());
        for d in &r.structure {
            let _ = writeln!(s, "  - {d}");
        }
    }
    let _ = writeln!(s, "\nBytes per chunk kind:            A            B");
    for ((k, x), (_, y)) in r.bytes.a.rows().iter().zip(r.bytes.b.rows()) {
        let mark = if *x != y { "  *" } else { "" };
        let _ = writeln!(s, "  {k:<26} {x:>10} {y:>12}{mark}");
    }
    let _ = writeln!(s, "\nTextures (display values, every parameter point):");
    let whole = Score {
        psnr_db: r.psnr_db,
        mse: r.mse,
        max_error: r.max_error,
        exact: r.textures_identical,
    };
    let _ = writeln!(
        s,
        "  whole file: PSNR {}, MSE {:.3e}, max error {:.4}",
        db(&whole),
        r.mse,
        r.max_error
    );
    for o in &r.objects {
        let _ = writeln!(
            s,
            "  object {:<14} {:>12}  max error {:.4}",
            o.name,
            db(&o.score),
            o.score.max_error
        );
        for l in &o.layers {
            if !l.compared {
                let _ = writeln!(
                    s,
                    "    layer {} {:<12} not compared: {}",
                    l.layer,
                    l.kind,
                    l.note.as_deref().unwrap_or("")
                );
                continue;
            }
            let worst = l.blocks.iter().filter(|b| !b.score.exact).min_by(|x, y| {
                x.score.psnr_db.partial_cmp(&y.score.psnr_db).unwrap_or(std::cmp::Ordering::Equal)
            });
            let worst = worst.map_or(String::new(), |b| {
                format!(", worst block {} at {}", b.block, db(&b.score))
            });
            let _ = writeln!(
                s,
                "    layer {} {:<12} {:>12}  MSE {:.3e}  max error {:.4}  ({} blocks{worst})",
                l.layer,
                l.kind,
                db(&l.score),
                l.score.mse,
                l.score.max_error,
                l.blocks.len()
            );
        }
    }
    for h in &r.heatmaps {
        let _ = writeln!(s, "  heatmap {} (top colour = RMS error {:.4})", h.file, h.scale);
    }
    for g in &r.gates {
        let v = g.value_db.map_or("inf".to_string(), |v| format!("{v:.2}"));
        let _ = writeln!(
            s,
            "Gate {}: {v} dB against {:.2} dB: {}",
            g.name,
            g.limit_db,
            if g.passed { "passed" } else { "FAILED" }
        );
    }
    let bytes = if r.bytes_identical {
        " (the bytes are identical)"
    } else if r.identical {
        " (the bytes differ)"
    } else {
        ""
    };
    let _ = writeln!(s, "Verdict: {}{bytes}", r.verdict);
    s
}
