//! A denoised set from two independent halves rendered elsewhere (RAYSET.md 5.4, 8).
//!
//! A renderer that cannot keep its even and odd samples apart renders the set twice, each
//! time at half the samples and from its own seeds, with the denoiser's guides. The two sets
//! are the halves A and B of pis-trace's own denoising: the joined set's raw layers are
//! their mean (the set at all the samples: an object's layers weighted by each half's
//! coverage), its guides their mean, and every radiance layer
//! gets a `denoised.` twin where the halves estimate it nearer the converged image than the
//! raw one ([`crate::denoise::denoise_point`]).

use super::meta::{PointMeta, SetMeta};
use super::shards::encode;
use super::writer::relative_to;
use super::{encode_exr, write_atomic, RaySet, SET_JSON};
use crate::denoise::{denoise_point, DenoiseInput, PointDenoise};
use crate::error::TraceError;
use crate::layers::{object_layer_name, LayerImage, LayerKind, PointImages};
use pis_scene::ObjectRole;
use serde::Serialize;
use std::fs;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The guides a half must carry, as pis-trace names them.
const GUIDES: [&str; 2] = ["guide.albedo", "guide.normal"];

/// Layers of adaptive sampling: a half that stopped pixels early has no fixed sample count.
const ADAPTIVE: [&str; 2] = ["samples", "error"];

/// Largest difference of two halves' camera matrices still the same camera.
const CAMERA_TOLERANCE: f32 = 1e-4;

/// What joining two halves did.
#[derive(Clone, Debug, Default, Serialize)]
pub struct HalvesReport {
    pub set: PathBuf,
    pub points: usize,
    /// Samples per pixel of the joined set: both halves'.
    pub spp: u32,
    pub denoiser: String,
    /// Layers given a denoised twin, summed over the points.
    pub denoised_layers: usize,
    /// `point N: layer` for every layer kept raw (denoising estimated to be worse).
    pub kept_raw: Vec<String>,
    pub seconds: f64,
    pub output_bytes: u64,
}

/// Joins the halves `even` and `odd` (two sets of one scene, points and cameras, rendered
/// from independent seeds at the same samples, each with `guide.albedo` and `guide.normal`)
/// into the denoised set `out`. `progress(done, points)` hears of every point written.
/// set.json is written last: until then `out` is an unfinished set.
pub fn denoise_halves(
    even: &Path,
    odd: &Path,
    out: &Path,
    progress: &dyn Fn(usize, usize),
) -> Result<HalvesReport, TraceError> {
    let start = Instant::now();
    let halves = [RaySet::open(even)?.with_raw(true), RaySet::open(odd)?.with_raw(true)];
    check_pair(&halves)?;
    let oidn = crate::oidn::shared().map_err(|e| TraceError::Denoise(e.to_string()))?;
    prepare_out(out, &halves)?;
    let objects = object_roles(&halves[0].meta)?;
    let mut meta = halves[0].meta.clone();
    let spp = meta.spp.checked_mul(2).ok_or_else(|| TraceError::InvalidSet {
        path: halves[0].dir.clone(),
        message: format!("spp {} is too large to double", meta.spp),
    })?;
    let mut report = HalvesReport {
        set: out.to_path_buf(),
        points: meta.points.len(),
        spp,
        denoiser: format!("Open Image Denoise {}", oidn.version()),
        ..HalvesReport::default()
    };
    for i in 0..meta.points.len() {
        let images = [halves[0].read_point(i)?, halves[1].read_point(i)?];
        let (joined, summary) = join_point(oidn, images, &objects, &halves[0].dir)?;
        let point = &mut meta.points[i];
        report.output_bytes += write_point(out, point, &joined, &halves[0].dir)?;
        report.denoised_layers += summary.layers.len();
        report.kept_raw.extend(summary.kept_raw.iter().map(|l| format!("point {i}: {l}")));
        point.denoise = Some(summary);
        progress(i + 1, report.points);
    }
    meta.spp = report.spp;
    meta.denoiser = Some(report.denoiser.clone());
    meta.scene_file = halves[0].scene_file().map(|f| relative_to(&f, out));
    let path = out.join(SET_JSON);
    let json = encode(&meta, &path)?;
    write_atomic(&path, &json)?;
    report.output_bytes += json.len() as u64;
    report.seconds = start.elapsed().as_secs_f64();
    Ok(report)
}

