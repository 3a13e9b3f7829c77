//! Played frames against the ray-traced gold standard: every sample point of a set drawn
//! through the player (offscreen), PSNR on display values per object and for the whole
//! image.
//!
//! Per object, the measure is pis-pack's prediction's: the pixels the player draws the
//! object at (its object index at the pixel's centre) that the tracer's coverage says the
//! object covers, the object's radiance there against its gold surface radiance (diffuse +
//! specular layers, both stored divided by coverage: the object's own radiance, unmixed with
//! what lies around it). A multisampled frame's resolved pixel mixes the objects of its
//! neighbourhood as the gold standard's combined image does, not as its layers do: at a
//! silhouette it is mostly the background's, and a small object's pixels are nearly all
//! silhouette. So the objects are measured on the frame's single-sample twin
//! ([`Player::render_centres`]: each pixel wholly the surface at its centre), and only the
//! whole image (with its silhouette and interior split) on the multisampled frame, against
//! the set's combined image. A translucent object (SPEC.md 9) has no radiance of its own
//! on screen: it is measured on what shows where it is nearest, itself over what lies
//! behind it, against the combined image.

use std::path::Path;

use anyhow::{anyhow, bail, Context, Result};
use pis_format::blocks::BlockGrid;
use pis_play::{CameraChoice, FloatImage, FrameRequest, Player};
use pis_trace::layers::{LayerKind, PointImages};
use pis_trace::set::RaySet;

use crate::metrics::SquaredError;

/// Coverage this close to 0 or 1 counts as none or full (float rounding of the filter).
const COVERAGE_EPS: f32 = 1e-4;

/// Comparison settings.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CompareOptions {
    /// Frame size; default the set's resolution (other sizes are compared after nothing:
    /// the size must equal the set's for pixel-wise PSNR).
    pub size: Option<(u32, u32)>,
}

/// One parameter block of one object.
#[derive(Clone, Debug, PartialEq)]
pub struct BlockScore {
    pub block: usize,
    pub psnr_db: f64,
    pub error: SquaredError,
}

/// One object over all points.
#[derive(Clone, Debug, PartialEq)]
pub struct ObjectScore {
    pub name: String,
    pub psnr_db: f64,
    pub error: SquaredError,
    pub blocks: Vec<BlockScore>,
}

/// One sample point.
#[derive(Clone, Debug, PartialEq)]
pub struct PointComparison {
    pub index: usize,
    pub point: Vec<f32>,
    /// Whole image.
    pub psnr_db: f64,
    pub objects: Vec<ObjectScore>,
}

/// All points.
#[derive(Clone, Debug, PartialEq)]
pub struct Comparison {
    /// Whole image, every point.
    pub psnr_db: f64,
    /// Every object's covered pixels pooled (each object's measure, summed over objects):
    /// what pis-pack reports as its predicted `psnr_db`.
    pub covered_psnr_db: f64,
    /// The whole image split by the gold standard's coverage: silhouette pixels are those
    /// some object covers partly (its filtered coverage strictly between 0 and 1: an edge
    /// the display filter mixes with what lies behind), interior pixels all others.
    pub interior: SquaredError,
    pub silhouette: SquaredError,
    pub objects: Vec<ObjectScore>,
    pub points: Vec<PointComparison>,
}

/// One drawn frame with its gold image, handed to the caller as it is compared.
pub struct FramePair<'a> {
    pub index: usize,
    pub point: &'a [f32],
    pub rendered: &'a FloatImage,
    pub gold: &'a FloatImage,
    pub object_ids: &'a [u32],
}

