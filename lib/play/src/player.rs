//! The player (thesis 4.7): opens a `.pis` for random access, and per frame decodes on
//! worker threads the level images on the pyramid paths of the parameter samples it draws
//! (through the level-image cache), rebuilds those textures, uploads them and builds their
//! MIP chains on the GPU (a shell's cube map with every face and stored MIP level), and
//! draws every object with its block's texture transform (branch cuts, then the affine map),
//! layers added in linear space, objects depth-tested against each other; an object with
//! environment-map shells in its reflection term also gets that term (the shells composited
//! "over", times Fresnel from its f0, SPEC.md 9) per parameter sample, with the sample's
//! weight. A lens object (role `refractive`, its shells in the refraction term) is drawn by
//! hybrid rendering (thesis 6.4): per frame its vertex rays are traced through it on the
//! workers, its tessellation refined where they diverge, and both terms drawn from its
//! shells per parameter sample ([`crate::frame::hybrid`]).

use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

use pis_compile::hybrid::{
    tessellate, HybridView, LensMaterial, LensObject, TessellationSettings, TERMS,
};
use pis_compile::shell::Shell;
use pis_compile::{Address, Filter, Sampler, TextureLayout, TextureTransform};
use pis_format::blocks::{level_image_index, BlockGrid};
use pis_format::texture::LevelLayout;
use pis_format::{Container, DepMask, Mapping, PisReader, Placement, StreamRef, Term};

use crate::blend::{check_point, merge_for_mask, nearest_sample, weighted_samples, Blend};
use crate::cache::{LevelCache, LevelKey};
use crate::camera::{mat4_from_rows, projection, CameraChoice, ViewCamera};
use crate::decode::{AssembleJob, Decoder, LevelJob};
use crate::error::PlayError;
use crate::frame::hybrid::{corner_buffer, term_corners, LensDraw, MAX_LENS_SHELLS};
use crate::frame::{
    colour_image, offscreen_format, FramePipelines, LayerDraw, MeshGpu, ObjectDraw, Readback,
    ReflectionDraw, Targets, TermShell, MAX_TERM_SHELLS,
};
use crate::gpu::Gpu;
use crate::image::FloatImage;
use crate::mip::MipBuilder;
use crate::multisample::{check_samples, choose, Multisample, DEFAULT_SAMPLES};
use crate::shell::ShellTexture;
use crate::textured::{create_sampler, ObjectTexture};

/// The player's settings.
#[derive(Clone, Debug, PartialEq)]
pub struct PlayerOptions {
    /// Memory for decoded level images (default 512 MiB).
    pub cache_budget_bytes: u64,
    /// Lifetime of a leaf level image in frames (thesis a, default 20).
    pub lifetime_a: u32,
    /// Lifetime growth per pyramid level up (thesis b, default 4).
    pub lifetime_b: u32,
    /// Decoding threads (default: one per core; a frame waits for its textures, so the
    /// render thread is idle while they decode).
    pub workers: usize,
    /// Texture resolution reduction: 1 draws full resolution; 2, 4, … draw MIP level
    /// log2(r) as the finest level (textures at 1/r resolution per side).
    pub reduction: u32,
    pub blend: Blend,
    /// Samples per pixel (multisample antialiasing of object silhouettes): 1 or 4 (default
    /// 4). Where the device cannot multisample a frame's formats that many times, frames
    /// are drawn with 1 ([`Player::multisample`] says which and why).
    pub msaa: u32,
    /// The display filter multisampled frames are resolved with when the file records none
    /// (SPEC.md 6.6 `display_filter`): the ray-traced set's filter (RAYSET.md section 4).
    /// With neither, each pixel's own samples are averaged.
    pub display_filter: Option<pis_format::DisplayFilter>,
    /// Lens objects: the screen edge length in pixels down to which the tessellation is
    /// refined where vertex rays diverge (thesis 6.4.1's τ; default 1).
    pub tau_px: f32,
}

impl Default for PlayerOptions {
    fn default() -> Self {
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
        PlayerOptions {
            cache_budget_bytes: 512 << 20,
            lifetime_a: 20,
            lifetime_b: 4,
            workers: cores.max(1),
            reduction: 1,
            blend: Blend::Nearest,
            msaa: DEFAULT_SAMPLES,
            display_filter: None,
            tau_px: TessellationSettings::default().tau_px,
        }
    }
}

/// One frame to draw.
#[derive(Clone, Debug, PartialEq)]
pub struct FrameRequest {
    /// Per dimension, a value in the dimension's own values and units (as stored in PSPC);
    /// values between samples are allowed.
    pub point: Vec<f32>,
    pub camera: CameraChoice,
}

/// What one frame cost.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FrameStats {
    /// Whole frame, request to drawn (and read back, for offscreen frames).
    pub frame_ms: f64,
    /// Recording and submitting the frame's draws and waiting for the GPU to finish them
    /// (offscreen frames; a window's frame is not waited for, and this stays 0).
    pub draw_ms: f64,
    /// Copying an offscreen frame to memory and converting it to linear RGBA.
    pub readback_ms: f64,
    /// Waiting for the workers: level images decoded and textures rebuilt.
    pub decode_ms: f64,
    /// Texture uploads and GPU MIP chains.
    pub upload_ms: f64,
    pub upload_bytes: u64,
    /// Level-image cache lookups of this frame.
    pub cache_hits: u64,
    pub cache_misses: u64,
    /// Bytes of decoded level images cached after the frame.
    pub cache_bytes: u64,
    /// Codestreams read from the file for this frame.
    pub codestreams_read: u64,
    /// Draws of surface layers (one per object, layer and parameter sample).
    pub surface_draws: u64,
    /// Draws of reflection terms (one per reflective object and parameter sample, each
    /// looking up all the term's shells).
    pub shell_draws: u64,
    /// Lens objects: tracing their vertex rays, refining the tessellation and building the
    /// terms' vertex buffers (texture-coordinate generation), on a thread of its own (the
    /// tracing on the workers) while the frame's textures are decoded.
    pub lens_ms: f64,
    /// Lens objects: rays traced for the frame's vertices (none where the frame draws the
    /// previous frame's tessellation again: same camera, transform, size and τ), and the
    /// triangles drawn.
    pub lens_rays: u64,
    pub lens_triangles: u64,
    /// Draws of lens terms (two per lens object and parameter sample).
    pub lens_draws: u64,
}

