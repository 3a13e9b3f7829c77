//! Inference of every object's layers as parameterized surface textures (thesis 3.5, 4.8):
//! a view-independent diffuse layer solved once over all views by stacking, and a
//! view-dependent specular layer solved per parameter sample, each warm-started from the
//! last sample solved with the same placement. Layers that are black for an object are left
//! out. Every solve is pyramidal (ε_f = 0.1) in the decimated parameterization: the unknowns
//! are level 0 and the coarser levels its decimations, as the player stores and rebuilds them.
//!
//! Texture coordinates (thesis 3.2) are optimized per object per parameter block: each block
//! of a layer gets the branch cuts, affine map and used size that suit the views of its
//! samples, so every point has one render matrix per placement its layers read.

use std::borrow::Cow;
use std::collections::BTreeMap;

use anyhow::{anyhow, Result};
use pis_compile::{solve, solve_view_independent, DrawMesh, RenderMatrix, SolveSettings, TextureLayout, TexturedObject, View, Viewport};
use pis_format::blocks::BlockGrid;
use pis_format::{DepMask, DimensionKind};
use pis_trace::layers::LayerKind as TraceLayer;
use pis_trace::PointImages;

use super::blocks::{block_sizes, geometry, stagger};
use super::input::LoadedSet;
use super::matrices::Matrices;
use super::{PackRequest, PlacementMode, Stages};
use crate::infer::{atlas, gather, merged_mesh, place_in, restrict_rows, sampler, Atlas, Mesh, Placed};

/// Largest linear radiance below which a layer counts as black.
pub const BLACK: f32 = 1e-4;

/// One point as the render matrices see an object (hardware model or probe mode): the rows
/// of A per placement its layers read there (the rows, the covered pixels, are the same for
/// every placement) and the gold standard of each layer at those pixels.
pub struct PointView {
    a: Vec<(usize, RenderMatrix)>,
    pub diffuse: Vec<f32>,
    pub specular: Vec<f32>,
}

impl PointView {
    /// The render matrix of placement `placement` (of [`ObjectModel::placements`]).
    pub fn a(&self, placement: usize) -> &RenderMatrix {
        &self.a.iter().find(|(p, _)| *p == placement).expect("a render matrix for every placement a layer reads at the point").1
    }

    /// Covered pixels.
    pub fn rows(&self) -> usize {
        self.a.first().map_or(0, |(_, a)| a.rows())
    }
}

/// A solved layer: one texture (the whole MIP chain of its placement's layout) per sample of
/// the dimensions it depends on.
pub struct InferredLayer {
    pub kind: pis_format::LayerKind,
    pub depends_on: DepMask,
    /// Key: sample index per masked dimension, in dimension order.
    pub textures: BTreeMap<Vec<u32>, Vec<f32>>,
    /// Per block of the layer's grid (SPEC.md 7.2), its placement in
    /// [`ObjectModel::placements`].
    pub block_placements: Vec<usize>,
    /// Per texture key, its block's placement.
    pub placement_of: BTreeMap<Vec<u32>, usize>,
    pub iterations: u64,
}

/// An object's inferred representation.
pub struct ObjectModel {
    pub index: usize,
    pub name: String,
    pub mesh: Mesh,
    /// The texture coordinates the file's mesh carries (before any block's branch cut).
    pub mesh_uvs: Vec<[f32; 2]>,
    /// The distinct placements of the object's blocks.
    pub placements: Vec<Placed>,
    /// Block origin offsets (thesis 4.7) and the samples per block the placements are for.
    pub stagger: Vec<u32>,
    pub block_sizes: Vec<u32>,
    /// Mean covered pixels per point: the screen-area weight of allocation.
    pub area: f64,
    /// Per point of the set.
    pub views: Vec<PointView>,
    pub layers: Vec<InferredLayer>,
    /// What was chosen and why.
    pub representation: String,
    pub why: String,
}