/// Draws every sample point of the set at `set_dir` through `player` (offscreen, the file's
/// camera at each point) and compares. `each` sees every frame with its gold image.
pub fn compare_with_set(
    player: &mut Player,
    set_dir: &Path,
    options: &CompareOptions,
    each: &mut dyn FnMut(&FramePair),
) -> Result<Comparison> {
    let set = RaySet::open(set_dir)
        .with_context(|| format!("opening the ray-traced set {}", set_dir.display()))?;
    let res = (set.meta.resolution[0], set.meta.resolution[1]);
    let size = options.size.unwrap_or(res);
    if size != res {
        bail!(
            "frames of {}x{} cannot be compared pixel by pixel with the set's {}x{} gold images",
            size.0,
            size.1,
            res.0,
            res.1
        );
    }
    let names = player.object_names();
    let translucent = player.translucent_objects();
    let channels = channels(&set, &names, set_dir)?;
    let grids = score_grids(player);
    let block_count = |o: usize| grids[o].block_count() as usize;
    let mut total = SquaredError::default();
    let (mut interior, mut silhouette) = (SquaredError::default(), SquaredError::default());
    let mut partial = vec![false; 0];
    let mut per_object: Vec<(SquaredError, Vec<SquaredError>)> = (0..names.len())
        .map(|o| (SquaredError::default(), vec![SquaredError::default(); block_count(o)]))
        .collect();
    let mut points = Vec::with_capacity(set.meta.points.len());
    for (i, p) in set.meta.points.iter().enumerate() {
        let images = checked_point(&set, set_dir, i, player)?;
        let req = FrameRequest { point: p.values.clone(), camera: CameraChoice::Sample };
        let (rendered, ids, _) = player
            .render_ids(&req, size)
            .with_context(|| format!("drawing point {i} {:?}", p.values))?;
        let centres = if player.multisample().samples > 1 {
            let (img, ids, _) = player
                .render_centres(&req, size)
                .with_context(|| format!("drawing point {i} {:?}", p.values))?;
            Some((img, ids))
        } else {
            None
        };
        let (own, own_ids) = centres.as_ref().map_or((&rendered, &ids), |(img, ids)| (img, ids));
        let gold = gold_image(&images, res, i, set_dir)?;
        silhouette_pixels(&images, &channels, &mut partial);
        let mut whole = SquaredError::default();
        for (k, &edge) in partial.iter().enumerate() {
            let mut px = SquaredError::default();
            for c in 0..3 {
                px.add(rendered.rgba[k * 4 + c], gold.rgba[k * 4 + c]);
            }
            whole.merge(&px);
            if edge {
                silhouette.merge(&px)
            } else {
                interior.merge(&px)
            }
        }
        let mut objects = Vec::with_capacity(names.len());
        for (o, ch) in channels.iter().enumerate() {
            let e = if translucent[o] {
                seen_through_error(&images, ch, o, own_ids, own, &gold)
            } else {
                object_error(&images, ch, o, own_ids, own)
            };
            let block = grids[o].locate(&p.samples).block;
            per_object[o].0.merge(&e);
            if let Some(b) = per_object[o].1.get_mut(block) {
                b.merge(&e);
            }
            objects.push(ObjectScore {
                name: names[o].clone(),
                psnr_db: e.psnr(),
                error: e,
                blocks: vec![BlockScore { block, psnr_db: e.psnr(), error: e }],
            });
        }
        total.merge(&whole);
        each(&FramePair {
            index: i,
            point: &p.values,
            rendered: &rendered,
            gold: &gold,
            object_ids: &ids,
        });
        points.push(PointComparison {
            index: i,
            point: p.values.clone(),
            psnr_db: whole.psnr(),
            objects,
        });
    }
    let mut covered = SquaredError::default();
    let objects = per_object
        .into_iter()
        .zip(&names)
        .map(|((e, blocks), name)| {
            covered.merge(&e);
            ObjectScore {
                name: name.clone(),
                psnr_db: e.psnr(),
                error: e,
                blocks: blocks
                    .into_iter()
                    .enumerate()
                    .filter(|(_, b)| b.count > 0)
                    .map(|(block, b)| BlockScore { block, psnr_db: b.psnr(), error: b })
                    .collect(),
            }
        })
        .collect();
    Ok(Comparison {
        psnr_db: total.psnr(),
        covered_psnr_db: covered.psnr(),
        interior,
        silhouette,
        objects,
        points,
    })
}

/// Point `i` of the set at `set_dir`, read, once its parameter values, size and camera are
/// checked against the file `player` plays.
fn checked_point(set: &RaySet, set_dir: &Path, i: usize, player: &Player) -> Result<PointImages> {
    let p = &set.meta.points[i];
    let dims = player.dimensions().len();
    let res = (set.meta.resolution[0], set.meta.resolution[1]);
    if p.values.len() != dims || p.samples.len() != dims {
        bail!(
            "point {i} of {} has {} values, the file's parameter space {dims} dimensions",
            set_dir.display(),
            p.values.len()
        );
    }
    let images =
        set.read_point(i).with_context(|| format!("reading point {i} of {}", set_dir.display()))?;
    if (images.width, images.height) != res {
        bail!(
            "point {i} of {} is {}x{}, the set declares {}x{}",
            set_dir.display(),
            images.width,
            images.height,
            res.0,
            res.1
        );
    }
    let (pose, yfov) = player.sample_pose(&p.values);
    if let Some(d) = p.camera.differs_from(pose, yfov) {
        return Err(pis_trace::TraceError::InvalidSet {
            path: set_dir.to_path_buf(),
            message: format!("point {i}: the file's camera is not the one the set was traced with ({d}): the file was packed from another scene or preset"),
        }
        .into());
    }
    Ok(images)
}

