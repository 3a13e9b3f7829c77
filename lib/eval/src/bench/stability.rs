//! `pis-bench stability`: PIS away from its samples. A dense camera path between the
//! sampled views (fractional view values: textures blended linearly between the two
//! neighbouring view samples) and one off the orbit (a free camera), each frame rendered
//! through the hardware model (A built for that exact camera, occlusion by the other
//! objects) and compared with a frame ray-traced at that exact camera by pis-trace, on
//! display values over the pixels the objects cover. Per representation: the textures as
//! solved and after coding at each ratio (up to extreme ratios).
//!
//! Popping: per path, the largest frame-to-frame RMS change of the PIS frames divided by
//! the reference's RMS change between the same two frames (1: as smooth as the reference).

use std::collections::btree_map::{BTreeMap, Entry};
use std::path::PathBuf;

use crate::chart::{Chart, Series};
use crate::metrics::{display, PairedError, SquaredError};
use crate::report::{Csv, Stamp};
use anyhow::{anyhow, Result};
use pis_compile::{
    render, render_matrix, scene_depth, DrawMesh, Filter, RenderMatrix, TexturedObject, Viewport,
};
use pis_format::DepMask;

use super::reference::{ReferenceFrame, ReferenceTrace};
use rayon::prelude::*;
use serde::Serialize;

use super::camera_path::{paths, PathFrame, PathKind, AWAY_ELEVATION_DEG, AWAY_RADIUS};
use super::output::{ensure_dir, record, write_chart};
use pis_pack::encode::LayerTextures;
use pis_pack::infer::{merged_mesh, sampler, Mesh};
use pis_pack::{Exit, Failure};
use pis_pack::{Inferred, PackRequest, PackSettings, StderrProgress};

/// What to measure.
#[derive(Clone, Debug)]
pub struct StabilityRequest {
    pub input: PathBuf,
    pub scene: Option<PathBuf>,
    /// Ratios of the coded representations (the solved textures are always included).
    pub ratios: Vec<f64>,
    /// Frames per path.
    pub frames: usize,
    /// How the reference frames are traced.
    pub reference: ReferenceTrace,
    pub out: PathBuf,
    pub resolution: Option<(u32, u32)>,
    pub trace_spp: Option<u32>,
    pub max_texture: u32,
    /// Tracing a scene.toml: a `[preset.NAME]`.
    pub preset: Option<String>,
    pub record: bool,
}

/// One frame's result.
#[derive(Clone, Debug, Serialize)]
pub struct FrameRow {
    pub representation: String,
    pub path: PathKind,
    pub frame: usize,
    pub view: f32,
    pub psnr_db: f64,
    /// RMS display change from the previous frame (PIS, reference); null for the first.
    pub change: Option<[f64; 2]>,
}

/// One representation on one path.
#[derive(Clone, Debug, Serialize)]
pub struct PathSummary {
    pub representation: String,
    pub path: PathKind,
    /// Level-image bytes (null for the textures as solved) and the ratio they give.
    pub ratio: Option<f64>,
    pub mean_psnr_db: f64,
    pub min_psnr_db: f64,
    pub popping: f64,
    /// With a reference pair, over the path's frames pooled: the PSNR against the
    /// references' mean, the same with their noise taken out (`null`: within it), and the
    /// mean's own noise ([`PairedError`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pooled_psnr_db: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub noise_removed_psnr_db: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reference_psnr_db: Option<f64>,
}

#[derive(Clone, Debug, Serialize)]
pub struct StabilityReport {
    pub scene: String,
    pub frames: usize,
    /// How the reference frames were traced (samples, seeding, adaptive sampling, denoising).
    pub reference: String,
    pub summaries: Vec<PathSummary>,
    pub rows: Vec<FrameRow>,
    pub csv: String,
    pub svg: String,
    pub stamp: Stamp,
    pub notes: Vec<String>,
}

