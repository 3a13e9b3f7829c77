//! Inference of every object's layers as parameterized surface textures (thesis 3.5, 4.8):
//! a view-independent diffuse layer solved once over all views by stacking, and a
//! view-dependent specular layer solved per parameter sample, each warm-started from the
//! neighbouring sample. Layers that are black for an object are left out. Every solve is
//! pyramidal (ε_f = 0.1) in the decimated parameterization: the unknowns are level 0 and the
//! coarser levels its decimations, as the player stores and rebuilds them.

use std::collections::BTreeMap;

use anyhow::{anyhow, Result};
use pis_compile::{solve, solve_view_independent, DrawMesh, RenderMatrix, SolveSettings, TexturedObject, View, Viewport};
use pis_format::{DepMask, DimensionKind};
use pis_trace::layers::LayerKind as TraceLayer;
use pis_trace::PointImages;

use super::input::LoadedSet;
use super::matrices::Matrices;
use super::{PackRequest, Stages};
use crate::infer::{merged_mesh, place, restrict, sampler, Mesh, Prepared};

/// Largest linear radiance below which a layer counts as black.
pub const BLACK: f32 = 1e-4;

/// One point as the render matrix sees an object (hardware model or probe mode): its covered
/// rows of A and the gold standard of each layer there.
pub(crate) struct PointView {
    pub(crate) a: RenderMatrix,
    pub(crate) diffuse: Vec<f32>,
    pub(crate) specular: Vec<f32>,
}

/// A solved layer: one texture (the whole MIP chain, [`Prepared::layout`]) per sample of
/// the dimensions it depends on.
pub(crate) struct InferredLayer {
    pub(crate) kind: pis_format::LayerKind,
    pub(crate) depends_on: DepMask,
    /// Key: sample index per masked dimension, in dimension order.
    pub(crate) textures: BTreeMap<Vec<u32>, Vec<f32>>,
    pub(crate) iterations: u64,
}

/// An object's inferred representation.
pub(crate) struct ObjectModel {
    pub(crate) index: usize,
    pub(crate) name: String,
    pub(crate) mesh: Mesh,
    pub(crate) prep: Prepared,
    /// Mean covered pixels per point: the screen-area weight of allocation.
    pub(crate) area: f64,
    /// Per point of the set.
    pub(crate) views: Vec<PointView>,
    pub(crate) layers: Vec<InferredLayer>,
    /// What was chosen and why.
    pub(crate) representation: String,
    pub(crate) why: String,
}

/// The key of `samples` under `mask`.
pub(crate) fn key(samples: &[u32], mask: DepMask) -> Vec<u32> {
    mask.dims().map(|k| samples[k]).collect()
}

fn layer_rgb(images: &PointImages, channel: &str, kind: TraceLayer) -> Vec<f32> {
    let n = images.width as usize * images.height as usize;
    let mut rgb = vec![0.0f32; n * 3];
    if let Some(l) = images.object_layer(channel, kind) {
        for (c, name) in ["R", "G", "B"].iter().enumerate() {
            if let Some(p) = l.channel(name) {
                for k in 0..n {
                    rgb[k * 3 + c] = p[k];
                }
            }
        }
    }
    rgb
}

fn views_of(set: &LoadedSet, o: usize, prep: &Prepared, meshes: &[Mesh], req: &PackRequest, matrices: &mut Matrices) -> Result<Vec<PointView>> {
    let (w, h) = set.resolution;
    let viewport = Viewport { width: w, height: h };
    let mut out = Vec::with_capacity(set.frames.len());
    for (frame, images) in set.frames.iter().zip(&set.images) {
        let clip_from = |k: usize| {
            pis_trace::camera::projection_matrix(&frame.camera, (w, h))
                * frame.camera.world_from_camera.inverse() * frame.instances[k].world_from_object
        };
        let draw: Vec<DrawMesh> = meshes.iter().enumerate().map(|(k, m)| DrawMesh {
            positions: &m.positions, uvs: &m.uvs, indices: &m.indices, clip_from_object: clip_from(k),
        }).collect();
        let mut mesh = draw[o];
        mesh.uvs = &prep.mesh_uvs;
        let obj = TexturedObject { mesh, transform: prep.transform, layout: prep.layout, sampler: sampler(req.filter, prep.repeat) };
        let a_full = matrices.matrix(viewport, &draw, o, &obj)?;
        let channel = &set.channels[o];
        let cov: Vec<f32> = images.object_layer(channel, TraceLayer::Coverage).and_then(|l| l.channel("A"))
            .map(<[f32]>::to_vec).unwrap_or_else(|| vec![0.0; (w * h) as usize]);
        let (a, diffuse) = restrict(&a_full, &cov, &layer_rgb(images, channel, TraceLayer::Diffuse));
        let (_, specular) = restrict(&a_full, &cov, &layer_rgb(images, channel, TraceLayer::Specular));
        out.push(PointView { a, diffuse, specular });
    }
    Ok(out)
}

