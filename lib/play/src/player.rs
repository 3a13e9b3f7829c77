//! The player (thesis 4.7): opens a `.pis` for random access, and per frame decodes on
//! worker threads the level images on the pyramid paths of the parameter samples it draws
//! (through the level-image cache), rebuilds those textures, uploads them and builds their
//! MIP chains on the GPU, and draws every object with its block's affine texture transform,
//! layers added in linear space, objects depth-tested against each other.

use std::path::Path;
use std::sync::Arc;

use crate::blend::Blend;
use crate::camera::{CameraChoice, ViewCamera};
use crate::error::PlayError;
use crate::gpu::Gpu;
use crate::image::FloatImage;

/// The player's settings.
#[derive(Clone, Debug, PartialEq)]
pub struct PlayerOptions {
    /// Memory for decoded level images (default 512 MiB).
    pub cache_budget_bytes: u64,
    /// Lifetime of a leaf level image in frames (thesis a, default 20).
    pub lifetime_a: u32,
    /// Lifetime growth per pyramid level up (thesis b, default 4).
    pub lifetime_b: u32,
    /// Decoding threads (default: cores − 1, at least 1).
    pub workers: usize,
    /// Texture resolution reduction: 1 draws full resolution; 2, 4, … draw MIP level
    /// log2(r) as the finest level (textures at 1/r resolution per side).
    pub reduction: u32,
    pub blend: Blend,
}

impl Default for PlayerOptions {
    fn default() -> Self {
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
        PlayerOptions { cache_budget_bytes: 512 << 20, lifetime_a: 20, lifetime_b: 4, workers: cores.saturating_sub(1).max(1), reduction: 1, blend: Blend::Nearest }
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
}

/// An open `.pis` ready to draw frames.
pub struct Player {
    gpu: Arc<Gpu>,
    reader: pis_format::PisReader,
    options: PlayerOptions,
}

impl Player {
    /// Opens `path` for random access (metadata read and checked; codestreams stay on disk).
    pub fn open(gpu: Arc<Gpu>, path: &Path, options: PlayerOptions) -> Result<Player, PlayError> {
        let reader = pis_format::PisReader::open(path)?;
        Ok(Player { gpu, reader, options })
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

    /// The file's camera at `point` (its nearest view sample).
    pub fn sample_camera(&self, point: &[f32]) -> ViewCamera {
        let _ = point;
        ViewCamera::from_file(&self.reader.container().cameras.cameras[0])
    }

    /// Draws a frame offscreen; linear RGBA read back (alpha 1 where an object is drawn).
    pub fn render_image(&mut self, req: &FrameRequest, size: (u32, u32)) -> Result<(FloatImage, FrameStats), PlayError> {
        let (img, _, stats) = self.render_ids(req, size)?;
        Ok((img, stats))
    }

    /// Draws a frame offscreen; also the object index per pixel (`u32::MAX`: none).
    pub fn render_ids(&mut self, req: &FrameRequest, size: (u32, u32)) -> Result<(FloatImage, Vec<u32>, FrameStats), PlayError> {
        let _ = (req, size, &self.gpu, &self.options);
        Err(PlayError::Request("not implemented".into()))
    }

    /// Draws a frame into `view` (any colour format; linear radiance, so an `*Srgb` format
    /// does the sRGB encoding).
    pub fn render_to_view(&mut self, req: &FrameRequest, view: &wgpu::TextureView, format: wgpu::TextureFormat, size: (u32, u32)) -> Result<FrameStats, PlayError> {
        let _ = (req, view, format, size);
        Err(PlayError::Request("not implemented".into()))
    }
}