/// A frame through the hardware model: display values and a coverage mask.
struct Rendered {
    rgb: Vec<f32>,
    mask: Vec<bool>,
}

/// The samples of one layer at a fractional view position, with their weights: the two
/// neighbouring view samples blended linearly (the nearest alone when the layer does not
/// depend on the view).
fn layer_samples(
    mask: DepMask,
    view_dim: usize,
    point: &[u32],
    view: f32,
    views: u32,
) -> Vec<(Vec<u32>, f32)> {
    let key_at = |v: u32| -> Vec<u32> {
        mask.dims().map(|d| if d == view_dim { v } else { point[d] }).collect()
    };
    if !mask.dims().any(|d| d == view_dim) {
        return vec![(key_at(0), 1.0)];
    }
    let k0 = (view.floor() as u32).min(views - 1);
    let k1 = (k0 + 1).min(views - 1);
    let f = view - k0 as f32;
    vec![(key_at(k0), 1.0 - f), (key_at(k1), f)]
}

fn render_frame(
    inf: &Inferred,
    meshes: &[Mesh],
    tex: &[Vec<LayerTextures>],
    pf: &PathFrame,
    view_dim: usize,
) -> Result<Rendered> {
    let set = &inf.set;
    let (w, h) = set.resolution;
    let viewport = Viewport { width: w, height: h };
    let frame = &pf.frame;
    let clip_from = |k: usize| {
        pis_trace::camera::projection_matrix(&frame.camera, (w, h))
            * frame.camera.world_from_camera.inverse()
            * frame.instances[k].world_from_object
    };
    let draw: Vec<DrawMesh> = meshes
        .iter()
        .enumerate()
        .map(|(k, m)| DrawMesh {
            positions: &m.positions,
            uvs: &m.uvs,
            indices: &m.indices,
            clip_from_object: clip_from(k),
        })
        .collect();
    let views = set.scene.space.dims[view_dim].values.len() as u32;
    let mut rgb = vec![0.0f32; w as usize * h as usize * 3];
    let mut mask = vec![false; w as usize * h as usize];
    for (mi, m) in inf.models.iter().enumerate() {
        let occluders = scene_depth(viewport, &draw, Some(m.index))?;
        let mut mesh = draw[m.index];
        mesh.uvs = &m.mesh_uvs;
        // One render matrix per placement the frame's samples carry (the same pixels).
        let mut matrices: BTreeMap<usize, RenderMatrix> = BTreeMap::new();
        let mut img: Vec<f32> = Vec::new();
        for (li, l) in m.layers.iter().enumerate() {
            for (k, weight) in layer_samples(l.depends_on, view_dim, &pf.point, pf.view, views) {
                let x = tex[mi][li].get(&k).ok_or_else(|| {
                    anyhow!("object {}: no texture near view {}", m.name, pf.view)
                })?;
                if weight == 0.0 {
                    continue;
                }
                let pid = l.placement_of[&k];
                let a = match matrices.entry(pid) {
                    Entry::Occupied(e) => e.into_mut(),
                    Entry::Vacant(e) => {
                        let pl = &m.placements[pid];
                        let obj = TexturedObject {
                            mesh,
                            transform: pl.transform,
                            layout: pl.layout,
                            sampler: sampler(Filter::Trilinear, pl.repeat),
                        };
                        e.insert(render_matrix(viewport, &obj, Some(&occluders))?)
                    }
                };
                img.resize(a.rows() * 3, 0.0);
                let y = render(a, x);
                img.iter_mut().zip(&y).for_each(|(s, v)| *s += weight * v);
            }
        }
        let Some(a) = matrices.values().next() else { continue };
        for r in 0..a.rows() {
            let p = a.pixels[r] as usize;
            mask[p] = true;
            for c in 0..3 {
                rgb[p * 3 + c] += img[r * 3 + c];
            }
        }
    }
    Ok(Rendered { rgb, mask })
}