impl ObjectModel {
    /// The placement of sample `key` of layer `layer`.
    pub fn placed(&self, layer: usize, key: &[u32]) -> &Placed {
        &self.placements[self.layers[layer].placement_of[key]]
    }

    /// The placements the layers' blocks carry, in increasing order.
    pub fn used_placements(&self) -> Vec<usize> {
        let mut used: Vec<usize> = self.layers.iter().flat_map(|l| l.block_placements.iter().copied()).collect();
        used.sort_unstable();
        used.dedup();
        used
    }

    /// The MIP layout of sample `key` of layer `layer`.
    pub fn layout(&self, layer: usize, key: &[u32]) -> TextureLayout {
        self.placed(layer, key).layout
    }
}

/// The key of `samples` under `mask`.
pub fn key(samples: &[u32], mask: DepMask) -> Vec<u32> {
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

fn coverage(set: &LoadedSet, p: usize, o: usize) -> Vec<f32> {
    let (w, h) = set.resolution;
    set.images[p].object_layer(&set.channels[o], TraceLayer::Coverage).and_then(|l| l.channel("A"))
        .map(<[f32]>::to_vec).unwrap_or_else(|| vec![0.0; (w * h) as usize])
}

/// The render matrix of object `o` at point `p` with texture coordinates `uvs` and placement
/// `placed`, every other mesh occluding it; rows where the tracer covers no pixel removed.
#[allow(clippy::too_many_arguments)]
fn matrix_at(set: &LoadedSet, p: usize, o: usize, meshes: &[Mesh], uvs: &[[f32; 2]], placed: &Placed, req: &PackRequest, matrices: &mut Matrices) -> Result<RenderMatrix> {
    let (w, h) = set.resolution;
    let frame = &set.frames[p];
    let clip_from = |k: usize| {
        pis_trace::camera::projection_matrix(&frame.camera, (w, h)) * frame.camera.world_from_camera.inverse() * frame.instances[k].world_from_object
    };
    let draw: Vec<DrawMesh> = meshes.iter().enumerate().map(|(k, m)| DrawMesh {
        positions: &m.positions, uvs: &m.uvs, indices: &m.indices, clip_from_object: clip_from(k),
    }).collect();
    let mut mesh = draw[o];
    mesh.uvs = uvs;
    let obj = TexturedObject { mesh, transform: placed.transform, layout: placed.layout, sampler: sampler(req.filter, placed.repeat) };
    let a = matrices.matrix(Viewport { width: w, height: h }, &draw, o, &obj)?;
    Ok(restrict_rows(&a, &coverage(set, p, o)))
}

/// Every point with placement 0 (over all views): the rows, the gold standard there.
fn views_of(set: &LoadedSet, o: usize, uvs: &[[f32; 2]], placed: &Placed, meshes: &[Mesh], req: &PackRequest, matrices: &mut Matrices) -> Result<Vec<PointView>> {
    let channel = &set.channels[o];
    (0..set.frames.len()).map(|p| {
        let a = matrix_at(set, p, o, meshes, uvs, placed, req, matrices)?;
        let pick = |kind| gather(&a.pixels, &layer_rgb(&set.images[p], channel, kind));
        let (diffuse, specular) = (pick(TraceLayer::Diffuse), pick(TraceLayer::Specular));
        Ok(PointView { a: vec![(0, a)], diffuse, specular })
    }).collect()
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

/// The traced radiance a layer is solved for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Radiance {
    /// The diffuse layer: view-independent, its views stacked (eq. 3.7).
    Diffuse,
    Specular,
    /// Diffuse + specular (`--layers combined`).
    Sum,
}

impl Radiance {
    /// b at the covered pixels of `v`.
    fn at(self, v: &PointView) -> Cow<'_, [f32]> {
        match self {
            Radiance::Diffuse => Cow::Borrowed(&v.diffuse),
            Radiance::Specular => Cow::Borrowed(&v.specular),
            Radiance::Sum => Cow::Owned(v.diffuse.iter().zip(&v.specular).map(|(d, s)| d + s).collect()),
        }
    }
}