/// An object's mesh on the GPU and the layers the player draws.
struct ObjectGpu {
    mesh: MeshGpu,
    /// Surface layers.
    layers: Vec<usize>,
    /// The reflection term's shell layers in increasing order (at most
    /// [`MAX_TERM_SHELLS`]); empty for an object without them or without normals.
    reflection: Vec<usize>,
    /// A lens object drawn by hybrid rendering.
    lens: Option<LensState>,
}

/// A lens object: its shell layers (the refraction term's, in increasing order, at most
/// [`MAX_LENS_SHELLS`]; both terms look them up), its triangles in object space, its
/// material, and the object placed in world space at the last transform drawn.
struct LensState {
    layers: Vec<usize>,
    positions: Vec<glam::Vec3>,
    normals: Vec<glam::Vec3>,
    indices: Vec<u32>,
    material: LensMaterial,
    placed: Option<(glam::Mat4, LensObject)>,
    /// The last frame's tessellation and what it was made for (transform, eye, view and
    /// projection, frame size, τ): a frame that changes none of them draws it again.
    tessellated: Option<(TessellationKey, std::sync::Arc<pis_compile::hybrid::Tessellation>)>,
}

/// What a lens object's tessellation depends on.
type TessellationKey = (glam::Mat4, glam::Vec3, glam::Mat4, (u32, u32), f32);

impl LensState {
    /// The lens object at `world` (rigid), built once per transform.
    fn at(&mut self, world: glam::Mat4) -> &LensObject {
        if self.placed.as_ref().is_none_or(|(m, _)| *m != world) {
            let positions = self.positions.iter().map(|&p| world.transform_point3(p)).collect();
            let normals = self.normals.iter().map(|&n| world.transform_vector3(n)).collect();
            self.placed =
                Some((world, LensObject::new(self.material, positions, normals, &self.indices)));
        }
        &self.placed.as_ref().expect("placed above").1
    }
}

/// A rebuilt texture: object, layer, block, the image of every pyramid level it sums.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
struct TextureKey {
    object: u32,
    layer: u32,
    block: u32,
    images: Vec<u32>,
}

/// A texture on the GPU: a surface texture with its MIP chain, or a shell's cube map.
enum GpuTexture {
    Surface(ObjectTexture),
    Shell(ShellTexture),
}

/// A texture on the GPU and the frame that last drew it.
struct Resident {
    texture: GpuTexture,
    last_frame: u64,
}

/// One texture a frame draws.
struct Wanted {
    draw: usize,
    key: TextureKey,
    weight: f32,
    transform: TextureTransform,
    repeat: [bool; 2],
}

/// One reflection term a frame draws: an object's shells at one parameter sample.
struct WantedReflection {
    draw: usize,
    weight: f32,
    /// Per shell of the term, in order: its texture, its geometry and its lookups per pixel
    /// side (SPEC.md 8.2).
    shells: Vec<(TextureKey, Shell, u32)>,
}

/// What a frame draws: per object its clip and world transforms, the frame's camera
/// position, and the textures and reflection terms of the parameter samples.
struct Plan {
    clips: Vec<glam::Mat4>,
    worlds: Vec<glam::Mat4>,
    eye: glam::Vec3,
    surfaces: Vec<Wanted>,
    reflections: Vec<WantedReflection>,
    /// Lens objects' shells per parameter sample (both terms look them up).
    lenses: Vec<WantedReflection>,
    clip_from_world: glam::Mat4,
}

impl Plan {
    /// Every texture the frame draws (a texture drawn twice is listed twice).
    fn keys(&self) -> Vec<&TextureKey> {
        let shells = self
            .reflections
            .iter()
            .chain(&self.lenses)
            .flat_map(|r| r.shells.iter().map(|(k, _, _)| k));
        self.surfaces.iter().map(|w| &w.key).chain(shells).collect()
    }
}

/// An offscreen frame read back: colour and, when asked for, object indices.
type Readout = (FloatImage, Option<Vec<u32>>);

/// Where a frame is drawn.
#[derive(Clone, Copy)]
enum Target<'a> {
    /// The offscreen target, read back (with every pixel's object index if `ids`).
    Offscreen { ids: bool },
    /// The offscreen target, drawn and waited for but not read back: a frame's cost as
    /// playback pays it, where the frame is shown rather than copied to memory.
    Timed,
    /// A caller's view of the given format.
    View(&'a wgpu::TextureView, wgpu::TextureFormat),
}

/// An open `.pis` ready to draw frames.
pub struct Player {
    gpu: Arc<Gpu>,
    reader: PisReader,
    options: PlayerOptions,
    decoder: Decoder,
    cache: LevelCache,
    objects: Vec<ObjectGpu>,
    filter: Filter,
    pipes: FramePipelines,
    mips: MipBuilder,
    targets: Option<Targets>,
    /// The multisampling of frames per target format (offscreen first).
    multisample: HashMap<wgpu::TextureFormat, Multisample>,
    readback: Option<(Readback, Readback)>,
    /// The display filter multisampled frames are resolved with, and whether the file
    /// records it.
    display: Option<(pis_format::DisplayFilter, bool)>,
    resident: HashMap<TextureKey, Resident>,
    samplers: HashMap<[bool; 2], wgpu::Sampler>,
    frame: u64,
}

