//! `pis-diff A.pis SET_DIR`: a container's accuracy against the ray-traced gold standard.
//!
//! Every sample point of the set is drawn through the player's offscreen (headless) path and
//! compared with the set's image by [`crate::compare::compare_with_set`], the comparison
//! `pis-play --headless --compare` prints, so both tools give the same PSNR per point, per
//! object and per parameter block. The diff adds NVIDIA FLIP on the sRGB display images
//! ([`crate::flip`]): mean FLIP per image, per object (the pixels the player draws the
//! object at) and overall; FLIP error maps as heatmaps; and the quality gates `--min-psnr`
//! (whole-image PSNR) and `--max-psnr-drop` (the PSNR over the objects' covered pixels, the
//! measure of pis-pack's prediction, against the file's recorded prediction or
//! `--reference-psnr`).

use std::path::PathBuf;
use std::sync::Arc;

use crate::compare::{compare_with_set, CompareOptions, Comparison};
use crate::flip::{flip_map, means, FlipMean};
use crate::heatmap::write_heatmap;
use anyhow::anyhow;
use pis_play::{Gpu, PlayError, Player, PlayerOptions};
use serde::Serialize;

use super::files::{min_psnr_gate, Gate};
use super::noise::{self, judge, ReferenceNoise};
use crate::reencode::open;
use pis_pack::{Exit, Failure};

/// The provenance setting that holds a writer's predicted PSNR (dB), the reference of
/// `--max-psnr-drop` when `--reference-psnr` is not given.
pub use pis_pack::PREDICTED_PSNR_SETTING;

/// What to measure.
#[derive(Clone, Debug, Default)]
pub struct GoldRequest {
    pub file: PathBuf,
    pub set: PathBuf,
    /// Write one FLIP error map (PNG) per sample point into this folder.
    pub heatmaps: Option<PathBuf>,
    pub min_psnr: Option<f64>,
    pub max_psnr_drop: Option<f64>,
    pub reference_psnr: Option<f64>,
    /// Samples per pixel the player draws with (1 or 4, as `pis-play --msaa`).
    pub msaa: u32,
    /// A second trace of the set from an independent sample stream: measures the set's own
    /// noise ([`super::noise`]).
    pub pair: Option<PathBuf>,
}