/// What one object's layers are before solving: mask, the block each point's sample is in,
/// each block's placement.
struct LayerPlan {
    kind: pis_format::LayerKind,
    radiance: Radiance,
    depends_on: DepMask,
    block_placements: Vec<usize>,
    /// Per point of the set, its sample's placement.
    point_placement: Vec<usize>,
}

/// Places the blocks of a layer with mask `mask` (thesis 3.2 per parameter block): each
/// block over the views of the points whose samples it holds; placements equal to one
/// already made are shared.
#[allow(clippy::too_many_arguments)]
fn plan_layer(
    set: &LoadedSet,
    grid: &BlockGrid,
    (kind, radiance, mask): (pis_format::LayerKind, Radiance, DepMask),
    o: usize,
    mesh: &Mesh,
    at: &Atlas,
    placements: &mut Vec<Placed>,
    req: &PackRequest,
) -> Result<LayerPlan> {
    let blocks = grid.block_count() as usize;
    let point_block: Vec<usize> = set.samples.iter().map(|s| grid.locate(s).block).collect();
    let mut block_placements = vec![0usize; blocks];
    if req.placement == PlacementMode::Block {
        for (b, slot) in block_placements.iter_mut().enumerate() {
            let frames: Vec<&pis_scene::Frame> = point_block.iter().zip(&set.frames).filter(|(pb, _)| **pb == b).map(|(_, f)| f).collect();
            if frames.is_empty() || frames.len() == set.frames.len() {
                continue;
            }
            let pl = place_in(&set.scene, &frames, set.resolution, o, mesh, at, req.max_texture, 1.0, req.texels_per_pixel)?;
            *slot = match placements.iter().position(|q| q.same(&pl)) {
                Some(i) => i,
                None => {
                    placements.push(pl);
                    placements.len() - 1
                }
            };
        }
    }
    let point_placement = point_block.iter().map(|&b| block_placements[b]).collect();
    Ok(LayerPlan { kind, radiance, depends_on: mask, block_placements, point_placement })
}

/// One texture per key of `plan`'s mask: each key's sample solved (or, for a view-independent
/// layer, its views stacked, eq. 3.7) with the render matrices of its block's placement,
/// warm-started from the last sample solved with the same placement.
fn solve_layer(set: &LoadedSet, views: &[PointView], placements: &[Placed], plan: &LayerPlan, settings: &SolveSettings) -> Result<InferredLayer> {
    let mut groups: BTreeMap<Vec<u32>, Vec<usize>> = BTreeMap::new();
    for (p, s) in set.samples.iter().enumerate() {
        groups.entry(key(s, plan.depends_on)).or_default().push(p);
    }
    let mut textures = BTreeMap::new();
    let mut placement_of = BTreeMap::new();
    let mut warm: BTreeMap<usize, Vec<f32>> = BTreeMap::new();
    let mut iterations = 0u64;
    for (k, points) in groups {
        let pid = plan.point_placement[points[0]];
        let bs: Vec<Cow<[f32]>> = points.iter().map(|&p| plan.radiance.at(&views[p])).collect();
        let vs: Vec<View> = points.iter().zip(&bs).map(|(&p, b)| View { a: views[p].a(pid), b }).collect();
        let start = warm.get(&pid).map(Vec::as_slice);
        let x = if plan.radiance == Radiance::Diffuse {
            // One texture for the views of the sample, stacked (eq. 3.7).
            let s = solve_view_independent(&vs, start, settings)?;
            iterations += s.iterations as u64;
            s.texels
        } else if vs[0].a.rows() == 0 {
            // A view-dependent sample (one point per key) where the object covers no pixel.
            start.map_or_else(|| vec![0.0; placements[pid].layout.texel_count() * 3], <[f32]>::to_vec)
        } else {
            let s = solve(vs[0].a, vs[0].b, start, settings)?;
            iterations += s.iterations as u64;
            s.texels
        };
        warm.insert(pid, x.clone());
        placement_of.insert(k.clone(), pid);
        textures.insert(k, x);
    }
    Ok(InferredLayer { kind: plan.kind, depends_on: plan.depends_on, textures, block_placements: plan.block_placements.clone(), placement_of, iterations })
}