/// The texture filter the file's textures were solved for: pis-pack records it in the
/// provenance settings (`filter`, `anisotropy`; SPEC.md 6.6); trilinear when absent. The
/// reader has checked the settings (rule 9001).
fn file_filter(c: &Container<StreamRef>) -> Filter {
    match pis_format::FileFilter::of(c.provenance.as_ref()).unwrap_or_default() {
        pis_format::FileFilter::Nearest => Filter::Nearest,
        pis_format::FileFilter::Bilinear => Filter::Bilinear,
        pis_format::FileFilter::Trilinear => Filter::Trilinear,
        pis_format::FileFilter::Anisotropic(n) => Filter::Anisotropic(n),
    }
}

fn content(reader: &PisReader, message: String) -> PlayError {
    PlayError::Content { path: reader.path().display().to_string(), message }
}

/// Checks what the player relies on beyond the reader's validation and uploads the meshes.
fn prepare_objects(gpu: &Gpu, reader: &PisReader) -> Result<Vec<ObjectGpu>, PlayError> {
    let c = reader.container();
    let mut out = Vec::with_capacity(c.objects.len());
    let mut skipped = Vec::new();
    // The reader has checked the tints (rule 9004).
    let named: Vec<(&str, pis_format::ObjectRole)> =
        c.objects.iter().map(|o| (o.name.as_str(), o.role)).collect();
    let tints = pis_format::tint::tints(c.provenance.as_ref(), &named)
        .unwrap_or_else(|_| vec![[1.0; 3]; c.objects.len()]);
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
        let lens = lens_state(reader, oi, tints[oi], &mut skipped)?;
        let reflection =
            if lens.is_some() { Vec::new() } else { reflection_shells(reader, oi, &mut skipped)? };
        let mesh =
            MeshGpu::new(gpu, &o.mesh.positions, o.mesh.normals.as_deref(), &uvs, &o.mesh.indices)
                .with_hull(o.mesh.hull_triangles);
        out.push(ObjectGpu { mesh, layers, reflection, lens });
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
/// tint `tint`. Its reflection term's own shells, if any, are not drawn (listed in
/// `skipped`), nor are the shells of a refractive object without normals.
fn lens_state(
    reader: &PisReader,
    oi: usize,
    tint: [f32; 3],
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
        placed: None,
        tessellated: None,
    }))
}

/// The cube-map geometry of a shell block's placement (SPEC.md 7.3) and its lookups per
/// pixel side (8.2); `None` for a quad or a surface placement.
fn shell_of(placement: &Placement) -> Option<(Shell, u32)> {
    let Placement::Shell { shape, origin, params, lookups } = placement else { return None };
    let mut values = [0.0f32; 12];
    values[..3].copy_from_slice(origin);
    values[3..9].copy_from_slice(params);
    Shell::from_placement(shape.code() as u16, &values).map(|s| (s, *lookups))
}

/// The reflection terms of a plan, with their cube maps on the GPU (`resident`).
fn reflection_draws<'a>(
    reader: &PisReader,
    resident: &'a HashMap<TextureKey, Resident>,
    plan: &Plan,
) -> Result<Vec<ReflectionDraw<'a>>, PlayError> {
    let c = reader.container();
    let mut out = Vec::with_capacity(plan.reflections.len());
    for r in &plan.reflections {
        let mut shells = Vec::with_capacity(r.shells.len());
        for (key, shell, lookups) in &r.shells {
            let GpuTexture::Shell(cube) = &resident[key].texture else {
                return Err(content(
                    reader,
                    format!("{key:?}: a surface texture drawn as a shell"),
                ));
            };
            shells.push(TermShell { shell: *shell, lookups: *lookups, cube });
        }
        out.push(ReflectionDraw {
            draw: r.draw,
            world_from_object: plan.worlds[r.draw],
            eye: plan.eye,
            f0: c.objects[r.draw].shading.f0,
            weight: r.weight,
            shells,
        });
    }
    Ok(out)
}