/// Half a step of an 8-bit display value: a layer whose removal moves no covered pixel by
/// more than this changes no displayed pixel.
pub const DISPLAY_STEP: f32 = 0.5 / 255.0;

/// True when the layer `pick` is black for the display: zero (below [`BLACK`]), or so dark
/// beside the other layer `other` that leaving it out changes no 8-bit pixel.
fn is_black(views: &[PointView], pick: impl Fn(&PointView) -> &[f32], other: impl Fn(&PointView) -> &[f32]) -> bool {
    let d = |v: f32| crate::images::srgb_encode(v.clamp(0.0, 1.0));
    views.iter().all(|v| pick(v).iter().zip(other(v)).all(|(x, o)| x.abs() < BLACK || (d(x + o) - d(*o)).abs() < DISPLAY_STEP))
}

/// One view-dependent layer of diffuse + specular radiance per parameter sample (no
/// lighting-layer separation), warm-started from the previous sample like the specular layer.
fn combined_layer(set: &LoadedSet, views: &[PointView], prep: &Prepared, settings: &SolveSettings) -> Result<InferredLayer> {
    let all = DepMask::of(&(0..set.scene.space.dims.len()).collect::<Vec<_>>());
    let mut textures = BTreeMap::new();
    let mut warm: Option<Vec<f32>> = None;
    let mut iterations = 0u64;
    for (p, s) in set.samples.iter().enumerate() {
        let v = &views[p];
        let x = if v.a.rows() == 0 {
            warm.clone().unwrap_or_else(|| vec![0.0; prep.layout.texel_count() * 3])
        } else {
            let b: Vec<f32> = v.diffuse.iter().zip(&v.specular).map(|(d, s)| d + s).collect();
            let sol = solve(&v.a, &b, warm.as_deref(), settings)?;
            iterations += sol.iterations as u64;
            sol.texels
        };
        warm = Some(x.clone());
        textures.insert(key(s, all), x);
    }
    Ok(InferredLayer { kind: pis_format::LayerKind::Specular, depends_on: all, textures, iterations })
}

