//! Parameterized surface textures (thesis ch. 3, 4.8): the representation of every object
//! today. A view-independent diffuse layer solved once over all views by stacking, and a
//! view-dependent specular layer solved per parameter sample, each warm-started from the
//! last sample solved with the same placement; layers that are black for an object are left
//! out. Every solve is pyramidal (ε_f = 0.1) in the decimated parameterization: the unknowns
//! are level 0 and the coarser levels its decimations, as the player stores and rebuilds them.
//!
//! Texture coordinates (thesis 3.2) are optimized per object per parameter block: each block
//! of a layer gets the branch cuts, affine map and used size that suit the views of its
//! samples, so every point has one render matrix per placement its layers read.

use std::collections::BTreeMap;

use anyhow::{anyhow, Result};
use pis_compile::{DrawMesh, RenderMatrix, SolveSettings, TexturedObject, Viewport};
use pis_format::blocks::BlockGrid;
use pis_format::DepMask;
use pis_scene::ObjectRole;
use pis_trace::layers::LayerKind as TraceLayer;
use pis_trace::PointImages;

use super::confidence::rows_confidence;
use super::density_choice;
use super::input::LoadedSet;
use super::matrices::Matrices;
use super::mesh::{atlas, occluding_indices, place_in, sampler, Atlas, Mesh, Placed};
use super::model::{key, InferredLayer, ObjectModel, PointView, Views};
use super::opacity::{premultiply, with_alpha};
use super::radiance::Radiance;
use super::represent::{Job, Planned, Representation, Surveyed};
use super::rows::{gather, restrict_rows};
pub(super) use super::sample::{LayerPlan, Sample};
pub use super::texture_form::{finest, mip_chain, TextureForm};
use super::textures::Textures;
use super::{PackRequest, PlacementMode};
use crate::solutions::Solver;

/// Largest linear radiance below which a layer counts as black.
pub const BLACK: f32 = 1e-4;

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

/// Object `o`'s coverage at point `p`, per pixel.
pub(super) fn coverage(set: &LoadedSet, p: usize, o: usize) -> Result<Vec<f32>> {
    let images = set.images.object(p, o)?;
    Ok(coverage_in(set, &images, o))
}

/// Object `o`'s coverage per pixel in `images` (a point of `set`).
fn coverage_in(set: &LoadedSet, images: &PointImages, o: usize) -> Vec<f32> {
    let (w, h) = set.resolution;
    images
        .object_layer(&set.channels[o], TraceLayer::Coverage)
        .and_then(|l| l.channel("A"))
        .map(<[f32]>::to_vec)
        .unwrap_or_else(|| vec![0.0; (w * h) as usize])
}

/// The render matrix of object `o` at point `p` with texture coordinates `uvs` and placement
/// `placed`, every other mesh occluding it; rows where the tracer covers no pixel (of
/// `coverage`, the object's there) removed.
#[allow(clippy::too_many_arguments)]
fn matrix_at(
    set: &LoadedSet,
    p: usize,
    o: usize,
    meshes: &[Mesh],
    uvs: &[[f32; 2]],
    placed: &Placed,
    filter: pis_compile::Filter,
    matrices: &mut Matrices,
    coverage: &[f32],
) -> Result<RenderMatrix> {
    let (w, h) = set.resolution;
    let frame = &set.frames[p];
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
            indices: occluding_indices(meshes, o, k),
            clip_from_object: clip_from(k),
        })
        .collect();
    let mut mesh = draw[o];
    mesh.uvs = uvs;
    let obj = TexturedObject {
        mesh,
        transform: placed.transform,
        layout: placed.layout,
        sampler: sampler(filter, placed.repeat),
    };
    let a = matrices.matrix(Viewport { width: w, height: h }, &draw, o, &obj)?;
    // A translucent object keeps the pixels the tracer sees through it: its opacity is 0
    // there.
    Ok(if meshes[o].translucent { a } else { restrict_rows(&a, coverage) })
}