/// Every surface texture and cube-map face of the file, as the player allocates it (padded
/// to powers of two), fits the adapter's largest 2D texture: checked at open, before any
/// frame.
fn check_texture_sizes(gpu: &Gpu, reader: &PisReader) -> Result<(), PlayError> {
    let limit = gpu.limits.max_texture_dimension_2d;
    for o in &reader.container().objects {
        for l in &o.layers {
            for b in &l.blocks {
                let (w, h) = match l.mapping {
                    Mapping::Surface => {
                        crate::textured::allocated_size(&TextureLayout::full(b.width, b.height))
                    }
                    Mapping::Shell => (b.width.next_power_of_two(), b.height.next_power_of_two()),
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

impl Player {
    /// Opens `path` for random access (metadata read and checked; codestreams stay on disk
    /// until a frame needs them).
    pub fn open(gpu: Arc<Gpu>, path: &Path, options: PlayerOptions) -> Result<Player, PlayError> {
        if options.reduction == 0 || !options.reduction.is_power_of_two() {
            return Err(PlayError::Request(format!(
                "texture resolution reduction {} must be a power of two (1, 2, 4, …)",
                options.reduction
            )));
        }
        check_samples(options.msaa).map_err(PlayError::Request)?;
        let reader = PisReader::open(path)?;
        check_texture_sizes(&gpu, &reader)?;
        let objects = prepare_objects(&gpu, &reader)?;
        let filter = file_filter(reader.container());
        // The reader has checked the settings (rule 9002).
        let file_display =
            pis_format::DisplayFilter::of(reader.container().provenance.as_ref()).ok().flatten();
        let display =
            file_display.map(|f| (f, true)).or(options.display_filter.map(|f| (f, false)));
        let decoder = Decoder::new(options.workers)?;
        let cache =
            LevelCache::new(options.cache_budget_bytes, options.lifetime_a, options.lifetime_b);
        let mut pipes = FramePipelines::new(&gpu);
        let offscreen = offscreen_format(&gpu);
        let ms = choose(&gpu, options.msaa, offscreen);
        // Compiled now rather than in the first frame's time.
        pipes.id_pipeline(&gpu, ms.samples);
        pipes.layer_pipeline(&gpu, offscreen, ms.samples);
        if objects.iter().any(|o| !o.reflection.is_empty()) {
            pipes.reflection_pipeline(&gpu, offscreen, ms.samples);
        }
        if objects.iter().any(|o| o.lens.is_some()) {
            pipes.hybrid_pipeline(&gpu, offscreen, ms.samples);
        }
        let mips = MipBuilder::new(&gpu);
        Ok(Player {
            gpu,
            reader,
            options,
            decoder,
            cache,
            objects,
            filter,
            pipes,
            mips,
            targets: None,
            multisample: HashMap::from([(offscreen, ms)]),
            readback: None,
            display,
            resident: HashMap::new(),
            samplers: HashMap::new(),
            frame: 0,
        })
    }

    /// The parameter space's dimensions.
    pub fn dimensions(&self) -> &[pis_format::Dimension] {
        &self.reader.container().space.dims
    }

    /// The objects' names, in file order (the indices `render_ids` reports).
    pub fn object_names(&self) -> Vec<String> {
        self.reader.container().objects.iter().map(|o| o.name.clone()).collect()
    }

    /// The image size of the file's cameras (the ray-traced set's resolution).
    pub fn image_size(&self) -> (u32, u32) {
        let c = &self.reader.container().cameras;
        (c.width, c.height)
    }

    /// The options the player was opened with.
    pub fn options(&self) -> &PlayerOptions {
        &self.options
    }

    /// The open file (its container and read counters).
    pub fn reader(&self) -> &PisReader {
        &self.reader
    }

    /// The level-image cache.
    pub fn cache(&self) -> &LevelCache {
        &self.cache
    }

    /// The format offscreen frames are drawn in before readback.
    pub fn offscreen_format(&self) -> wgpu::TextureFormat {
        offscreen_format(&self.gpu)
    }

    /// The multisampling of offscreen frames: samples per pixel asked for and drawn with.
    pub fn multisample(&self) -> &Multisample {
        &self.multisample[&offscreen_format(&self.gpu)]
    }

    /// The multisampling of frames drawn into targets of `format` ([`Player::render_to_view`]).
    /// With a display filter the samples are drawn in the offscreen format whatever the
    /// target's, and resolved by a shader: that format must multisample.
    pub fn multisample_for(&mut self, format: wgpu::TextureFormat) -> &Multisample {
        let (gpu, msaa) = (&self.gpu, self.options.msaa);
        let drawn = if self.display.is_some() { offscreen_format(gpu) } else { format };
        self.multisample.entry(format).or_insert_with(|| choose(gpu, msaa, drawn))
    }

    /// The display filter multisampled frames are resolved with (the ray-traced set's, RAYSET.md
    /// section 4), and whether the file records it (else it came from
    /// [`PlayerOptions::display_filter`]); `None`: each pixel's own samples are averaged.
    pub fn display_filter(&self) -> Option<(pis_format::DisplayFilter, bool)> {
        self.display
    }

    /// The nearest parameter sample of `point` (missing values count as the first sample,
    /// extra values are ignored).
    fn nearest(&self, point: &[f32]) -> Vec<u32> {
        let dims = self.dimensions();
        let mut full: Vec<f32> =
            dims.iter().map(|d| d.values.first().copied().unwrap_or(0.0)).collect();
        for (f, &v) in full.iter_mut().zip(point) {
            if v.is_finite() {
                *f = v;
            }
        }
        nearest_sample(dims, &full)
    }

    fn camera_record(&self, sample: &[u32]) -> pis_format::Camera {
        let c = self.reader.container();
        let i = c.space.table_index(c.cameras.depends_on, sample);
        c.cameras.cameras.get(i).or(c.cameras.cameras.first()).copied().unwrap_or(
            pis_format::Camera {
                world_from_camera: pis_format::IDENTITY_3X4,
                yfov: 0.8,
                znear: 0.1,
                zfar: 100.0,
            },
        )
    }

    /// The file's camera at `point` (its nearest view sample).
    pub fn sample_camera(&self, point: &[f32]) -> ViewCamera {
        ViewCamera::from_file(&self.camera_record(&self.nearest(point)))
    }

    /// Draws a frame offscreen; linear RGBA read back, colour premultiplied by coverage:
    /// alpha is the fraction of the pixel's samples objects cover (1 inside objects, 0
    /// where none is drawn, between on silhouettes of multisampled frames; with a display
    /// filter, the objects' filtered coverage of the pixel's 3×3 neighbourhood's samples).
    pub fn render_image(
        &mut self,
        req: &FrameRequest,
        size: (u32, u32),
    ) -> Result<(FloatImage, FrameStats), PlayError> {
        let (out, stats) = self.frame(req, size, Target::Offscreen { ids: false })?;
        let (img, _) = out.ok_or_else(|| PlayError::Readback("no offscreen frame".into()))?;
        Ok((img, stats))
    }

    /// Draws a frame offscreen ([`Player::render_image`]); also the object index per pixel,
    /// the nearest surface at the pixel's centre (`u32::MAX`: none).
    pub fn render_ids(
        &mut self,
        req: &FrameRequest,
        size: (u32, u32),
    ) -> Result<(FloatImage, Vec<u32>, FrameStats), PlayError> {
        let (out, stats) = self.frame(req, size, Target::Offscreen { ids: true })?;
        let (img, ids) = out.ok_or_else(|| PlayError::Readback("no offscreen frame".into()))?;
        Ok((img, ids.unwrap_or_default(), stats))
    }

    /// Draws a frame offscreen and waits for the GPU to finish it, without reading it back:
    /// what the frame costs where it is shown rather than copied to memory (timings).
    pub fn render_timed(
        &mut self,
        req: &FrameRequest,
        size: (u32, u32),
    ) -> Result<FrameStats, PlayError> {
        Ok(self.frame(req, size, Target::Timed)?.1)
    }

    /// Draws a frame into `view` (any colour format; linear radiance, so an `*Srgb` format
    /// does the sRGB encoding) of `size`, with [`Player::multisample_for`] the format's
    /// samples per pixel resolved into it.
    pub fn render_to_view(
        &mut self,
        req: &FrameRequest,
        view: &wgpu::TextureView,
        format: wgpu::TextureFormat,
        size: (u32, u32),
    ) -> Result<FrameStats, PlayError> {
        Ok(self.frame(req, size, Target::View(view, format))?.1)
    }

    /// What a frame draws: the objects' transforms, the camera position, and per object the
    /// textures of its surface layers and its reflection terms at the parameter samples.
    fn plan(&self, req: &FrameRequest, size: (u32, u32)) -> Result<Plan, PlayError> {
        let c = self.reader.container();
        let dims = &c.space.dims;
        check_point(dims, &req.point).map_err(PlayError::Request)?;
        let samples = weighted_samples(dims, &req.point, self.options.blend);
        let nearest = nearest_sample(dims, &req.point);
        let (clip_from_world, eye) = match req.camera {
            CameraChoice::Sample => {
                let cam = self.camera_record(&nearest);
                let world_from_camera = mat4_from_rows(&cam.world_from_camera);
                (
                    projection(cam.yfov, cam.znear, cam.zfar, size.0, size.1)
                        * world_from_camera.inverse(),
                    world_from_camera.w_axis.truncate(),
                )
            }
            CameraChoice::Free(cam) => {
                cam.check().map_err(PlayError::Request)?;
                (cam.projection(size) * cam.view_matrix(), cam.eye)
            }
        };
        let mut plan = Plan {
            clips: Vec::with_capacity(c.objects.len()),
            worlds: Vec::with_capacity(c.objects.len()),
            eye,
            surfaces: Vec::new(),
            reflections: Vec::new(),
            lenses: Vec::new(),
            clip_from_world,
        };
        for (oi, (o, og)) in c.objects.iter().zip(&self.objects).enumerate() {
            let t = &o.transforms;
            let world = t
                .transforms
                .get(c.space.table_index(t.depends_on, &nearest))
                .map_or(glam::Mat4::IDENTITY, mat4_from_rows);
            plan.clips.push(clip_from_world * world);
            plan.worlds.push(world);
            for &li in &og.layers {
                for (s, w) in merge_for_mask(&samples, o.layers[li].depends_on) {
                    let (key, block) = self.texture_key(oi, li, &s)?;
                    let Placement::Surface { affine, repeat, cut } = block.placement else {
                        continue;
                    };
                    plan.surfaces.push(Wanted {
                        draw: oi,
                        key,
                        weight: w,
                        transform: TextureTransform { values: affine, cut },
                        repeat,
                    });
                }
            }
            plan.reflections.extend(self.shell_terms(oi, &og.reflection, &samples)?);
            if let Some(lens) = &og.lens {
                plan.lenses.extend(self.shell_terms(oi, &lens.layers, &samples)?);
            }
        }
        Ok(plan)
    }

    /// The texture of object `oi`'s layer `li` at parameter sample `sample`: its key and its
    /// block.
    fn texture_key(
        &self,
        oi: usize,
        li: usize,
        sample: &[u32],
    ) -> Result<(TextureKey, &pis_format::Block<StreamRef>), PlayError> {
        let c = self.reader.container();
        let (o, layer) = (&c.objects[oi], &c.objects[oi].layers[li]);
        let pos = BlockGrid::new(&c.space, layer.depends_on, &o.stagger).locate(sample);
        let block = layer.blocks.get(pos.block).ok_or_else(|| {
            content(&self.reader, format!("object {oi} layer {li}: block {} missing", pos.block))
        })?;
        let images = block
            .levels
            .iter()
            .map(|l| level_image_index(&l.counts, &pos.local, &pos.extent) as u32)
            .collect();
        Ok((
            TextureKey { object: oi as u32, layer: li as u32, block: pos.block as u32, images },
            block,
        ))
    }

    /// Object `oi`'s terms of shell layers `term` (in order) at the weighted parameter
    /// samples: one per class of samples the term's shells cannot tell apart (equal on the
    /// union of their dependency masks), with the class's summed weight, as the surface
    /// layers are blended.
    fn shell_terms(
        &self,
        oi: usize,
        term: &[usize],
        samples: &[(Vec<u32>, f32)],
    ) -> Result<Vec<WantedReflection>, PlayError> {
        let o = &self.reader.container().objects[oi];
        if term.is_empty() {
            return Ok(Vec::new());
        }
        let mask = DepMask(term.iter().fold(0, |m, &li| m | o.layers[li].depends_on.0));
        let mut out = Vec::new();
        for (s, weight) in merge_for_mask(samples, mask) {
            let mut shells = Vec::with_capacity(term.len());
            for &li in term {
                let (key, block) = self.texture_key(oi, li, &s)?;
                let (shell, lookups) = shell_of(&block.placement).ok_or_else(|| {
                    content(
                        &self.reader,
                        format!("object {oi} layer {li} block {}: not a closed shell", key.block),
                    )
                })?;
                shells.push((key, shell, lookups));
            }
            out.push(WantedReflection { draw: oi, weight, shells });
        }
        Ok(out)
    }

    /// Decodes (on the workers) and uploads every wanted texture not on the GPU.
    fn make_resident(
        &mut self,
        wanted: &[&TextureKey],
        stats: &mut FrameStats,
    ) -> Result<(), PlayError> {
        let frame = self.frame;
        let mut missing: Vec<&TextureKey> = Vec::new();
        for &key in wanted {
            match self.resident.get_mut(key) {
                Some(r) => r.last_frame = frame,
                None if !missing.contains(&key) => missing.push(key),
                None => {}
            }
        }
        if missing.is_empty() {
            return Ok(());
        }
        let c = self.reader.container();
        let t = Instant::now();
        let hits0 = self.cache.counters();
        // Level images: cached, or decoded on the workers (each once).
        let mut have: HashMap<LevelKey, Arc<Vec<f32>>> = HashMap::new();
        let mut jobs: Vec<(LevelKey, u32, LevelJob)> = Vec::new();
        for k in &missing {
            let layer = &c.objects[k.object as usize].layers[k.layer as usize];
            let block = &layer.blocks[k.block as usize];
            let planes = LevelLayout::of(layer, block).planes();
            let n = block.levels.len() as u32;
            for (lv, (level, &img)) in block.levels.iter().zip(&k.images).enumerate() {
                let key = LevelKey {
                    object: k.object,
                    layer: k.layer,
                    block: k.block,
                    level: lv as u32,
                    image: img,
                };
                if have.contains_key(&key) || jobs.iter().any(|j| j.0 == key) {
                    continue;
                }
                match self.cache.get(&key) {
                    Some(v) => {
                        have.insert(key, v);
                    }
                    None => {
                        let stream = *level.images.get(img as usize).ok_or_else(|| {
                            content(&self.reader, format!("{key:?}: no such level image"))
                        })?;
                        let at = (k.object as usize, k.layer as usize, k.block as usize, lv);
                        jobs.push((
                            key,
                            n - 1 - lv as u32,
                            LevelJob { stream, planes: planes.clone(), at },
                        ));
                    }
                }
            }
        }
        let level_jobs: Vec<LevelJob> = jobs.iter().map(|j| j.2.clone()).collect();
        let decoded = self.decoder.decode_levels(&self.reader, &level_jobs);
        let mut first_error = None;
        for ((key, height, _), r) in jobs.into_iter().zip(decoded) {
            match r {
                Ok(v) => {
                    let v = Arc::new(v);
                    self.cache.insert(key, height, v.clone());
                    have.insert(key, v);
                }
                Err(e) => {
                    first_error.get_or_insert(e);
                }
            }
        }
        if let Some(e) = first_error {
            return Err(e);
        }
        // Textures rebuilt on the workers: surface textures' finest levels, shells' cube maps.
        let drop_levels = self.options.reduction.trailing_zeros();
        let is_shell = |k: &TextureKey| {
            c.objects[k.object as usize].layers[k.layer as usize].mapping == Mapping::Shell
        };
        let (shells, surfaces): (Vec<&TextureKey>, Vec<&TextureKey>) =
            missing.iter().partition(|k| is_shell(k));
        let job = |k: &&TextureKey| {
            let layer = &c.objects[k.object as usize].layers[k.layer as usize];
            let block = &layer.blocks[k.block as usize];
            let levels = k
                .images
                .iter()
                .enumerate()
                .map(|(lv, &img)| {
                    have[&LevelKey {
                        object: k.object,
                        layer: k.layer,
                        block: k.block,
                        level: lv as u32,
                        image: img,
                    }]
                        .clone()
                })
                .collect();
            let full = TextureLayout::full(block.width, block.height).levels;
            AssembleJob {
                layer,
                layout: LevelLayout::of(layer, block),
                levels,
                drop_levels: drop_levels.min(full.saturating_sub(1)),
            }
        };
        let images = self.decoder.assemble(&surfaces.iter().map(job).collect::<Vec<_>>());
        let cubes = self.decoder.assemble_cubes(&shells.iter().map(job).collect::<Vec<_>>());
        stats.decode_ms += t.elapsed().as_secs_f64() * 1e3;
        let hits1 = self.cache.counters();
        stats.cache_hits += hits1.hits - hits0.hits;
        stats.cache_misses += hits1.misses - hits0.misses;
        // Uploads, GPU MIP chains of surface textures, cube maps with their stored levels.
        let t = Instant::now();
        let mut encoder = self
            .gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("uploads") });
        let mut made = Vec::with_capacity(missing.len());
        for (k, img) in surfaces.iter().zip(&images) {
            let texture = self.mips.texture(&self.gpu, TextureLayout::full(img.width, img.height));
            stats.upload_bytes += self.mips.upload(&self.gpu, &texture, img, &mut encoder)?;
            made.push((
                (*k).clone(),
                Resident { texture: GpuTexture::Surface(texture), last_frame: frame },
            ));
        }
        for (k, cube) in shells.iter().zip(&cubes) {
            let texture =
                ShellTexture::new(&self.gpu, cube.layout, &c.objects[k.object as usize].name)?;
            texture.upload(&self.gpu, &cube.rgba)?;
            stats.upload_bytes += (cube.rgba.len() * 4) as u64;
            made.push((
                (*k).clone(),
                Resident { texture: GpuTexture::Shell(texture), last_frame: frame },
            ));
        }
        self.gpu.queue.submit([encoder.finish()]);
        self.gpu
            .device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| PlayError::Readback(e.to_string()))?;
        self.resident.extend(made);
        stats.upload_ms += t.elapsed().as_secs_f64() * 1e3;
        Ok(())
    }

    fn frame(
        &mut self,
        req: &FrameRequest,
        size: (u32, u32),
        target: Target,
    ) -> Result<(Option<Readout>, FrameStats), PlayError> {
        let t0 = Instant::now();
        let reads0 = self.reader.stats().codestreams;
        let mut stats = FrameStats::default();
        let plan = self.plan(req, size)?;
        // Lens objects' vertex rays, tessellation and vertex buffers on their own thread (its
        // tracing on the workers) while the textures are decoded: their states are taken out
        // of the objects for the frame.
        let mut lens_states: Vec<(usize, LensState)> = Vec::new();
        for r in &plan.lenses {
            if !lens_states.iter().any(|(d, _)| *d == r.draw) {
                if let Some(state) = self.objects[r.draw].lens.take() {
                    lens_states.push((r.draw, state));
                }
            }
        }
        let tau_px = self.options.tau_px;
        let gpu_for_lenses = self.gpu.clone();
        let (result, lens_work) = std::thread::scope(|scope| {
            let lens_thread = scope
                .spawn(|| lens_corners(&gpu_for_lenses, &mut lens_states, &plan, size, tau_px));
            let result = self.make_resident(&plan.keys(), &mut stats);
            (result, lens_thread.join())
        });
        for (draw, state) in lens_states {
            self.objects[draw].lens = Some(state);
        }
        let lens_work = match lens_work {
            Ok(w) => w,
            Err(_) => {
                self.end_frame();
                return Err(PlayError::Request("the lens objects' tessellation failed".into()));
            }
        };
        if let Err(e) = result {
            self.end_frame();
            return Err(e);
        }
        let corner_sets = lens_work.sets;
        stats.lens_ms = lens_work.ms;
        stats.lens_rays = lens_work.rays;
        stats.lens_triangles = lens_work.triangles;
        let format = match target {
            Target::Offscreen { .. } | Target::Timed => offscreen_format(&self.gpu),
            Target::View(_, f) => f,
        };
        let samples = self.multisample_for(format).samples;
        if self.targets.as_ref().is_none_or(|t| t.size != size || t.samples != samples) {
            self.targets = Some(Targets::new(&self.gpu, &self.pipes, size, samples)?);
            self.readback = None;
        }
        let gpu = self.gpu.clone();
        let objects: Vec<ObjectDraw> = self
            .objects
            .iter()
            .zip(&plan.clips)
            .enumerate()
            .map(|(i, (o, &clip))| ObjectDraw {
                object: i as u32,
                mesh: &o.mesh,
                clip_from_object: clip,
            })
            .collect();
        for w in &plan.surfaces {
            self.samplers.entry(w.repeat).or_insert_with(|| {
                let address =
                    w.repeat.map(|r| if r { Address::Repeat } else { Address::ClampToEdge });
                create_sampler(&gpu, &Sampler { filter: self.filter, address })
            });
        }
        let mut layers = Vec::with_capacity(plan.surfaces.len());
        for w in &plan.surfaces {
            let GpuTexture::Surface(texture) = &self.resident[&w.key].texture else {
                return Err(content(
                    &self.reader,
                    format!("{:?}: a shell's texture drawn as a surface layer", w.key),
                ));
            };
            let sampler = Sampler {
                filter: self.filter,
                address: w.repeat.map(|r| if r { Address::Repeat } else { Address::ClampToEdge }),
            };
            for (axis, k, s) in [('s', 0, texture.layout.width), ('t', 1, texture.layout.height)] {
                if w.repeat[k] && !s.is_power_of_two() {
                    return Err(PlayError::RepeatSize { axis, size: s });
                }
            }
            layers.push(LayerDraw {
                draw: w.draw,
                texture,
                sampler: &self.samplers[&w.repeat],
                transform: w.transform,
                max_level: pis_compile::filter::max_level(&texture.layout, &sampler) as f32,
                weight: w.weight,
                anisotropic: matches!(self.filter, Filter::Anisotropic(_)),
            });
        }
        let reflections = reflection_draws(&self.reader, &self.resident, &plan)?;
        let mut lenses = Vec::new();
        for r in &plan.lenses {
            let shells: Vec<Shell> = r.shells.iter().map(|(_, s, _)| *s).collect();
            let Some((_, _, buffers)) =
                corner_sets.iter().find(|(d, s, _)| *d == r.draw && *s == shells)
            else {
                continue;
            };
            let mut cubes = Vec::with_capacity(r.shells.len());
            for (key, _, _) in &r.shells {
                let GpuTexture::Shell(cube) = &self.resident[key].texture else {
                    return Err(content(
                        &self.reader,
                        format!("{key:?}: a surface texture drawn as a shell"),
                    ));
                };
                cubes.push(cube);
            }
            for (corners, count) in buffers {
                lenses.push(LensDraw {
                    object: r.draw as u32,
                    clip_from_world: plan.clip_from_world,
                    weight: r.weight,
                    corners,
                    count: *count,
                    shells: cubes.clone(),
                });
            }
        }
        stats.lens_draws = lenses.len() as u64;
        stats.surface_draws = layers.len() as u64;
        stats.shell_draws = reflections.len() as u64;
        let targets = self.targets.as_mut().expect("targets made above");
        let t_draw = Instant::now();
        let mut encoder = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("frame") });
        let offscreen_view;
        let (view, want_ids) = match target {
            Target::View(v, _) => (v, false),
            Target::Offscreen { ids } => {
                offscreen_view = targets.colour.create_view(&Default::default());
                (&offscreen_view, ids)
            }
            Target::Timed => {
                offscreen_view = targets.colour.create_view(&Default::default());
                (&offscreen_view, false)
            }
        };
        let display = self.display.map(|(f, _)| f);
        crate::frame::encode(
            &gpu,
            &mut self.pipes,
            targets,
            view,
            format,
            &objects,
            &layers,
            &reflections,
            &lenses,
            want_ids,
            display,
            &mut encoder,
        );
        let out = match target {
            Target::Offscreen { ids } => {
                gpu.queue.submit([encoder.finish()]);
                wait_for_gpu(&gpu)?;
                stats.draw_ms = t_draw.elapsed().as_secs_f64() * 1e3;
                let t_read = Instant::now();
                let texel = if format == wgpu::TextureFormat::Rgba16Float { 8 } else { 16 };
                let (rc, ri) = self.readback.get_or_insert_with(|| {
                    (Readback::new(&gpu, size, texel), Readback::new(&gpu, size, 4))
                });
                let mut copy = gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
                    label: Some("readback"),
                });
                rc.copy(&targets.colour, &mut copy);
                if ids {
                    ri.copy(&targets.ids, &mut copy);
                }
                gpu.queue.submit([copy.finish()]);
                let colour = colour_image(&rc.read(&gpu)?, format, size);
                let ids = if ids {
                    Some(
                        ri.read(&gpu)?
                            .chunks_exact(4)
                            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
                            .collect(),
                    )
                } else {
                    None
                };
                stats.readback_ms = t_read.elapsed().as_secs_f64() * 1e3;
                Some((colour, ids))
            }
            Target::Timed => {
                gpu.queue.submit([encoder.finish()]);
                wait_for_gpu(&gpu)?;
                stats.draw_ms = t_draw.elapsed().as_secs_f64() * 1e3;
                None
            }
            Target::View(..) => {
                gpu.queue.submit([encoder.finish()]);
                None
            }
        };
        drop(lenses);
        drop(reflections);
        drop(layers);
        drop(objects);
        self.end_frame();
        stats.cache_bytes = self.cache.bytes();
        stats.codestreams_read = self.reader.stats().codestreams - reads0;
        stats.frame_ms = t0.elapsed().as_secs_f64() * 1e3;
        Ok((out, stats))
    }

    /// Ends the frame: level-image lifetimes and budget, and GPU textures the frame did not
    /// draw released.
    fn end_frame(&mut self) {
        let frame = self.frame;
        self.resident.retain(|_, r| r.last_frame == frame);
        self.cache.end_frame();
        self.frame += 1;
    }
}