#[derive(Clone, Debug, Serialize)]
pub struct GoldBlock {
    pub block: usize,
    pub psnr_db: Option<f64>,
    pub mse: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct GoldObject {
    pub name: String,
    /// Null when no error was measured (an exact match or no pixel).
    pub psnr_db: Option<f64>,
    pub mse: f64,
    /// Mean FLIP over the pixels the player drew the object at, every point.
    pub flip_mean: Option<f64>,
    pub blocks: Vec<GoldBlock>,
}

#[derive(Clone, Debug, Serialize)]
pub struct GoldPointObject {
    pub name: String,
    pub psnr_db: Option<f64>,
    pub flip_mean: Option<f64>,
}

#[derive(Clone, Debug, Serialize)]
pub struct GoldPoint {
    pub index: usize,
    /// The point's value along each dimension.
    pub point: Vec<f32>,
    pub psnr_db: Option<f64>,
    pub flip_mean: Option<f64>,
    pub objects: Vec<GoldPointObject>,
}

/// The report (`--json` prints it).
#[derive(Clone, Debug, Serialize)]
pub struct GoldReport {
    pub file: String,
    pub set: String,
    pub device: String,
    /// Samples per pixel the player drew with (its default multisampling; 1: none).
    pub msaa_samples: u32,
    /// Samples per pixel asked for (`--msaa`).
    pub msaa_requested: u32,
    /// How multisampled frames are resolved (as pis-play's report).
    pub resolve: crate::headless::Resolve,
    /// Whole image, every point (display values, peak 1).
    pub psnr_db: Option<f64>,
    /// Every object's covered pixels pooled: the measure of pis-pack's predicted PSNR, which
    /// `--max-psnr-drop` compares with.
    pub covered_psnr_db: Option<f64>,
    /// The whole image at the gold standard's silhouette pixels (some object partly covers
    /// them) and elsewhere, with the silhouette pixels' share of the image.
    pub silhouette_psnr_db: Option<f64>,
    pub interior_psnr_db: Option<f64>,
    pub silhouette_fraction: f64,
    /// Mean FLIP over every pixel of every point.
    pub flip_mean: Option<f64>,
    /// The reference of `--max-psnr-drop` and where it came from.
    pub reference_psnr_db: Option<f64>,
    pub reference_from: Option<String>,
    pub psnr_drop_db: Option<f64>,
    pub objects: Vec<GoldObject>,
    pub points: Vec<GoldPoint>,
    pub heatmaps: Vec<String>,
    pub gates: Vec<Gate>,
    /// `measured` (no gate), `within gates` or `gate failed`.
    pub verdict: String,
    /// With a reference pair: the set's own noise beside each figure.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reference_noise: Option<ReferenceNoise>,
}

impl GoldReport {
    pub fn exit(&self) -> Exit {
        if self.verdict == "gate failed" {
            Exit::Different
        } else {
            Exit::Ok
        }
    }
}

fn finite(v: f64) -> Option<f64> {
    v.is_finite().then_some(v)
}

/// The exit code of an error from the player or the comparison: no adapter is "not
/// supported", file errors keep theirs, a set that cannot be read is an I/O error.
fn failure(e: anyhow::Error) -> Failure {
    let exit = if let Some(p) = e.downcast_ref::<PlayError>() {
        crate::headless::play_exit(p)
    } else {
        pis_pack::exit_of(&e, Exit::Runtime)
    };
    Failure::new(exit, e)
}

/// Checks the gates' figures and returns the reference of the drop gate, with where it came
/// from: `--reference-psnr`, else the prediction the file's provenance records. Creates the
/// heatmap folder.
fn drop_reference(req: &GoldRequest) -> Result<(Option<f64>, Option<String>), Failure> {
    for (name, v) in [
        ("--min-psnr", req.min_psnr),
        ("--max-psnr-drop", req.max_psnr_drop),
        ("--reference-psnr", req.reference_psnr),
    ] {
        if v.is_some_and(|v| !v.is_finite()) {
            return Err(Failure::new(Exit::Usage, anyhow!("{name} must be a number of dB")));
        }
    }
    let reader = open(&req.file)?;
    let recorded = reader.container().provenance.as_ref().and_then(|p| {
        p.settings
            .iter()
            .find(|(k, _)| k == PREDICTED_PSNR_SETTING)
            .and_then(|(_, v)| v.trim().parse::<f64>().ok())
    });
    let (reference, reference_from) = match (req.reference_psnr, recorded) {
        (Some(r), _) => (Some(r), Some("--reference-psnr".to_string())),
        (None, Some(r)) => (Some(r), Some(format!("provenance setting {PREDICTED_PSNR_SETTING}"))),
        (None, None) => (None, None),
    };
    if req.max_psnr_drop.is_some() && reference.is_none() {
        return Err(Failure::new(
            Exit::Usage,
            anyhow!("--max-psnr-drop needs a reference: {} records no {PREDICTED_PSNR_SETTING}; give --reference-psnr DB", req.file.display()),
        ));
    }
    if let Some(dir) = &req.heatmaps {
        std::fs::create_dir_all(dir)
            .map_err(|e| Failure::new(Exit::Io, anyhow!("{}: {e}", dir.display())))?;
    }
    drop(reader);
    Ok((reference, reference_from))
}

/// The objects' figures: PSNR and MSE from the comparison, FLIP from each point's.
fn gold_objects(
    comparison: &Comparison,
    names: &[String],
    object_flip: &[FlipMean],
) -> Vec<GoldObject> {
    let object_index = |name: &str| names.iter().position(|n| n == name);
    comparison
        .objects
        .iter()
        .map(|o| GoldObject {
            name: o.name.clone(),
            psnr_db: finite(o.psnr_db),
            mse: o.error.mse(),
            flip_mean: object_index(&o.name).and_then(|i| object_flip[i].mean()),
            blocks: o
                .blocks
                .iter()
                .map(|b| GoldBlock {
                    block: b.block,
                    psnr_db: finite(b.psnr_db),
                    mse: b.error.mse(),
                })
                .collect(),
        })
        .collect()
}

/// The points' figures, each with its objects'.
fn gold_points(
    comparison: &Comparison,
    names: &[String],
    flips: &[(usize, FlipMean, Vec<FlipMean>)],
) -> Vec<GoldPoint> {
    let object_index = |name: &str| names.iter().position(|n| n == name);
    comparison
        .points
        .iter()
        .map(|p| {
            let f = flips.iter().find(|(i, _, _)| *i == p.index);
            GoldPoint {
                index: p.index,
                point: p.point.clone(),
                psnr_db: finite(p.psnr_db),
                flip_mean: f.and_then(|(_, w, _)| w.mean()),
                objects: p
                    .objects
                    .iter()
                    .map(|o| GoldPointObject {
                        name: o.name.clone(),
                        psnr_db: finite(o.psnr_db),
                        flip_mean: f.and_then(|(_, _, per)| {
                            object_index(&o.name).and_then(|i| per[i].mean())
                        }),
                    })
                    .collect(),
            }
        })
        .collect()
}

/// Measures `req.file` against the set `req.set`.
pub fn gold(req: &GoldRequest) -> Result<GoldReport, Failure> {
    // The reference of the drop gate and the set's own noise, before any drawing.
    let (reference, reference_from) = drop_reference(req)?;
    let pair = req.pair.as_ref().map(|p| super::sets::pair(&req.set, p, false)).transpose()?;

    let gpu = Arc::new(Gpu::new().map_err(|e| failure(e.into()))?);
    let device = gpu.describe();
    let mut player = Player::open(
        gpu,
        &req.file,
        PlayerOptions {
            msaa: req.msaa,
            display_filter: crate::headless::set_display_filter(&req.set),
            ..PlayerOptions::default()
        },
    )
    .map_err(|e| failure(e.into()))?;
    let msaa_samples = player.multisample().samples;
    let resolve = crate::headless::Resolve::of(&player);
    if let Some(note) = &player.multisample().note {
        eprintln!("pis-diff: note: {note}");
    }
    let names = player.object_names();
    let mut flips: Vec<(usize, FlipMean, Vec<FlipMean>)> = Vec::new();
    let mut heatmaps = Vec::new();
    let mut side_error: Option<anyhow::Error> = None;
    let comparison =
        compare_with_set(&mut player, &req.set, &CompareOptions::default(), &mut |pair| {
            if side_error.is_some() {
                return;
            }
            let result = flip_map(pair.gold, pair.rendered).and_then(|map| {
                let (whole, per) = means(&map, pair.object_ids, names.len());
                flips.push((pair.index, whole, per));
                if let Some(dir) = &req.heatmaps {
                    let file = dir.join(format!("point_{:05}_flip.png", pair.index));
                    write_heatmap(&file, pair.rendered.width, pair.rendered.height, &map, 1.0)?;
                    heatmaps.push(file.display().to_string());
                }
                Ok(())
            });
            if let Err(e) = result {
                side_error = Some(e);
            }
        })
        .map_err(failure)?;
    if let Some(e) = side_error {
        return Err(Failure::new(Exit::Runtime, e));
    }

    let mut total_flip = FlipMean::default();
    let mut object_flip = vec![FlipMean::default(); names.len()];
    for (_, whole, per) in &flips {
        total_flip.merge(whole);
        object_flip.iter_mut().zip(per).for_each(|(a, b)| a.merge(b));
    }
    let objects = gold_objects(&comparison, &names, &object_flip);
    let points = gold_points(&comparison, &names, &flips);

    let psnr = finite(comparison.psnr_db);
    let covered = finite(comparison.covered_psnr_db);
    let drop = reference.map(|r| r - covered.unwrap_or(f64::INFINITY));
    let mut gates = Vec::new();
    if let Some(limit) = req.min_psnr {
        gates.push(min_psnr_gate(limit, psnr));
    }
    if let (Some(limit), Some(d)) = (req.max_psnr_drop, drop) {
        gates.push(Gate {
            name: "max-psnr-drop".into(),
            limit_db: limit,
            value_db: finite(d),
            passed: d <= limit,
        });
    }
    let verdict = match (gates.is_empty(), gates.iter().all(|g| g.passed)) {
        (true, _) => "measured",
        (false, true) => "within gates",
        (false, false) => "gate failed",
    };
    Ok(GoldReport {
        file: req.file.display().to_string(),
        set: req.set.display().to_string(),
        device,
        msaa_samples,
        msaa_requested: req.msaa,
        resolve,
        psnr_db: psnr,
        covered_psnr_db: covered,
        silhouette_psnr_db: finite(comparison.silhouette.psnr()),
        interior_psnr_db: finite(comparison.interior.psnr()),
        silhouette_fraction: comparison.silhouette.count as f64
            / (comparison.silhouette.count + comparison.interior.count).max(1) as f64,
        flip_mean: total_flip.mean(),
        reference_psnr_db: reference,
        reference_from,
        psnr_drop_db: drop.and_then(finite),
        points,
        heatmaps,
        gates,
        verdict: verdict.to_string(),
        reference_noise: pair.map(|p| ReferenceNoise {
            pair: p.b.clone(),
            points: p.points_compared,
            figures: [
                judge("whole image", psnr, p.psnr_db),
                judge("objects' covered pixels", covered, p.pooled_objects_psnr()),
            ]
            .into_iter()
            .chain(
                objects
                    .iter()
                    .filter(|o| o.mse > 0.0)
                    .map(|o| judge(&o.name, o.psnr_db, p.object_psnr(&o.name))),
            )
            .collect(),
        }),
        objects,
    })
}

fn db(v: Option<f64>) -> String {
    v.map_or("inf".to_string(), |v| format!("{v:.2}"))
}

fn fl(v: Option<f64>) -> String {
    v.map_or("-".to_string(), |v| format!("{v:.4}"))
}

/// The readable report.
pub fn render(r: &GoldReport) -> String {
    use std::fmt::Write;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "{} against the gold-standard set {} ({} points, {}, {}{})",
        r.file,
        r.set,
        r.points.len(),
        r.device,
        crate::headless::msaa_label(r.msaa_samples, r.msaa_requested),
        r.resolve.label()
    );
    let _ = writeln!(
        s,
        "  PSNR (display values): whole image {} dB, objects' covered pixels {} dB",
        db(r.psnr_db),
        db(r.covered_psnr_db)
    );
    let _ = writeln!(s, "  whole image at silhouettes {} dB ({:.1} % of the pixels: partly covered in the gold standard), elsewhere {} dB", db(r.silhouette_psnr_db), 100.0 * r.silhouette_fraction, db(r.interior_psnr_db));
    let _ = writeln!(s, "  mean FLIP (sRGB images): {}", fl(r.flip_mean));
    let _ = writeln!(s, "  objects:                PSNR (dB)   mean FLIP   worst block");
    for o in &r.objects {
        let worst =
            o.blocks.iter().filter(|b| b.psnr_db.is_some()).min_by(|a, b| {
                a.psnr_db.partial_cmp(&b.psnr_db).unwrap_or(std::cmp::Ordering::Equal)
            });
        let worst =
            worst.map_or(String::new(), |b| format!("block {} at {} dB", b.block, db(b.psnr_db)));
        let _ = writeln!(
            s,
            "    {:<20} {:>10} {:>11}   {worst}",
            o.name,
            db(o.psnr_db),
            fl(o.flip_mean)
        );
    }
    let _ = writeln!(s, "  points:");
    for p in &r.points {
        let values: Vec<String> = p.point.iter().map(|v| format!("{v:.3}")).collect();
        let _ = writeln!(
            s,
            "    {:>5} ({:<14}) PSNR {:>7} dB  FLIP {}",
            p.index,
            values.join(", "),
            db(p.psnr_db),
            fl(p.flip_mean)
        );
    }
    if let (Some(r0), Some(from)) = (r.reference_psnr_db, &r.reference_from) {
        let _ = writeln!(s, "  reference {r0:.2} dB ({from}): drop {} dB", db(r.psnr_drop_db));
    }
    if let Some(n) = &r.reference_noise {
        s.push_str(&noise::render(n));
    }
    for h in &r.heatmaps {
        let _ = writeln!(s, "  FLIP map {h}");
    }
    for g in &r.gates {
        let _ = writeln!(
            s,
            "Gate {}: {} dB against {:.2} dB: {}",
            g.name,
            db(g.value_db),
            g.limit_db,
            if g.passed { "passed" } else { "FAILED" }
        );
    }
    let _ = writeln!(s, "Verdict: {}", r.verdict);
    s
}
