//! The file's objects as the player draws them, checked and uploaded at open: each object's
//! mesh, its surface layers, its reflection term's shells, and, for a lens object, what its
//! tessellation is traced from; and the checks of the file's textures against the adapter.

use std::sync::Arc;

use pis_compile::hybrid::{LensMaterial, LensObject, VertexTracer};
use pis_compile::{Filter, TextureLayout};
use pis_format::{Container, Mapping, PisReader, Placement, StreamRef, Term};

use super::depth::{object_depth_shells, DepthShells};
use crate::cube_atlas::CubeAtlas;
use crate::error::PlayError;
use crate::frame::hybrid::MAX_LENS_SHELLS;
use crate::frame::{MeshGpu, MAX_TERM_SHELLS};
use crate::gpu::Gpu;
use crate::lens_rays::{vertex_tracer, GpuRays, LensRayPipeline};
use crate::shell::ShellCode;
use crate::textured::allocated_size;

/// An object's mesh on the GPU and the layers the player draws.
pub(super) struct ObjectGpu {
    pub(super) mesh: MeshGpu,
    /// Surface layers.
    pub(super) layers: Vec<usize>,
    /// The reflection term's shell layers in increasing order (at most
    /// [`MAX_TERM_SHELLS`]); empty for an object without them or without normals.
    pub(super) reflection: Vec<usize>,
    /// A lens object drawn by hybrid rendering.
    pub(super) lens: Option<LensState>,
    /// A surface layer carries the object's opacity (4 channels, SPEC.md 7.1): the object
    /// is composited over the opaque surfaces behind it (SPEC.md 9).
    pub(super) translucent: bool,
    /// The depth shells of its reflection term, by (layer, block).
    pub(super) depth: DepthShells,
}

impl ObjectGpu {
    /// The code of the shell pipelines its draws need, from its term's shell layers' blocks
    /// (`object` is its record in the file): what the player compiles when it opens a file
    /// rather than in a frame's time. A lens object's shells are never marched.
    pub(super) fn shell_code(&self, object: &pis_format::Object<StreamRef>) -> Option<ShellCode> {
        let layers = match &self.lens {
            Some(lens) => &lens.layers,
            None if self.reflection.is_empty() => return None,
            None => &self.reflection,
        };
        let blocks = layers.iter().flat_map(|&li| &object.layers[li].blocks);
        let code = blocks.filter_map(|b| match b.placement {
            Placement::Shell { shape, lookups, .. } => {
                Some(ShellCode::of_placement(shape, lookups))
            }
            _ => None,
        });
        let code = code.fold(ShellCode::default(), ShellCode::union);
        Some(ShellCode { depth: code.depth && self.lens.is_none(), ..code })
    }
}

/// A lens object: its shell layers (the refraction term's, in increasing order, at most
/// [`MAX_LENS_SHELLS`]; both terms look them up), its triangles in object space, its
/// material, and the object placed in world space at the last transform drawn.
pub(super) struct LensState {
    pub(super) layers: Vec<usize>,
    positions: Vec<glam::Vec3>,
    normals: Vec<glam::Vec3>,
    indices: Vec<u32>,
    material: LensMaterial,
    /// The paths traced at its vertices and the terms drawn (SPEC.md 6.6 `lens_model`).
    pub(super) model: pis_compile::hybrid::LensModel,
    placed: Option<(glam::Mat4, Placed)>,
    /// Where its vertex rays are traced on the GPU: the device and the pipeline (`None`: on
    /// the workers).
    gpu_rays: Option<GpuRays>,
    /// The last frame's tessellation and what it was made for (transform, eye, view and
    /// projection, frame size, τ): a frame that changes none of them draws it again.
    pub(super) tessellated: Option<(TessellationKey, Arc<pis_compile::hybrid::Tessellation>)>,
}

/// What a lens object's tessellation depends on.
pub(super) type TessellationKey = (glam::Mat4, glam::Vec3, glam::Mat4, (u32, u32), f32);

/// A lens object placed at a transform, and what traces its vertex rays (on the GPU, its
/// BVH uploaded once per placement; or on the workers).
pub(super) type Placed = (Arc<LensObject>, Arc<dyn VertexTracer + Send + Sync>);