/// The reference frame at `pf` (with a pair, the mean of two traces, and both).
fn reference(req: &StabilityRequest, inf: &Inferred, pf: &PathFrame) -> Result<ReferenceFrame> {
    let mut f = req.reference.frame(&inf.set.scene, &pf.frame)?;
    f.images.layers.clear();
    Ok(f)
}

/// One representation's frames on one path against the references: a row per frame into
/// `rows`, and the path's summary.
fn measure_path(
    (name, ratio): (&str, Option<f64>),
    kind: PathKind,
    frames: &[PathFrame],
    rendered: &[Rendered],
    refs: &[ReferenceFrame],
    rows: &mut Vec<FrameRow>,
) -> PathSummary {
    let idx: Vec<usize> = (0..frames.len()).filter(|&i| frames[i].kind == kind).collect();
    let (mut psnrs, mut popping, mut pooled) = (Vec::new(), 0.0f64, PairedError::default());
    for (j, &i) in idx.iter().enumerate() {
        let (mut e, r) = (SquaredError::default(), &refs[i]);
        for (p, _) in rendered[i].mask.iter().enumerate().filter(|(_, m)| **m) {
            let px = p * 3..p * 3 + 3;
            e.add_slices(&rendered[i].rgb[px.clone()], &r.rgb[px.clone()]);
            if let Some([a, b]) = &r.pair {
                pooled.add_slices(&rendered[i].rgb[px.clone()], &a[px.clone()], &b[px]);
            }
        }
        let change = (j > 0).then(|| {
            let prev = idx[j - 1];
            let both: Vec<bool> =
                rendered[i].mask.iter().zip(&rendered[prev].mask).map(|(a, b)| *a && *b).collect();
            [
                rms_change(&rendered[i].rgb, &rendered[prev].rgb, &both),
                rms_change(&r.rgb, &refs[prev].rgb, &both),
            ]
        });
        if let Some([p, r]) = change {
            popping = popping.max(p / r.max(0.5 / 255.0));
        }
        psnrs.push(e.psnr());
        rows.push(FrameRow {
            representation: name.to_string(),
            path: kind,
            frame: j,
            view: frames[i].view,
            psnr_db: e.psnr(),
            change,
        });
    }
    let mean = psnrs.iter().sum::<f64>() / psnrs.len().max(1) as f64;
    let min = psnrs.iter().copied().fold(f64::INFINITY, f64::min);
    eprintln!(
        "pis-bench: stability: {name:<16} {:<8} mean {mean:6.2} dB, min {min:6.2} dB, popping {popping:5.2}",
        kind.name()
    );
    let paired = refs.first().is_some_and(|r| r.pair.is_some());
    let pair = |v: f64| paired.then_some(v);
    PathSummary {
        representation: name.to_string(),
        path: kind,
        ratio,
        mean_psnr_db: mean,
        min_psnr_db: min,
        popping,
        pooled_psnr_db: pair(pooled.against_mean.psnr()),
        noise_removed_psnr_db: pair(pooled.psnr_noise_removed()).filter(|v| v.is_finite()),
        reference_psnr_db: pair(pooled.reference_psnr()),
    }
}

fn rms_change(a: &[f32], b: &[f32], mask: &[bool]) -> f64 {
    let (mut s, mut n) = (0.0f64, 0usize);
    for (p, &m) in mask.iter().enumerate() {
        if m {
            for c in 0..3 {
                s += (display(a[p * 3 + c]) - display(b[p * 3 + c])).powi(2);
                n += 1;
            }
        }
    }
    (s / n.max(1) as f64).sqrt()
}

fn runtime(e: anyhow::Error) -> Failure {
    Failure::new(Exit::Runtime, e)
}