/// The halves' set.json must describe one set: the same size, samples, objects and layers,
/// and at every point the same parameter values and camera. Neither may be denoised already.
fn check_pair(halves: &[RaySet; 2]) -> Result<(), TraceError> {
    let [a, b] = [&halves[0].meta, &halves[1].meta];
    let bad = |message: String| TraceError::InvalidSet { path: halves[1].dir.clone(), message };
    for (set, meta) in halves.iter().zip([a, b]) {
        if meta.denoiser.is_some() || set.is_denoised() {
            return Err(TraceError::InvalidSet {
                path: set.dir.clone(),
                message: "the set is denoised already: halves are raw renders".into(),
            });
        }
    }
    if (a.resolution, a.spp, a.points.len()) != (b.resolution, b.spp, b.points.len()) {
        return Err(bad(format!(
            "{}x{}, {} spp, {} points; the even half has {}x{}, {} spp, {} points",
            b.resolution[0],
            b.resolution[1],
            b.spp,
            b.points.len(),
            a.resolution[0],
            a.resolution[1],
            a.spp,
            a.points.len()
        )));
    }
    if a.objects != b.objects || a.filter != b.filter {
        return Err(bad("its objects, layers or filter differ from the even half's".into()));
    }
    for (p, q) in a.points.iter().zip(&b.points) {
        if let Some(why) = point_differs(p, q) {
            return Err(bad(format!("points[{}]: {why}", q.index)));
        }
    }
    Ok(())
}

/// Why two halves' entries for one point are not the same point, if they are not.
fn point_differs(p: &PointMeta, q: &PointMeta) -> Option<String> {
    if p.values != q.values {
        return Some(format!("values {:?}, the even half's {:?}", q.values, p.values));
    }
    let [m, n] = [&p.camera.world_from_camera, &q.camera.world_from_camera];
    let far = m.iter().zip(n).map(|(x, y)| (x - y).abs()).fold(0.0, f32::max);
    (far > CAMERA_TOLERANCE || p.camera.yfov != q.camera.yfov)
        .then(|| format!("the camera differs from the even half's (by {far:.2e} in its matrix)"))
}

/// The objects by channel name and role, as the denoiser reads them.
fn object_roles(meta: &SetMeta) -> Result<Vec<(String, ObjectRole)>, TraceError> {
    meta.objects
        .iter()
        .map(|o| {
            let role = ObjectRole::ALL.into_iter().find(|r| r.name() == o.role);
            role.map(|r| (o.channel_name.clone(), r)).ok_or_else(|| {
                TraceError::InvalidInput(format!("object {:?}: unknown role {:?}", o.name, o.role))
            })
        })
        .collect()
}

/// Makes `out`, which must be neither half, and takes away a set.json a run before left.
fn prepare_out(out: &Path, halves: &[RaySet; 2]) -> Result<(), TraceError> {
    fs::create_dir_all(out).map_err(|e| TraceError::io(out, e))?;
    let here = fs::canonicalize(out).map_err(|e| TraceError::io(out, e))?;
    for h in halves {
        if fs::canonicalize(&h.dir).is_ok_and(|d| d == here) {
            return Err(TraceError::InvalidInput(format!(
                "{}: the output is one of the halves; write the joined set to a folder of its own",
                out.display()
            )));
        }
    }
    match fs::remove_file(out.join(SET_JSON)) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => Err(TraceError::io(out, e)),
        _ => Ok(()),
    }
}

/// One point joined: the halves' mean, its guides, and the denoised twins.
fn join_point(
    oidn: &crate::oidn::Oidn,
    halves: [PointImages; 2],
    objects: &[(String, ObjectRole)],
    dir: &Path,
) -> Result<(PointImages, PointDenoise), TraceError> {
    let mut joined = mean(&halves, dir)?;
    let guides = GUIDES.map(|g| joined.layer(g).cloned());
    let [Some(albedo), Some(normal)] = guides else {
        return Err(TraceError::InvalidSet {
            path: dir.to_path_buf(),
            message: "the points have no `guide.albedo` and `guide.normal` layers: render the halves with the denoiser's guides".into(),
        });
    };
    let input = DenoiseInput { guides: [albedo, normal], halves };
    let denoised = denoise_point(oidn, &joined, &input, objects)?;
    joined.layers.extend(denoised.images);
    Ok((joined, denoised.summary))
}