impl LensState {
    /// The lens object at `world` (rigid) and its tracer, made once per transform.
    pub(super) fn at(&mut self, world: glam::Mat4) -> &Placed {
        if self.placed.as_ref().is_none_or(|(m, _)| *m != world) {
            self.placed = Some((world, self.placed_at(world)));
        }
        &self.placed.as_ref().expect("placed above").1
    }

    /// The lens object at `world` and its tracer: those drawn last where the transform is
    /// the same, else made anew (for a frame expected next, leaving the last in place).
    pub(super) fn placed_at(&self, world: glam::Mat4) -> Placed {
        match &self.placed {
            Some((m, placed)) if *m == world => placed.clone(),
            _ => {
                let positions = self.positions.iter().map(|&p| world.transform_point3(p)).collect();
                let normals = self.normals.iter().map(|&n| world.transform_vector3(n)).collect();
                let lens = LensObject::new(self.material, positions, normals, &self.indices);
                let tracer = vertex_tracer(self.gpu_rays.as_ref(), &lens);
                (Arc::new(lens), tracer)
            }
        }
    }

    /// Traces its vertex rays on `gpu` from now on.
    pub(super) fn trace_on_gpu(&mut self, gpu: Arc<Gpu>, pipeline: Arc<LensRayPipeline>) {
        self.gpu_rays = Some((gpu, pipeline));
        self.placed = None;
    }

    /// The settings its tessellations are made with at `tau_px`.
    pub(super) fn settings(&self, tau_px: f32) -> pis_compile::hybrid::TessellationSettings {
        pis_compile::hybrid::TessellationSettings {
            tau_px,
            model: self.model,
            ..Default::default()
        }
    }
}

/// Per object, the texture filter its textures were solved for: pis-pack records the file's
/// in the provenance settings (`filter`, `anisotropy`) and an object's own where it differs
/// (`filter.NAME`; SPEC.md 6.6); trilinear when absent. The reader has checked the settings
/// (rule 9001).
pub(super) fn object_filters(c: &Container<StreamRef>) -> Vec<Filter> {
    let names: Vec<&str> = c.objects.iter().map(|o| o.name.as_str()).collect();
    let filters = pis_format::FileFilter::per_object(c.provenance.as_ref(), &names)
        .unwrap_or_else(|_| vec![pis_format::FileFilter::default(); names.len()]);
    filters
        .into_iter()
        .map(|f| match f {
            pis_format::FileFilter::Nearest => Filter::Nearest,
            pis_format::FileFilter::Bilinear => Filter::Bilinear,
            pis_format::FileFilter::Trilinear => Filter::Trilinear,
            pis_format::FileFilter::Anisotropic(n) => Filter::Anisotropic(n),
        })
        .collect()
}

pub(super) fn content(reader: &PisReader, message: String) -> PlayError {
    PlayError::Content { path: reader.path().display().to_string(), message }
}