/// Every point with placement 0 (over all views) drawn with `filter`: the rows, the gold
/// standard there.
fn views_of(
    set: &LoadedSet,
    o: usize,
    uvs: &[[f32; 2]],
    placed: &Placed,
    meshes: &[Mesh],
    filter: pis_compile::Filter,
    matrices: &mut Matrices,
) -> Result<Views> {
    let channel = &set.channels[o];
    let mut views = Views::new(set.scratch.clone());
    for p in 0..set.frames.len() {
        let images = set.images.object(p, o)?;
        let cov = coverage_in(set, &images, o);
        let a = matrix_at(set, p, o, meshes, uvs, placed, filter, matrices, &cov)?;
        let pick = |kind| gather(&a.pixels, &layer_rgb(&images, channel, kind));
        let (mut diffuse, mut specular) = (pick(TraceLayer::Diffuse), pick(TraceLayer::Specular));
        let alpha = if meshes[o].translucent {
            premultiply(&a, &cov, [&mut diffuse, &mut specular])
        } else {
            Vec::new()
        };
        let weight = rows_confidence(set, p, o, &a.pixels)?;
        views.push(PointView { a: vec![(0, a)], diffuse, specular, alpha, weight })?;
    }
    Ok(views)
}

/// Why a translucent object's first layer has four channels.
const TRANSLUCENT: &str = "translucent (glTF alpha mode MASK or BLEND): its first layer carries its opacity, and the player composites it over what lies behind it";

/// Half a step of an 8-bit display value: a layer whose removal moves no covered pixel by
/// more than this changes no displayed pixel.
pub const DISPLAY_STEP: f32 = 0.5 / 255.0;