/// Per object of the file: the set's channel name.
fn channels(set: &RaySet, names: &[String], set_dir: &Path) -> Result<Vec<String>> {
    names
        .iter()
        .map(|n| {
            set.meta
                .objects
                .iter()
                .find(|o| &o.name == n)
                .map(|o| o.channel_name.clone())
                .ok_or_else(|| {
                    anyhow!("object '{n}' of the file is not in the set {}", set_dir.display())
                })
        })
        .collect()
}

/// Per object: the grid of its layer that depends on the most dimensions (the blocks a
/// score is reported for).
fn score_grids(player: &Player) -> Vec<BlockGrid> {
    let c = player.reader().container();
    c.objects
        .iter()
        .map(|o| {
            let mask = o
                .layers
                .iter()
                .map(|l| l.depends_on)
                .max_by_key(|m| m.count())
                .unwrap_or(pis_format::DepMask::NONE);
            BlockGrid::new(&c.space, mask, &o.stagger)
        })
        .collect()
}

/// Point `i`'s gold image: the set's combined image, alpha 1.
fn gold_image(
    images: &PointImages,
    res: (u32, u32),
    i: usize,
    set_dir: &Path,
) -> Result<FloatImage> {
    let npx = res.0 as usize * res.1 as usize;
    let combined = images
        .layer("combined")
        .ok_or_else(|| anyhow!("point {i} of {} has no combined image", set_dir.display()))?;
    let mut gold = FloatImage { width: res.0, height: res.1, rgba: vec![1.0; npx * 4] };
    for (c, name) in ["R", "G", "B"].iter().enumerate() {
        let plane = combined
            .channel(name)
            .ok_or_else(|| anyhow!("point {i}: combined image without {name}"))?;
        for (px, v) in gold.rgba.chunks_exact_mut(4).zip(plane) {
            px[c] = *v;
        }
    }
    Ok(gold)
}

/// Marks in `partial` the silhouette pixels: those some object covers partly.
fn silhouette_pixels(images: &PointImages, channels: &[String], partial: &mut Vec<bool>) {
    let npx = images.width as usize * images.height as usize;
    partial.clear();
    partial.resize(npx, false);
    for ch in channels {
        if let Some(cov) = images.object_layer(ch, LayerKind::Coverage).and_then(|l| l.channel("A"))
        {
            for (p, &c) in partial.iter_mut().zip(cov) {
                *p |= c > COVERAGE_EPS && c < 1.0 - COVERAGE_EPS;
            }
        }
    }
}

/// A translucent object `o`'s error over the pixels the player draws it at (its surface
/// nearest at the centre) and the tracer's coverage says it covers: what shows there, the
/// object over what lies behind it, against the gold standard's combined image.
fn seen_through_error(
    images: &PointImages,
    ch: &str,
    o: usize,
    ids: &[u32],
    rendered: &FloatImage,
    gold: &FloatImage,
) -> SquaredError {
    let cov = images.object_layer(ch, LayerKind::Coverage).and_then(|l| l.channel("A"));
    let mut e = SquaredError::default();
    if let Some(cov) = cov {
        for (k, (&id, &c)) in ids.iter().zip(cov).enumerate() {
            if id == o as u32 && c > 0.0 {
                (0..3).for_each(|i| e.add(rendered.rgba[k * 4 + i], gold.rgba[k * 4 + i]));
            }
        }
    }
    e
}

/// Object `o`'s error over the pixels the player draws it at and the tracer's coverage says
/// it covers, against its gold surface radiance (diffuse + specular).
fn object_error(
    images: &PointImages,
    ch: &str,
    o: usize,
    ids: &[u32],
    rendered: &FloatImage,
) -> SquaredError {
    let npx = images.width as usize * images.height as usize;
    let layer = |kind: LayerKind| images.object_layer(ch, kind);
    let cov = layer(LayerKind::Coverage).and_then(|l| l.channel("A"));
    let (d, s) = (layer(LayerKind::Diffuse), layer(LayerKind::Specular));
    let planes: Vec<[Option<&[f32]>; 2]> = ["R", "G", "B"]
        .iter()
        .map(|c| [d.and_then(|l| l.channel(c)), s.and_then(|l| l.channel(c))])
        .collect();
    let mut e = SquaredError::default();
    if let Some(cov) = cov {
        for k in 0..npx {
            if ids[k] != o as u32 || cov[k] <= 0.0 {
                continue;
            }
            for (c, [dp, sp]) in planes.iter().enumerate() {
                let g = dp.map_or(0.0, |p| p[k]) + sp.map_or(0.0, |p| p[k]);
                e.add(rendered.rgba[k * 4 + c], g);
            }
        }
    }
    e
}