pub fn check(req: &StabilityRequest) -> Result<(), Failure> {
    if !req.input.exists() {
        return Err(Failure::new(
            Exit::Io,
            anyhow!("{}: no such set directory or scene file", req.input.display()),
        ));
    }
    if let Some(r) = req.ratios.iter().find(|r| !(r.is_finite() && **r >= 1.0)) {
        return Err(Failure::new(
            Exit::Usage,
            anyhow!("--ratios: every ratio must be at least 1, got {r}"),
        ));
    }
    req.reference.check()?;
    if req.frames < 2 || req.frames > 10_000 || req.reference.spp == 0 {
        return Err(Failure::new(
            Exit::Usage,
            anyhow!("--frames must be in 2..=10000 and --spp at least 1"),
        ));
    }
    Ok(())
}

/// Writes stability.csv and stability.svg: a row per frame and per path's summary, a series
/// per representation and path.
fn write_stability(
    req: &StabilityRequest,
    scene_s: &str,
    stamp: &Stamp,
    rows: &[FrameRow],
    summaries: &[PathSummary],
) -> Result<(PathBuf, PathBuf), Failure> {
    let mut csv = Csv::new(&[
        "representation",
        "path",
        "frame",
        "view",
        "psnr_db",
        "change_pis",
        "change_reference",
    ]);
    for r in rows {
        csv.push(vec![
            r.representation.clone(),
            r.path.name().into(),
            r.frame.to_string(),
            format!("{:.3}", r.view),
            format!("{:.3}", r.psnr_db),
            r.change.map_or(String::new(), |c| format!("{:.5}", c[0])),
            r.change.map_or(String::new(), |c| format!("{:.5}", c[1])),
        ]);
    }
    for s in summaries {
        csv.push(vec![
            s.representation.clone(),
            format!("{}-summary", s.path.name()),
            String::new(),
            String::new(),
            format!("{:.3}", s.mean_psnr_db),
            format!("popping {:.3}", s.popping),
            format!("min {:.3}", s.min_psnr_db),
        ]);
    }
    let series: Vec<Series> = summaries
        .iter()
        .map(|s| Series {
            name: format!("{} · {} (popping {:.2})", s.representation, s.path.name(), s.popping),
            points: rows
                .iter()
                .filter(|r| r.representation == s.representation && r.path == s.path)
                .map(|r| (r.view as f64, r.psnr_db))
                .collect(),
        })
        .collect();
    let chart = Chart {
        title: format!("Stability off the samples — {scene_s}"),
        subtitle: format!("through the hardware model at each exact camera vs pis-trace ({}) over covered pixels; between: fractional view, away: radius ×{AWAY_RADIUS}, elevation +{AWAY_ELEVATION_DEG}°", req.reference.describe()),
        x_label: "position along the view dimension (samples)".into(),
        y_label: "PSNR (dB)".into(),
        x_log: false,
        stamp: stamp.lines(),
    };
    write_chart(&req.out, "stability", &csv, &chart, &series).map_err(|e| Failure::new(Exit::Io, e))
}