/// An object with its blocks placed: texture coordinates, placements, block origins, the
/// points with the render matrices its layers read, the layers to solve.
struct Planned {
    o: usize,
    atlas: Atlas,
    placements: Vec<Placed>,
    stagger: Vec<u32>,
    views: Vec<PointView>,
    plans: Vec<LayerPlan>,
}

/// An object that covers a pixel and is not black: its texture coordinates, placement over
/// all views and the points as that placement sees them.
struct Covered {
    o: usize,
    atlas: Atlas,
    views: Vec<PointView>,
    whole: Placed,
    diffuse_black: bool,
    specular_black: bool,
}

/// Infers every object that covers a pixel somewhere in the set.
pub fn infer_all(set: &LoadedSet, req: &PackRequest, matrices: &mut Matrices, stages: &mut Stages) -> Result<Vec<ObjectModel>> {
    let scene = &set.scene;
    let meshes: Vec<Mesh> = (0..scene.objects.len()).map(|o| merged_mesh(scene, o)).collect();
    let frames: Vec<&pis_scene::Frame> = set.frames.iter().collect();
    let ndims = scene.space.dims.len();
    let sizes = block_sizes(req.block.as_slice(), ndims)?;
    let (space, _) = geometry(set, &sizes);
    let view_dims: Vec<usize> = scene.space.dims.iter().enumerate().filter(|(_, d)| d.kind == DimensionKind::View).map(|(k, _)| k).collect();
    let all = DepMask::of(&(0..ndims).collect::<Vec<_>>());
    let non_view = DepMask::of(&(0..ndims).filter(|k| !view_dims.contains(k)).collect::<Vec<_>>());
    // Level 0 solved through the MIP chain the player decimates from it (thesis 3.6): the
    // solved textures are the drawn ones.
    let mut settings = SolveSettings::decimated();
    if let Some(n) = req.max_iterations {
        settings.cg.max_iterations = n.max(1);
    }
    let combined = req.layers == super::LayerMode::Combined;
    // Texture coordinates and render matrices over all views first: which objects cover a
    // pixel, which layers are black, the rows and gold standard of every point.
    let mut covered = Vec::new();
    for o in 0..scene.objects.len() {
        let name = &scene.objects[o].name;
        let at = atlas(&frames, set.resolution, o, &meshes[o]);
        let whole = place_in(scene, &frames, set.resolution, o, &meshes[o], &at, req.max_texture, 1.0, req.texels_per_pixel)?;
        let before = matrices.renderings();
        let views = views_of(set, o, &at.uvs, &whole, &meshes, req, matrices)?;
        if matrices.renderings() > before {
            stages.note(&format!("object {name}: {} probe renderings over {} points", matrices.renderings() - before, views.len()));
        }
        if views.iter().all(|v| v.rows() == 0) {
            stages.note(&format!("object {name} covers no pixel of the set; left out"));
            continue;
        }
        let diffuse_black = is_black(&views, |v| &v.diffuse, |v| &v.specular);
        let specular_black = is_black(&views, |v| &v.specular, |v| &v.diffuse);
        if diffuse_black && specular_black {
            stages.note(&format!("object {name} is black in every layer; nothing stored"));
            continue;
        }
        covered.push(Covered { o, atlas: at, views, whole, diffuse_black, specular_black });
    }
    if covered.is_empty() {
        return Err(anyhow!("no object covers a pixel of the set"));
    }
    // Per object per block: the placement over the block's views, and the render matrices
    // of the placements each point's layers read.
    let n = covered.len();
    let mut planned = Vec::with_capacity(n);
    let (mut made, mut extra) = (0usize, 0usize);
    for (mi, c) in covered.into_iter().enumerate() {
        let st = stagger(mi, n, &sizes);
        let mut placements = vec![c.whole.clone()];
        let mut plans = Vec::new();
        let wanted = if combined {
            vec![(pis_format::LayerKind::Specular, Radiance::Sum, all)]
        } else {
            let diffuse = (!c.diffuse_black).then_some((pis_format::LayerKind::Diffuse, Radiance::Diffuse, non_view));
            let specular = (!c.specular_black).then_some((pis_format::LayerKind::Specular, Radiance::Specular, all));
            diffuse.into_iter().chain(specular).collect()
        };
        for layer in wanted {
            let grid = BlockGrid::new(&space, layer.2, &st);
            plans.push(plan_layer(set, &grid, layer, c.o, &meshes[c.o], &c.atlas, &mut placements, req)?);
        }
        made += placements.len();
        let mut views = c.views;
        for (p, v) in views.iter_mut().enumerate() {
            let mut read: Vec<usize> = plans.iter().map(|pl| pl.point_placement[p]).collect();
            read.sort_unstable();
            read.dedup();
            for &pid in &read {
                if pid == 0 || v.rows() == 0 {
                    continue;
                }
                let a = matrix_at(set, p, c.o, &meshes, &c.atlas.uvs, &placements[pid], req, matrices)?;
                if a.pixels != v.a(0).pixels {
                    return Err(anyhow!("object {}: point {p}: the render matrices of two placements cover different pixels", scene.objects[c.o].name));
                }
                v.a.push((pid, a));
                extra += 1;
            }
            if !read.contains(&0) && v.a.len() > 1 {
                v.a.remove(0);
            }
        }
        planned.push(Planned { o: c.o, atlas: c.atlas, placements, stagger: st, views, plans });
    }
    stages.done("matrices", &format!(
        "texture coordinates of {} objects ({made} placements, per {}) and render matrices at {} points ({}; {extra} for block placements)",
        scene.objects.len(), req.placement.name(), set.frames.len(), matrices.describe(),
    ));
    let mut out = Vec::new();
    for Planned { o, atlas: at, placements, stagger: st, views, plans } in planned {
        let name = scene.objects[o].name.clone();
        let covered: usize = views.iter().map(PointView::rows).sum();
        let area = covered as f64 / views.len() as f64;
        let layers = plans.iter().map(|plan| solve_layer(set, &views, &placements, plan, &settings)).collect::<Result<Vec<_>>>()?;
        let radiances: Vec<Radiance> = plans.iter().map(|p| p.radiance).collect();
        let (representation, why) = match radiances.as_slice() {
            [Radiance::Sum] => ("combined", "--layers combined: one view-dependent layer of diffuse + specular radiance per parameter sample"),
            [Radiance::Diffuse] => ("diffuse", "the specular layer changes no displayed pixel: one view-independent diffuse texture per non-view sample"),
            [Radiance::Specular] => ("specular", "the diffuse layer changes no displayed pixel: a view-dependent texture per parameter sample"),
            _ => ("diffuse+specular", "view-independent diffuse layer over the non-view dimensions plus a view-dependent specular layer per parameter sample"),
        };
        let (representation, why) = (representation.to_string(), why.to_string());
        let m = ObjectModel {
            index: o, name, mesh: merged_mesh(scene, o), mesh_uvs: at.uvs, placements, stagger: st, block_sizes: sizes.clone(),
            area, views, layers, representation, why,
        };
        let sizes_text: Vec<String> = m.used_placements().iter().map(|&p| format!("{}x{}", m.placements[p].layout.width, m.placements[p].layout.height)).collect();
        stages.note(&format!("object {}: {} texels, {} ({})", m.name, sizes_text.join(", "), m.representation, m.why));
        out.push(m);
    }
    stages.done("infer", &format!("{} objects solved", out.len()));
    Ok(out)
}