/// Checks what the player relies on beyond the reader's validation and uploads the meshes.
/// `depth_steps` replaces the march's step count of depth shells ([`super::PlayerOptions`]).
pub(super) fn prepare_objects(
    gpu: &Gpu,
    reader: &PisReader,
    depth_steps: Option<u32>,
) -> Result<Vec<ObjectGpu>, PlayError> {
    let c = reader.container();
    let mut out = Vec::with_capacity(c.objects.len());
    let mut skipped = Vec::new();
    // The reader has checked the tints (rule 9004).
    let named: Vec<(&str, pis_format::ObjectRole)> =
        c.objects.iter().map(|o| (o.name.as_str(), o.role)).collect();
    let tints = pis_format::tint::tints(c.provenance.as_ref(), &named)
        .unwrap_or_else(|_| vec![[1.0; 3]; c.objects.len()]);
    // And the lens models (rule 9005).
    let models = pis_format::lens_model::lens_models(c.provenance.as_ref(), &named)
        .unwrap_or_else(|_| vec![Default::default(); c.objects.len()]);
    for (oi, o) in c.objects.iter().enumerate() {
        let n = o.mesh.positions.len();
        let uvs: Vec<[f32; 2]> = match &o.mesh.texcoords {
            Some(t) if t.len() == n => t.clone(),
            Some(t) => {
                return Err(content(
                    reader,
                    format!(
                        "object {oi} '{}': {} texture coordinates for {n} positions",
                        o.name,
                        t.len()
                    ),
                ))
            }
            None => vec![[0.0; 2]; n],
        };
        if let Some(bad) = o.mesh.indices.iter().find(|&&i| i as usize >= n) {
            return Err(content(
                reader,
                format!("object {oi} '{}': index {bad} with {n} positions", o.name),
            ));
        }
        if let Some(normals) = o.mesh.normals.as_ref().filter(|v| v.len() != n) {
            return Err(content(
                reader,
                format!("object {oi} '{}': {} normals for {n} positions", o.name, normals.len()),
            ));
        }
        let mut layers = Vec::new();
        for (li, l) in o.layers.iter().enumerate() {
            if !(1..=4).contains(&l.channels) {
                return Err(content(
                    reader,
                    format!("object {oi} '{}' layer {li} has {} channels", o.name, l.channels),
                ));
            }
            if l.mapping == Mapping::Shell {
                continue;
            }
            if o.mesh.texcoords.is_none() {
                return Err(content(
                    reader,
                    format!(
                        "object {oi} '{}' has a surface layer but no texture coordinates",
                        o.name
                    ),
                ));
            }
            layers.push(li);
        }
        let lens = lens_state(reader, oi, (tints[oi], models[oi]), &mut skipped)?;
        let reflection =
            if lens.is_some() { Vec::new() } else { reflection_shells(reader, oi, &mut skipped)? };
        let mesh =
            MeshGpu::new(gpu, &o.mesh.positions, o.mesh.normals.as_deref(), &uvs, &o.mesh.indices)
                .with_hull(o.mesh.hull_triangles);
        let translucent = layers.iter().any(|&li| o.layers[li].channels == 4);
        let depth = object_depth_shells(gpu, c, oi, depth_steps);
        out.push(ObjectGpu { mesh, layers, reflection, lens, translucent, depth });
    }
    if !skipped.is_empty() {
        eprintln!(
            "pis-play: note: shell layers are not drawn by this player: {}",
            skipped.join(", ")
        );
    }
    Ok(out)
}

/// The shell layers of object `oi`'s reflection term in increasing order, the player draws
/// them all in one pass: at most [`MAX_TERM_SHELLS`] (more is not supported), each block a
/// closed shell (sphere, ellipsoid, box or cylinder; a quad is not supported). Shell layers
/// the player does not draw — the refraction term's, and every shell of an object without
/// normals — are listed in `skipped` (`object/kind (why)`).
fn reflection_shells(
    reader: &PisReader,
    oi: usize,
    skipped: &mut Vec<String>,
) -> Result<Vec<usize>, PlayError> {
    let o = &reader.container().objects[oi];
    let shells = |term| {
        o.layers
            .iter()
            .enumerate()
            .filter(move |(_, l)| l.mapping == Mapping::Shell && l.term == term)
    };
    let mut note = |li: usize, why: &str| {
        skipped.push(format!("{}/{} ({why})", o.name, o.layers[li].kind.name()))
    };
    shells(Term::Refraction).for_each(|(li, _)| note(li, "refraction term"));
    let term: Vec<usize> = shells(Term::Reflection).map(|(li, _)| li).collect();
    if o.mesh.normals.is_none() {
        term.iter().for_each(|&li| note(li, "the mesh has no normals"));
        return Ok(Vec::new());
    }
    ordered_closed_shells(reader, oi, term, "reflection", MAX_TERM_SHELLS)
}