/// A frame's lens work: per lens object and shell geometry, both terms' corner buffers
/// (and their corner counts); the time it took, its rays and triangles.
struct LensWork {
    sets: Vec<(usize, Vec<Shell>, [(wgpu::Buffer, u32); 2])>,
    ms: f64,
    rays: u64,
    triangles: u64,
}

/// Traces the vertex rays of every lens object `plan` draws through the object placed at
/// the frame's transform, refines its tessellation down to `tau_px`, and builds both
/// terms' corners once per object and shell geometry (`states`: the objects' lens states).
fn lens_corners(
    gpu: &Gpu,
    states: &mut [(usize, LensState)],
    plan: &Plan,
    size: (u32, u32),
    tau_px: f32,
) -> LensWork {
    let t = Instant::now();
    let settings = TessellationSettings { tau_px, ..TessellationSettings::default() };
    let mut work = LensWork { sets: Vec::new(), ms: 0.0, rays: 0, triangles: 0 };
    for r in &plan.lenses {
        let shells: Vec<Shell> = r.shells.iter().map(|(_, s, _)| *s).collect();
        if work.sets.iter().any(|(d, s, _)| *d == r.draw && *s == shells) {
            continue;
        }
        let Some((_, state)) = states.iter_mut().find(|(d, _)| *d == r.draw) else { continue };
        let key: TessellationKey =
            (plan.worlds[r.draw], plan.eye, plan.clip_from_world, size, tau_px);
        let tess = match &state.tessellated {
            Some((k, t)) if *k == key => t.clone(),
            _ => {
                let lens = state.at(plan.worlds[r.draw]);
                let t = std::sync::Arc::new(tessellate(
                    lens,
                    &HybridView { eye: plan.eye, clip_from_world: plan.clip_from_world, size },
                    &settings,
                ));
                state.tessellated = Some((key, t.clone()));
                work.rays += t.stats.rays;
                t
            }
        };
        let (reflection, refraction) = rayon::join(
            || term_corners(&tess, TERMS[0], &shells),
            || term_corners(&tess, TERMS[1], &shells),
        );
        let buffers = [reflection, refraction]
            .map(|corners| (corner_buffer(gpu, &corners), corners.len() as u32));
        work.triangles += buffers.iter().map(|b| b.1 as u64 / 3).max().unwrap_or(0);
        work.sets.push((r.draw, shells, buffers));
    }
    work.ms = t.elapsed().as_secs_f64() * 1e3;
    work
}

/// Blocks until the GPU has finished everything submitted.
fn wait_for_gpu(gpu: &Gpu) -> Result<(), PlayError> {
    gpu.device
        .poll(wgpu::PollType::wait_indefinitely())
        .map(|_| ())
        .map_err(|e| PlayError::Readback(e.to_string()))
}
