//! The per-size targets a frame is drawn into: object indices, depth and the offscreen
//! colour target, and for more than one sample per pixel the multisampled attachments.

use std::collections::HashMap;

use super::draw::ID_FORMAT;
use super::pipelines::FramePipelines;
use crate::error::PlayError;
use crate::gpu::Gpu;
use crate::textured::DEPTH_FORMAT;

/// The format offscreen frames accumulate in: `Rgba32Float` where the device can blend it,
/// else `Rgba16Float`.
pub fn offscreen_format(gpu: &Gpu) -> wgpu::TextureFormat {
    if gpu.device.features().contains(wgpu::Features::FLOAT32_BLENDABLE) {
        wgpu::TextureFormat::Rgba32Float
    } else {
        wgpu::TextureFormat::Rgba16Float
    }
}

/// The multisampled attachments of a frame drawn with more than one sample per pixel: object
/// indices and depth per sample, and colour attachments resolved into the frame's target:
/// per target format for the hardware resolve, in the offscreen format (kept, for the shader
/// to read) for the display-filter resolve.
pub(super) struct SampleTargets {
    pub(super) ids: wgpu::Texture,
    pub(super) depth: wgpu::Texture,
    pub(super) ids_bind: wgpu::BindGroup,
    /// Keyed by format and whether the display-filter resolve reads it.
    pub(super) colour: HashMap<(wgpu::TextureFormat, bool), wgpu::Texture>,
    /// The display-filter resolve's per-pixel shared object index (made on first use).
    pub(super) shared_ids: Option<wgpu::Texture>,
}

/// The per-size targets: object indices (one per pixel, at its centre), depth, the offscreen
/// colour target, and with `samples` > 1 the multisampled attachments.
pub struct Targets {
    pub size: (u32, u32),
    pub samples: u32,
    pub ids: wgpu::Texture,
    pub depth: wgpu::Texture,
    pub colour: wgpu::Texture,
    pub(super) ids_bind: wgpu::BindGroup,
    pub(super) multi: Option<SampleTargets>,
    /// The translucent draws' targets (made on first use).
    pub(super) translucent: Option<TranslucentTargets>,
}

pub(super) fn target_texture(
    gpu: &Gpu,
    label: &str,
    size: (u32, u32),
    samples: u32,
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> wgpu::Texture {
    gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d { width: size.0, height: size.1, depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: samples,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage,
        view_formats: &[],
    })
}

/// A bind group of `texture`'s whole view alone, at `binding` of `layout`.
pub(super) fn texture_bind(
    gpu: &Gpu,
    label: &str,
    texture: &wgpu::Texture,
    layout: &wgpu::BindGroupLayout,
    binding: u32,
) -> wgpu::BindGroup {
    let view = texture.create_view(&Default::default());
    gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout,
        entries: &[wgpu::BindGroupEntry {
            binding,
            resource: wgpu::BindingResource::TextureView(&view),
        }],
    })
}

impl Targets {
    /// Targets of `size` for frames of `samples` per pixel (1, or a count
    /// [`crate::multisample::choose`] found supported).
    pub fn new(
        gpu: &Gpu,
        pipes: &FramePipelines,
        size: (u32, u32),
        samples: u32,
    ) -> Result<Targets, PlayError> {
        let limit = gpu.limits.max_texture_dimension_2d;
        if size.0 == 0 || size.1 == 0 || size.0 > limit || size.1 > limit {
            return Err(PlayError::TargetSize { width: size.0, height: size.1, limit });
        }
        let attach = wgpu::TextureUsages::RENDER_ATTACHMENT;
        let ids = target_texture(
            gpu,
            "object ids",
            size,
            1,
            ID_FORMAT,
            attach | wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_SRC,
        );
        let depth = target_texture(gpu, "depth", size, 1, DEPTH_FORMAT, attach);
        let colour = target_texture(
            gpu,
            "frame",
            size,
            1,
            offscreen_format(gpu),
            attach | wgpu::TextureUsages::COPY_SRC,
        );
        let bind = |texture: &wgpu::Texture, layout, binding| {
            texture_bind(gpu, "object ids", texture, layout, binding)
        };
        let ids_bind = bind(&ids, &pipes.ids_layout, 0);
        let multi = (samples > 1).then(|| {
            let ids = target_texture(
                gpu,
                "object ids per sample",
                size,
                samples,
                ID_FORMAT,
                attach | wgpu::TextureUsages::TEXTURE_BINDING,
            );
            let depth =
                target_texture(gpu, "depth per sample", size, samples, DEPTH_FORMAT, attach);
            let ids_bind = bind(&ids, &pipes.ids_ms_layout, 1);
            SampleTargets { ids, depth, ids_bind, colour: HashMap::new(), shared_ids: None }
        });
        Ok(Targets { size, samples, ids, depth, colour, ids_bind, multi, translucent: None })
    }
}

/// What the translucent draws draw into, per size and samples per pixel: the nearest
/// translucent surface's object index per sample (and the bind group the layers test it
/// with), and per format the translucent colour and opacity with the composite's bind group.
pub(super) struct TranslucentTargets {
    pub(super) ids: wgpu::Texture,
    pub(super) ids_bind: wgpu::BindGroup,
    pub(super) colour: HashMap<wgpu::TextureFormat, (wgpu::Texture, wgpu::BindGroup)>,
}

impl Targets {
    /// Makes the translucent draws' targets in `format` where missing (after
    /// [`FramePipelines::translucent_pipelines`]).
    pub(super) fn translucent_targets(
        &mut self,
        gpu: &Gpu,
        pipes: &FramePipelines,
        format: wgpu::TextureFormat,
    ) {
        let (size, samples) = (self.size, self.samples);
        let attach = wgpu::TextureUsages::RENDER_ATTACHMENT;
        let bind = |texture: &wgpu::Texture, layout, binding| {
            texture_bind(gpu, "frame translucent", texture, layout, binding)
        };
        let multisampled = samples > 1;
        let t = self.translucent.get_or_insert_with(|| {
            let ids = target_texture(
                gpu,
                "translucent object ids",
                size,
                samples,
                ID_FORMAT,
                attach | wgpu::TextureUsages::TEXTURE_BINDING,
            );
            let layout = if multisampled { &pipes.ids_ms_layout } else { &pipes.ids_layout };
            let ids_bind = bind(&ids, layout, multisampled as u32);
            TranslucentTargets { ids, ids_bind, colour: HashMap::new() }
        });
        t.colour.entry(format).or_insert_with(|| {
            let texture = target_texture(
                gpu,
                "translucent colour and opacity",
                size,
                samples,
                format,
                attach | wgpu::TextureUsages::TEXTURE_BINDING,
            );
            let b =
                bind(&texture, pipes.translucent.composite_layout(samples), multisampled as u32);
            (texture, b)
        });
    }
}