/// True when the layer `pick` is black for the display: zero (below [`BLACK`]), or so dark
/// beside the other layer `other` that leaving it out changes no 8-bit pixel.
fn is_black(
    views: &Views,
    pick: impl Fn(&PointView) -> &[f32],
    other: impl Fn(&PointView) -> &[f32],
) -> Result<bool> {
    let d = |v: f32| crate::images::srgb_encode(v.clamp(0.0, 1.0));
    for p in 0..views.len() {
        let v = views.get(p)?;
        if !pick(&v)
            .iter()
            .zip(other(&v))
            .all(|(x, o)| x.abs() < BLACK || (d(x + o) - d(*o)).abs() < DISPLAY_STEP)
        {
            return Ok(false);
        }
    }
    Ok(true)
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
    (req, texels_per_pixel): (&PackRequest, Option<f64>),
) -> Result<LayerPlan> {
    let blocks = grid.block_count() as usize;
    let point_block: Vec<usize> = set.samples.iter().map(|s| grid.locate(s).block).collect();
    let mut block_placements = vec![0usize; blocks];
    if req.placement == PlacementMode::Block {
        for (b, slot) in block_placements.iter_mut().enumerate() {
            let frames: Vec<&pis_scene::Frame> = point_block
                .iter()
                .zip(&set.frames)
                .filter(|(pb, _)| **pb == b)
                .map(|(_, f)| f)
                .collect();
            if frames.is_empty() || frames.len() == set.frames.len() {
                continue;
            }
            let pl = place_in(
                &set.scene,
                &frames,
                set.resolution,
                o,
                mesh,
                at,
                req.max_texture,
                1.0,
                texels_per_pixel,
            )?;
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
    Ok(LayerPlan {
        kind,
        radiance,
        depends_on: mask,
        block_placements,
        point_placement,
        alpha: false,
    })
}

/// One texture per key of `plan`'s mask: each key's sample solved (or, for a view-independent
/// layer, its views stacked, eq. 3.7) with the render matrices of its block's placement,
/// warm-started from the last sample solved with the same placement.
fn solve_layer(
    set: &LoadedSet,
    views: &Views,
    placements: &[Placed],
    plan: &LayerPlan,
    settings: &SolveSettings,
    solver: &Solver,
) -> Result<InferredLayer> {
    let mut groups: BTreeMap<Vec<u32>, Vec<usize>> = BTreeMap::new();
    for (p, s) in set.samples.iter().enumerate() {
        groups.entry(key(s, plan.depends_on)).or_default().push(p);
    }
    // Spilled as solved when the pack streams: a layer's samples grow with the points.
    let mut textures = Textures::new(set.scratch.as_ref());
    let mut placement_of = BTreeMap::new();
    let mut warm: BTreeMap<(Radiance, usize), Vec<f32>> = BTreeMap::new();
    let mut iterations = 0u64;
    let view_independent = plan.radiance == Radiance::Diffuse;
    for (k, points) in groups {
        let pid = plan.point_placement[points[0]];
        let sample = Sample { views, points: &points, placement: &placements[pid], pid };
        let mut solve = |radiance: Radiance| -> Result<Vec<f32>> {
            let start = warm.get(&(radiance, pid)).map(Vec::as_slice);
            let (x, n) = sample.solve(radiance, view_independent, start, settings, solver)?;
            iterations += n;
            warm.insert((radiance, pid), x.clone());
            Ok(x)
        };
        let mut x = solve(plan.radiance)?;
        if plan.alpha {
            x = with_alpha(&x, &solve(Radiance::Alpha)?);
        }
        placement_of.insert(k.clone(), pid);
        textures.insert(k, x)?;
    }
    let form = Box::new(TextureForm {
        placements: placements.to_vec(),
        block_placements: plan.block_placements.clone(),
        placement_of: placement_of.clone(),
        channels: if plan.alpha { 4 } else { 3 },
    });
    Ok(InferredLayer {
        kind: plan.kind,
        depends_on: plan.depends_on,
        textures,
        block_placements: plan.block_placements.clone(),
        placement_of,
        iterations,
        form,
        shell: None,
        light: None,
    })
}

/// Parameterized surface textures: any object.
pub struct SurfaceTextures;

impl Representation for SurfaceTextures {
    fn name(&self) -> &'static str {
        "surface textures"
    }

    fn applies(&self, _role: ObjectRole) -> bool {
        true
    }

    /// Texture coordinates and render matrices over all views: whether the object covers a
    /// pixel, which layers are black, the rows and gold standard of every point.
    fn survey(&self, job: &mut Job<'_>, o: usize) -> Result<Option<Box<dyn Surveyed>>> {
        survey_surface(job, o, true)
    }
}

/// [`SurfaceTextures`]' survey of object `o`, its filter chosen; without `with_specular`, its
/// surface part is its diffuse layer alone, with the file's filter (another representation
/// stores the rest), surveyed even when black, for its views' rows and gold standard.
pub fn survey_surface(
    job: &mut Job<'_>,
    o: usize,
    with_specular: bool,
) -> Result<Option<Box<dyn Surveyed>>> {
    {
        let (set, req) = (job.set, job.req);
        let scene = &set.scene;
        let frames: Vec<&pis_scene::Frame> = set.frames.iter().collect();
        let name = &scene.objects[o].name;
        let at = atlas(&frames, set.resolution, o, &job.meshes[o]);
        let whole = place_in(
            scene,
            &frames,
            set.resolution,
            o,
            &job.meshes[o],
            &at,
            req.max_texture,
            1.0,
            req.texels_per_pixel,
        )?;
        let before = job.matrices.renderings();
        let views = views_of(set, o, &at.uvs, &whole, &job.meshes, req.filter, job.matrices)?;
        if job.matrices.renderings() > before {
            job.note(&format!(
                "object {name}: {} probe renderings over {} points",
                job.matrices.renderings() - before,
                views.len()
            ));
        }
        if (0..views.len()).all(|p| views.rows(p) == 0) {
            job.note(&format!("object {name} covers no pixel of the set; left out"));
            return Ok(None);
        }
        let chosen = super::filter_choice::choose(job, with_specular, name, &whole, views, |j| {
            let bilinear = pis_compile::Filter::Bilinear;
            views_of(set, o, &at.uvs, &whole, &j.meshes, bilinear, j.matrices)
        })?;
        let filter = chosen.filter;
        let base = (whole, chosen.views, chosen.held_out);
        let dense = density_choice::choose(job, with_specular, name, base, |j, k| {
            let frames: Vec<&pis_scene::Frame> = set.frames.iter().collect();
            let (max, meshes) = (req.max_texture, &j.meshes);
            let placed =
                place_in(scene, &frames, set.resolution, o, &meshes[o], &at, max, 1.0, Some(k))?;
            let views = views_of(set, o, &at.uvs, &placed, meshes, filter, j.matrices)?;
            Ok((placed, views))
        })?;
        let (whole, views) = (dense.whole, dense.views);
        // A translucent object's first layer carries its opacity: kept wherever the object
        // hides some of what lies behind it, even in black.
        let hides = |v: &PointView| v.alpha.iter().any(|&a| a > DISPLAY_STEP);
        let diffuse_black = is_black(&views, |v| &v.diffuse, |v| &v.specular)?
            && !(0..views.len()).any(|p| views.get(p).is_ok_and(|v| hides(&v)));
        let specular_black = !with_specular || is_black(&views, |v| &v.specular, |v| &v.diffuse)?;
        if diffuse_black && specular_black && with_specular {
            job.note(&format!("object {name} is black in every layer; nothing stored"));
            return Ok(None);
        }
        Ok(Some(Box::new(Covered {
            o,
            atlas: at,
            views,
            whole,
            filter: (chosen.filter, chosen.why),
            density: (dense.texels_per_pixel, dense.why),
            diffuse_black,
            specular_black,
            diffuse_only: !with_specular,
            relit: super::relit::Relit::of(set).filter(|_| with_specular && req.relight),
        })))
    }
}

/// An object that covers a pixel and is not black: its texture coordinates, placement over
/// all views and the points as that placement sees them.
struct Covered {
    o: usize,
    atlas: Atlas,
    views: Views,
    whole: Placed,
    /// The filter its textures are solved for, and why where it was chosen.
    filter: (pis_compile::Filter, Option<String>),
    /// The texel budget its placements are made under, and why where it was chosen.
    density: (Option<f64>, Option<String>),
    diffuse_black: bool,
    specular_black: bool,
    /// The diffuse layer is the object's only surface layer (whatever `--layers` says).
    diffuse_only: bool,
    /// The set's light directions, which the layers span as coefficients.
    relit: Option<super::relit::Relit>,
}

impl Surveyed for Covered {
    /// Per block: the placement over the block's views, and the render matrices of the
    /// placements each point's layers read.
    fn plan(self: Box<Self>, job: &mut Job<'_>, st: Vec<u32>) -> Result<Box<dyn Planned>> {
        let c = *self;
        let (set, req) = (job.set, job.req);
        let scene = &set.scene;
        let mut placements = vec![c.whole.clone()];
        let mut plans = Vec::new();
        let wanted = if req.layers == super::LayerMode::Combined && !c.diffuse_only {
            vec![(pis_format::LayerKind::Specular, Radiance::Sum, job.all)]
        } else {
            let diffuse = (!c.diffuse_black).then_some((
                pis_format::LayerKind::Diffuse,
                Radiance::Diffuse,
                job.non_view,
            ));
            let specular = (!c.specular_black).then_some((
                pis_format::LayerKind::Specular,
                Radiance::Specular,
                job.all,
            ));
            diffuse.into_iter().chain(specular).collect()
        };
        for mut layer in wanted {
            if let Some(r) = &c.relit {
                layer.2 = r.without(layer.2);
            }
            let grid = BlockGrid::new(&job.plan.space, layer.2, &st);
            plans.push(plan_layer(
                set,
                &grid,
                layer,
                c.o,
                &job.meshes[c.o],
                &c.atlas,
                &mut placements,
                (req, c.density.0),
            )?);
        }
        if let Some(first) = plans.first_mut() {
            first.alpha = job.meshes[c.o].translucent;
        }
        job.placements += placements.len();
        let mut views = c.views;
        for p in 0..views.len() {
            let mut read: Vec<usize> = plans.iter().map(|pl| pl.point_placement[p]).collect();
            read.sort_unstable();
            read.dedup();
            let extra: Vec<usize> =
                read.iter().copied().filter(|&pid| pid != 0 && views.rows(p) > 0).collect();
            if extra.is_empty() && read.contains(&0) {
                continue;
            }
            let cov = if extra.is_empty() { Vec::new() } else { coverage(set, p, c.o)? };
            let mut made = Vec::new();
            for &pid in &extra {
                made.push((
                    pid,
                    matrix_at(
                        set,
                        p,
                        c.o,
                        &job.meshes,
                        &c.atlas.uvs,
                        &placements[pid],
                        c.filter.0,
                        job.matrices,
                        &cov,
                    )?,
                ));
                job.extra_matrices += 1;
            }
            let name = &scene.objects[c.o].name;
            views.update(p, |v| {
                for (pid, a) in made {
                    if a.pixels != v.a(0).pixels {
                        return Err(anyhow!("object {name}: point {p}: the render matrices of two placements cover different pixels"));
                    }
                    v.a.push((pid, a));
                }
                if !read.contains(&0) && v.a.len() > 1 {
                    v.a.remove(0);
                }
                Ok(())
            })?;
        }
        let (o, atlas, filter, texels_per_pixel) = (c.o, c.atlas, c.filter.0, c.density.0);
        let chosen = [c.filter.1, c.density.1].into_iter().flatten().collect();
        Ok(Box::new(Layers {
            o,
            atlas,
            placements,
            stagger: st,
            views,
            plans,
            filter: (filter, texels_per_pixel),
            chosen,
            relit: c.relit,
        }))
    }
}

/// An object with its blocks placed: texture coordinates, placements, block origins, the
/// points with the render matrices its layers read, the layers to solve.
struct Layers {
    o: usize,
    atlas: Atlas,
    placements: Vec<Placed>,
    stagger: Vec<u32>,
    views: Views,
    plans: Vec<LayerPlan>,
    /// The filter its textures are solved for, and the texel budget of its placements.
    filter: (pis_compile::Filter, Option<f64>),
    /// What the choices of its filter and texel density measured, where they were made.
    chosen: Vec<String>,
    relit: Option<super::relit::Relit>,
}

impl Planned for Layers {
    fn solve(self: Box<Self>, job: &Job<'_>) -> Result<ObjectModel> {
        let Layers {
            o,
            atlas: at,
            placements,
            stagger: st,
            views,
            plans,
            filter,
            mut chosen,
            relit,
        } = *self;
        let (set, scene) = (job.set, &job.set.scene);
        let name = scene.objects[o].name.clone();
        let covered: usize = (0..views.len()).map(|p| views.rows(p)).sum();
        let area = covered as f64 / views.len() as f64;
        let mut layers = Vec::new();
        for plan in &plans {
            let (settings, solver) = (&job.settings, &job.solver);
            match &relit {
                Some(r) => {
                    let (coefficients, why) = super::relit::solve_relit_layer(
                        set,
                        &views,
                        &placements,
                        plan,
                        (settings, solver),
                        r,
                    )?;
                    layers.extend(coefficients);
                    chosen.push(why);
                }
                None => layers.push(solve_layer(set, &views, &placements, plan, settings, solver)?),
            }
        }
        let radiances: Vec<Radiance> = plans.iter().map(|p| p.radiance).collect();
        let translucent = plans.first().is_some_and(|p| p.alpha);
        let (representation, why) = match radiances.as_slice() {
            [Radiance::Sum] => ("combined", "--layers combined: one view-dependent layer of diffuse + specular radiance per parameter sample"),
            [Radiance::Diffuse] => ("diffuse", "the specular layer changes no displayed pixel: one view-independent diffuse texture per non-view sample"),
            [Radiance::Specular] => ("specular", "the diffuse layer changes no displayed pixel: a view-dependent texture per parameter sample"),
            _ => ("diffuse+specular", "view-independent diffuse layer over the non-view dimensions plus a view-dependent specular layer per parameter sample"),
        };
        Ok(ObjectModel {
            index: o,
            name,
            mesh: job.meshes[o].clone(),
            mesh_uvs: at.uvs,
            placements,
            stagger: st,
            area,
            views,
            layers,
            shells: None,
            hull_triangles: 0,
            representation: match (translucent, &relit) {
                (true, _) => format!("{representation}, translucent"),
                (false, Some(r)) => format!("{representation}, relightable over {}", r.name),
                (false, None) => representation.to_string(),
            },
            why: [Some(why.to_string()), translucent.then(|| TRANSLUCENT.to_string())]
                .into_iter()
                .flatten()
                .chain(chosen)
                .collect::<Vec<_>>()
                .join("; "),
            filter: filter.0,
            texels_per_pixel: filter.1,
            auto: None,
        })
    }
}