/// Every layer of the even half averaged with the odd half's of the same name and channels,
/// as one render at both halves' samples would hold it: the combined image, coverages and
/// guides plainly, an object's other layers (values over its coverage, section 4) weighted
/// by the coverage each half has at the pixel.
fn mean(halves: &[PointImages; 2], dir: &Path) -> Result<PointImages, TraceError> {
    let [a, b] = [&halves[0], &halves[1]];
    let bad = |message: String| TraceError::InvalidSet { path: dir.to_path_buf(), message };
    if (a.width, a.height) != (b.width, b.height) || a.layers.len() != b.layers.len() {
        return Err(bad("the halves' point images differ in size or layers".into()));
    }
    let mut layers = Vec::with_capacity(a.layers.len());
    for la in &a.layers {
        if ADAPTIVE.contains(&la.name.as_str()) {
            return Err(bad(format!(
                "layer `{}`: halves are fixed-sample renders (no adaptive sampling)",
                la.name
            )));
        }
        let lb = b.layer(&la.name).filter(|l| l.channels == la.channels).ok_or_else(|| {
            bad(format!("layer `{}` is not in the odd half with the same channels", la.name))
        })?;
        let weights = match coverage_of(&la.name) {
            Some(name) => {
                let [ca, cb] = [a, b].map(|h| h.layer(&name).map(|l| &l.planes[0]));
                let (Some(ca), Some(cb)) = (ca, cb) else {
                    return Err(bad(format!("layer `{}` has no `{name}` beside it", la.name)));
                };
                Some((ca, cb))
            }
            None => None,
        };
        let planes = la.planes.iter().zip(&lb.planes).map(|(p, q)| blend(p, q, weights)).collect();
        layers.push(LayerImage {
            name: la.name.clone(),
            channels: la.channels.clone(),
            width: la.width,
            height: la.height,
            planes,
        });
    }
    Ok(PointImages { width: a.width, height: a.height, layers })
}

/// The coverage layer an object layer is divided by (`object.o.coverage` for `object.o.diffuse`);
/// `None` for the combined image, guides and coverages themselves.
fn coverage_of(layer: &str) -> Option<String> {
    let (object, kind) = layer.strip_prefix("object.")?.rsplit_once('.')?;
    (kind != LayerKind::Coverage.name()).then(|| object_layer_name(object, LayerKind::Coverage))
}

/// The mean of two planes, weighted per pixel by `weights` (0 where both are 0).
fn blend(p: &[f32], q: &[f32], weights: Option<(&Vec<f32>, &Vec<f32>)>) -> Vec<f32> {
    match weights {
        None => p.iter().zip(q).map(|(x, y)| 0.5 * (x + y)).collect(),
        Some((wp, wq)) => (0..p.len())
            .map(|i| {
                let w = wp[i] + wq[i];
                if w > 0.0 {
                    (wp[i] * p[i] + wq[i] * q[i]) / w
                } else {
                    0.0
                }
            })
            .collect(),
    }
}

/// Writes the joined point's EXR (and copies the even half's ray records, the same
/// geometry) into `out`; returns the bytes written.
fn write_point(
    out: &Path,
    point: &PointMeta,
    images: &PointImages,
    even: &Path,
) -> Result<u64, TraceError> {
    let path = out.join(&point.image);
    let bytes = encode_exr(images, &path)?;
    write_atomic(&path, &bytes)?;
    let mut written = bytes.len() as u64;
    if let Some(rays) = &point.rays {
        let from = even.join(rays);
        let data = fs::read(&from).map_err(|e| TraceError::io(&from, e))?;
        write_atomic(&out.join(rays), &data)?;
        written += data.len() as u64;
    }
    Ok(written)
}