/// Infers every object that covers a pixel somewhere in the set.
pub(crate) fn infer_all(set: &LoadedSet, req: &PackRequest, matrices: &mut Matrices, stages: &mut Stages) -> Result<Vec<ObjectModel>> {
    let scene = &set.scene;
    let meshes: Vec<Mesh> = (0..scene.objects.len()).map(|o| merged_mesh(scene, o)).collect();
    let frames: Vec<&pis_scene::Frame> = set.frames.iter().collect();
    let view_dims: Vec<usize> = scene.space.dims.iter().enumerate().filter(|(_, d)| d.kind == DimensionKind::View).map(|(k, _)| k).collect();
    let all = DepMask::of(&(0..scene.space.dims.len()).collect::<Vec<_>>());
    let non_view = DepMask::of(&(0..scene.space.dims.len()).filter(|k| !view_dims.contains(k)).collect::<Vec<_>>());
    // Level 0 solved through the MIP chain the player decimates from it (thesis 3.6): the
    // solved textures are the drawn ones.
    let mut settings = SolveSettings::decimated();
    if let Some(n) = req.max_iterations {
        settings.cg.max_iterations = n.max(1);
    }
    let combined = req.layers == super::LayerMode::Combined;
    // Texture coordinates and render matrices of every object at every point first, so the
    // matrix source's cost is a stage of its own.
    let mut placed = Vec::with_capacity(scene.objects.len());
    for o in 0..scene.objects.len() {
        let prep = place(scene, &frames, set.resolution, o, &meshes[o], req.max_texture, 1.0, req.texels_per_pixel)?;
        let before = matrices.renderings();
        let views = views_of(set, o, &prep, &meshes, req, matrices)?;
        if matrices.renderings() > before {
            eprintln!("pis-pack: object {}: {} probe renderings over {} points", scene.objects[o].name, matrices.renderings() - before, views.len());
        }
        placed.push((prep, views));
    }
    stages.done("matrices", &format!("texture coordinates and render matrices of {} objects × {} points ({})", scene.objects.len(), set.frames.len(), matrices.describe()));
    let mut out = Vec::new();
    for (o, (prep, views)) in placed.into_iter().enumerate() {
        let name = scene.objects[o].name.clone();
        let covered: usize = views.iter().map(|v| v.a.rows()).sum();
        if covered == 0 {
            eprintln!("pis-pack: object {name} covers no pixel of the set; left out");
            continue;
        }
        let area = covered as f64 / views.len() as f64;
        let mut layers = Vec::new();
        let diffuse_black = is_black(&views, |v| &v.diffuse, |v| &v.specular);
        let specular_black = is_black(&views, |v| &v.specular, |v| &v.diffuse);
        if diffuse_black && specular_black {
            eprintln!("pis-pack: object {name} is black in every layer; nothing stored");
            continue;
        }
        if combined {
            let layer = combined_layer(set, &views, &prep, &settings)?;
            let (representation, why) = ("combined".to_string(), "--layers combined: one view-dependent layer of diffuse + specular radiance per parameter sample".to_string());
            eprintln!("pis-pack: object {name}: {}x{} texels, {representation}", prep.layout.width, prep.layout.height);
            out.push(ObjectModel { index: o, name, mesh: merged_mesh(scene, o), prep, area, views, layers: vec![layer], representation, why });
            continue;
        }
        if !diffuse_black {
            // Stacked over the views of each non-view sample (thesis 4.8: one diffuse
            // texture per light position).
            let mut groups: BTreeMap<Vec<u32>, Vec<usize>> = BTreeMap::new();
            for (p, s) in set.samples.iter().enumerate() {
                groups.entry(key(s, non_view)).or_default().push(p);
            }
            let mut textures = BTreeMap::new();
            let mut warm: Option<Vec<f32>> = None;
            let mut iterations = 0u64;
            for (k, points) in groups {
                let vs: Vec<View> = points.iter().map(|&p| View { a: &views[p].a, b: &views[p].diffuse }).collect();
                let s = solve_view_independent(&vs, warm.as_deref(), &settings)?;
                iterations += s.iterations as u64;
                warm = Some(s.texels.clone());
                textures.insert(k, s.texels);
            }
            layers.push(InferredLayer { kind: pis_format::LayerKind::Diffuse, depends_on: non_view, textures, iterations });
        }
        if !specular_black {
            let mut textures = BTreeMap::new();
            let mut warm: Option<Vec<f32>> = None;
            let mut iterations = 0u64;
            for (p, s) in set.samples.iter().enumerate() {
                let v = &views[p];
                let x = if v.a.rows() == 0 {
                    warm.clone().unwrap_or_else(|| vec![0.0; prep.layout.texel_count() * 3])
                } else {
                    let sol = solve(&v.a, &v.specular, warm.as_deref(), &settings)?;
                    iterations += sol.iterations as u64;
                    sol.texels
                };
                warm = Some(x.clone());
                textures.insert(key(s, all), x);
            }
            layers.push(InferredLayer { kind: pis_format::LayerKind::Specular, depends_on: all, textures, iterations });
        }
        let (representation, why) = match (diffuse_black, specular_black) {
            (false, true) => ("diffuse".to_string(), "the specular layer changes no displayed pixel: one view-independent diffuse texture per non-view sample".to_string()),
            (true, false) => ("specular".to_string(), "the diffuse layer changes no displayed pixel: a view-dependent texture per parameter sample".to_string()),
            (false, false) => ("diffuse+specular".to_string(), "view-independent diffuse layer over the non-view dimensions plus a view-dependent specular layer per parameter sample".to_string()),
            (true, true) => ("black".to_string(), "both layers black: nothing stored".to_string()),
        };
        eprintln!("pis-pack: object {name}: {}x{} texels, {representation} ({why})", prep.layout.width, prep.layout.height);
        out.push(ObjectModel { index: o, name, mesh: merged_mesh(scene, o), prep, area, views, layers, representation, why });
    }
    if out.is_empty() {
        return Err(anyhow!("no object covers a pixel of the set"));
    }
    stages.done("infer", &format!("{} objects solved", out.len()));
    Ok(out)
}