/// Shell layers `layers` of object `oi`'s `term` in increasing order, checked drawable: at
/// most `max` of them, each block a closed shell (sphere, ellipsoid, box or cylinder; a quad
/// is not supported).
fn ordered_closed_shells(
    reader: &PisReader,
    oi: usize,
    mut layers: Vec<usize>,
    term: &str,
    max: usize,
) -> Result<Vec<usize>, PlayError> {
    let o = &reader.container().objects[oi];
    layers.sort_by_key(|&li| o.layers[li].order);
    let not_supported = |message: String| {
        PlayError::File(pis_format::Error::NotSupported(format!(
            "{}: object {oi} '{}': {message}",
            reader.path().display(),
            o.name
        )))
    };
    if layers.len() > max {
        return Err(not_supported(format!(
            "{} shells in the {term} term; this player draws at most {max}",
            layers.len()
        )));
    }
    for &li in &layers {
        let closed = o.layers[li]
            .blocks
            .iter()
            .all(|b| matches!(b.placement, Placement::Shell { shape, .. } if shape.faces() == 6));
        if !closed {
            return Err(not_supported(format!("layer {li} ({}) is not a closed shell (sphere, ellipsoid, box or cylinder): quad shells are not drawn", o.layers[li].kind.name())));
        }
    }
    Ok(layers)
}

/// Object `oi` as a lens object, when it is one: role `refractive`, shell layers in the
/// refraction term (at most [`MAX_LENS_SHELLS`], closed shells), normals; its transmission
/// tint and lens model `(tint, model)`. Its reflection term's own shells, if any, are not drawn (listed in
/// `skipped`), nor are the shells of a refractive object without normals.
fn lens_state(
    reader: &PisReader,
    oi: usize,
    (tint, model): ([f32; 3], pis_format::lens_model::LensTerms),
    skipped: &mut Vec<String>,
) -> Result<Option<LensState>, PlayError> {
    let o = &reader.container().objects[oi];
    if o.role != pis_format::ObjectRole::Refractive {
        return Ok(None);
    }
    let shells = |term| {
        o.layers
            .iter()
            .enumerate()
            .filter(move |(_, l)| l.mapping == Mapping::Shell && l.term == term)
            .map(|(li, _)| li)
    };
    let layers: Vec<usize> = shells(Term::Refraction).collect();
    if layers.is_empty() {
        return Ok(None);
    }
    let Some(normals) = &o.mesh.normals else {
        layers.iter().for_each(|&li| {
            skipped.push(format!(
                "{}/{} (the mesh has no normals)",
                o.name,
                o.layers[li].kind.name()
            ))
        });
        return Ok(None);
    };
    shells(Term::Reflection).for_each(|li| {
        skipped.push(format!(
            "{}/{} (a lens object's reflection term reads its refraction term's shells)",
            o.name,
            o.layers[li].kind.name()
        ))
    });
    let layers = ordered_closed_shells(reader, oi, layers, "refraction", MAX_LENS_SHELLS)?;
    let v3 = |v: &[f32; 3]| glam::Vec3::from_array(*v);
    // The runtime's paths take the file's constants: IOR, absorption and the transmission
    // tint (SPEC.md 6.4, 6.6, 9).
    let material = LensMaterial {
        ior: o.shading.ior,
        base: glam::Vec3::from_array(tint),
        sigma_a: v3(&o.shading.absorption),
    };
    Ok(Some(LensState {
        layers,
        positions: o.mesh.positions.iter().map(v3).collect(),
        normals: normals.iter().map(v3).collect(),
        indices: o.mesh.indices.clone(),
        material,
        model: pis_compile::hybrid::file_lens_model(model),
        placed: None,
        gpu_rays: None,
        tessellated: None,
    }))
}

/// Every surface texture and cube-map face of the file, as the player allocates it (padded
/// to powers of two; a cube map's faces as atlases), fits the adapter's largest 2D texture:
/// checked at open, before any frame.
pub(super) fn check_texture_sizes(gpu: &Gpu, reader: &PisReader) -> Result<(), PlayError> {
    let limit = gpu.limits.max_texture_dimension_2d;
    for o in &reader.container().objects {
        for l in &o.layers {
            for b in &l.blocks {
                let (w, h) = match l.mapping {
                    Mapping::Surface => allocated_size(&TextureLayout::full(b.width, b.height)),
                    Mapping::Shell => {
                        let side = CubeAtlas::of(&TextureLayout::cube(b.width)).largest_side();
                        (side, side)
                    }
                };
                if w > limit || h > limit {
                    return Err(PlayError::TextureSize {
                        object: o.name.clone(),
                        width: b.width,
                        height: b.height,
                        limit,
                    });
                }
            }
        }
    }
    Ok(())
}
