//! The player's settings, the frame a caller asks for, and what a frame cost.

use pis_compile::hybrid::TessellationSettings;

use crate::blend::Blend;
use crate::multisample::DEFAULT_SAMPLES;

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
    /// are drawn with 1 ([`crate::Player::multisample`] says which and why).
    pub msaa: u32,
    /// The display filter multisampled frames are resolved with when the file records none
    /// (SPEC.md 6.6 `display_filter`): the ray-traced set's filter (RAYSET.md section 4).
    /// With neither, each pixel's own samples are averaged.
    pub display_filter: Option<pis_format::DisplayFilter>,
    /// Lens objects: the screen edge length in pixels down to which the tessellation is
    /// refined where vertex rays diverge (thesis 6.4.1's τ; default 1).
    pub tau_px: f32,
    /// Where textures are rebuilt from their decoded level images (default: on the GPU
    /// where the adapter is one, on the workers where it is a CPU rasterizer).
    pub rebuild: Rebuild,
    /// The precision textures are held in (default: half floats where the file records
    /// that they leave its frames within its coding error).
    pub precision: super::precision::TexturePrecision,
    /// Depth shells (SPEC.md 8.5): the march's coarse steps along each reflected ray, in
    /// place of the count the file records, which its radiance was solved with (1 to
    /// `pis_compile::shell::depth::MAX_STEPS`; default: the file's).
    pub depth_steps: Option<u32>,
    /// Where lens objects' vertex rays are traced (default: on the GPU where the adapter is
    /// one, on the workers where it is a CPU rasterizer).
    pub lens_rays: LensRays,
}

/// Where a stage of the frame that has a compute pass beside its CPU reference runs: the
/// texture rebuild ([`Rebuild`]) and the lens objects' vertex rays ([`LensRays`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum RunOn {
    /// [`RunOn::Gpu`] on a GPU, [`RunOn::Workers`] on a CPU rasterizer (Mesa's lavapipe),
    /// where a compute pass runs on the same cores as the workers, slower.
    #[default]
    Auto,
    /// Compute passes on the GPU.
    Gpu,
    /// On the workers: the reference the GPU is held to.
    Workers,
}

/// Where textures are rebuilt from their decoded level images (SPEC.md 8.4: the level
/// images summed, inverse gamma, stored MIP residuals, the MIP chain). On the GPU
/// (rebuild.wgsl) the workers only decode, and each decoded level image goes up once,
/// compact, and stays on the GPU while the level-image cache keeps it; on the workers the
/// texture is uploaded as RGBA. A resolution reduction is always rebuilt on the workers.
pub type Rebuild = RunOn;

/// Where lens objects' vertex rays are traced (thesis 6.4.1): the walk of each tessellation
/// level's vertices through the lens object. On the GPU a compute pass per level
/// (`lens_rays.wgsl`), the object's BVH uploaded once per placement, and paths deeper than
/// the shader's stack traced on the workers; on the workers pis-compile's `trace_vertex`.
pub type LensRays = RunOn;

impl RunOn {
    /// The name `--rebuild` and `--lens-rays` take.
    pub fn name(self) -> &'static str {
        match self {
            RunOn::Auto => "auto",
            RunOn::Gpu => "gpu",
            RunOn::Workers => "workers",
        }
    }

    /// Every choice, in the order the tools list them.
    pub const ALL: [RunOn; 3] = [RunOn::Auto, RunOn::Gpu, RunOn::Workers];

    /// The choice made for an adapter of `device_type`: [`RunOn::Auto`] resolved.
    pub fn on(self, device_type: wgpu::DeviceType) -> RunOn {
        match (self, device_type) {
            (RunOn::Auto, wgpu::DeviceType::Cpu) => RunOn::Workers,
            (RunOn::Auto, _) => RunOn::Gpu,
            (r, _) => r,
        }
    }
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
            rebuild: Rebuild::Auto,
            precision: super::precision::TexturePrecision::Auto,
            depth_steps: None,
            lens_rays: LensRays::Auto,
        }
    }
}

/// One frame to draw.
#[derive(Clone, Debug, PartialEq)]
pub struct FrameRequest {
    /// Per dimension, a value in the dimension's own values and units (as stored in PSPC);
    /// values between samples are allowed.
    pub point: Vec<f32>,
    pub camera: crate::camera::CameraChoice,
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
    /// Texture uploads (RGBA textures rebuilt on the workers with their MIP chains, level
    /// images for the GPU rebuild): recorded, submitted and waited for.
    pub upload_ms: f64,
    /// The GPU's rebuilds of textures from their level images (compute passes and MIP
    /// chains): recorded, submitted and waited for; 0 where the workers rebuild them.
    pub rebuild_ms: f64,
    pub upload_bytes: u64,
    /// Level-image cache lookups of this frame.
    pub cache_hits: u64,
    pub cache_misses: u64,
    /// Bytes of decoded level images cached after the frame.
    pub cache_bytes: u64,
    /// Level images this frame found decoded ahead ([`crate::Player::prefetch`]), and
    /// textures it found rebuilt ahead on the workers.
    pub prefetched: u64,
    pub rebuilt_ahead: u64,
    /// Level images this frame waited for: decoded when it asked for them, or still being
    /// decoded ahead. A frame with none did not wait on decoding.
    pub decode_waits: u64,
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
    /// Lens objects whose tessellation the frame found made ahead
    /// ([`crate::Player::prefetch`]): their rays traced while an earlier frame drew.
    pub lens_traced_ahead: u64,
    /// Draws of lens terms (two per lens object and parameter sample).
    pub lens_draws: u64,
}