/// Runs the paths for every representation and writes stability.csv and stability.svg.
pub fn run(req: &StabilityRequest) -> Result<StabilityReport, Failure> {
    check(req)?;
    ensure_dir(&req.out).map_err(|e| Failure::new(Exit::Io, e))?;
    let settings = PackSettings {
        max_texture: req.max_texture,
        resolution: req.resolution,
        spp: req.trace_spp,
        preset: req.preset.clone(),
        ..super::pack_defaults()
    };
    let base = PackRequest {
        scene: req.scene.clone(),
        ..PackRequest::new(req.input.clone(), req.out.join("unused.pis"), settings)
    };
    eprintln!("pis-bench: stability: loading and inferring");
    let inf = Inferred::new(&base, &StderrProgress)?;
    let scene = &inf.set.scene;
    let (view_dim, frames) = paths(scene, req.frames, &[PathKind::Between, PathKind::Away])
        .map_err(|e| Failure::new(Exit::NotSupported, e))?;
    req.reference.announce("stability", frames.len());
    let refs: Vec<ReferenceFrame> =
        frames.iter().map(|f| reference(req, &inf, f)).collect::<Result<_>>().map_err(runtime)?;
    let meshes: Vec<Mesh> = (0..scene.objects.len()).map(|o| merged_mesh(scene, o)).collect();
    let raw = inf.raw_image_bytes();
    let mut reps: Vec<(String, Option<f64>, Vec<Vec<LayerTextures>>)> =
        vec![("solved".into(), None, inf.solved().map_err(runtime)?)];
    for &r in &req.ratios {
        let (t, bytes) = inf.decoded(&base.with(|s| s.target = pis_pack::Target::Ratio(r)))?;
        reps.push((format!("wavelet {r}:1"), Some(raw as f64 / bytes.max(1) as f64), t));
    }
    let mut rows = Vec::new();
    let mut summaries = Vec::new();
    for (name, ratio, tex) in &reps {
        let rendered: Vec<Rendered> = frames
            .par_iter()
            .map(|f| render_frame(&inf, &meshes, tex, f, view_dim))
            .collect::<Result<_>>()
            .map_err(runtime)?;
        for kind in [PathKind::Between, PathKind::Away] {
            let summary = measure_path((name, *ratio), kind, &frames, &rendered, &refs, &mut rows);
            summaries.push(summary);
        }
    }
    let set = &inf.set;
    let scene_s = format!(
        "{} ({} points, {}x{})",
        set.scene.name,
        set.samples.len(),
        set.resolution.0,
        set.resolution.1
    );
    let stamp = Stamp::here(&scene_s);
    let (c, s) = write_stability(req, &scene_s, &stamp, &rows, &summaries)?;
    let report = StabilityReport {
        scene: scene_s, frames: req.frames, reference: req.reference.describe(), summaries, rows, csv: c.display().to_string(), svg: s.display().to_string(), stamp,
        notes: vec![
            "frames rendered through the hardware model (CPU), textures blended linearly between the two neighbouring view samples".into(),
            "PSNR on display values over the pixels the model covers, against pis-trace's combined image at the same camera".into(),
            "popping = max over consecutive frames of RMS change (PIS) / RMS change (reference), reference change floored at half an 8-bit step".into(),
        ],
    };
    if req.record {
        let summary: Vec<String> = report
            .summaries
            .iter()
            .map(|s| {
                format!(
                    "{} {} {:.2} dB (min {:.2}, popping {:.2})",
                    s.representation,
                    s.path.name(),
                    s.mean_psnr_db,
                    s.min_psnr_db,
                    s.popping
                )
            })
            .collect();
        record("stability", &report.stamp, &summary.join("; "))
            .map_err(|e| Failure::new(Exit::Io, e))?;
    }
    Ok(report)
}

pub fn print(r: &StabilityReport, out: &mut impl std::io::Write) -> std::io::Result<()> {
    writeln!(
        out,
        "stability: {} — {} frames per path, references at {}",
        r.scene, r.frames, r.reference
    )?;
    for s in &r.summaries {
        write!(
            out,
            "  {:<16} {:<8} {:>8} mean {:6.2} dB  min {:6.2} dB  popping {:5.2}",
            s.representation,
            s.path.name(),
            s.ratio.map_or("-".into(), |x| format!("{x:.0}:1")),
            s.mean_psnr_db,
            s.min_psnr_db,
            s.popping
        )?;
        if let (Some(pooled), Some(reference)) = (s.pooled_psnr_db, s.reference_psnr_db) {
            let removed = s
                .noise_removed_psnr_db
                .map_or("within the references' noise".into(), |v| format!("{v:6.2} dB"));
            write!(out, "  pooled {pooled:6.2} dB  noise removed {removed}  (gold standard's noise {reference:.2} dB)")?;
        }
        writeln!(out)?;
    }
    writeln!(out, "  wrote {} and {}", r.csv, r.svg)
}
