//! Translucent objects (SPEC.md 9): an object whose surface layer carries its opacity is
//! left out of the id pass and drawn after the opaque surfaces. Its own id pass keeps, per
//! sample, the nearest translucent surface in front of the opaque ones; its layers then add
//! their premultiplied colour and, from the layer that carries it, weight × opacity into a
//! target of their own; `composite.wgsl` lays that target over the frame ("over": colour +
//! (1 − opacity) · frame). Here: the pipelines of those draws and the composite, and the
//! targets they draw into.

use std::collections::HashMap;

use super::draw::ID_FORMAT;
use super::pipelines::{additive_pipeline, FramePipelines, POSITION_LAYOUT, UV_LAYOUT};
use super::targets::{target_texture, texture_bind, Targets};
use crate::gpu::Gpu;

/// The WGSL source of the composite.
pub const COMPOSITE: &str = include_str!("composite.wgsl");

/// The translucent draws' pipelines, compiled on first use.
#[derive(Default)]
pub struct TranslucentPipelines {
    /// The composite's module and its bind group layouts (one sample per pixel, several).
    composite: Option<(wgpu::ShaderModule, wgpu::BindGroupLayout, wgpu::BindGroupLayout)>,
    /// Per target format and samples per pixel: the translucent layers.
    pub(super) layers: HashMap<(wgpu::TextureFormat, u32), wgpu::RenderPipeline>,
    /// Per target format and samples per pixel: the composite.
    pub(super) composites: HashMap<(wgpu::TextureFormat, u32), wgpu::RenderPipeline>,
}

/// Colour and opacity both add (over layers and parameter samples).
fn accumulate_target(format: wgpu::TextureFormat) -> wgpu::ColorTargetState {
    let add = wgpu::BlendComponent {
        src_factor: wgpu::BlendFactor::One,
        dst_factor: wgpu::BlendFactor::One,
        operation: wgpu::BlendOperation::Add,
    };
    wgpu::ColorTargetState {
        format,
        blend: Some(wgpu::BlendState { color: add, alpha: add }),
        write_mask: wgpu::ColorWrites::ALL,
    }
}

/// Premultiplied "over": the source plus the destination times one minus source alpha.
fn over_target(format: wgpu::TextureFormat) -> wgpu::ColorTargetState {
    let over = wgpu::BlendComponent {
        src_factor: wgpu::BlendFactor::One,
        dst_factor: wgpu::BlendFactor::OneMinusSrcAlpha,
        operation: wgpu::BlendOperation::Add,
    };
    wgpu::ColorTargetState {
        format,
        blend: Some(wgpu::BlendState { color: over, alpha: over }),
        write_mask: wgpu::ColorWrites::ALL,
    }
}

/// The composite's bind group layout for one sample per pixel or several.
fn layer_layout(gpu: &Gpu, multisampled: bool) -> wgpu::BindGroupLayout {
    gpu.device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("frame translucent layer"),
        entries: &[wgpu::BindGroupLayoutEntry {
            binding: multisampled as u32,
            visibility: wgpu::ShaderStages::FRAGMENT,
            ty: wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Float { filterable: false },
                view_dimension: wgpu::TextureViewDimension::D2,
                multisampled,
            },
            count: None,
        }],
    })
}

impl FramePipelines {
    /// Compiles the translucent layers' pipeline and the composite for a target format and
    /// `samples` per pixel, where not compiled yet.
    pub fn translucent_pipelines(&mut self, gpu: &Gpu, format: wgpu::TextureFormat, samples: u32) {
        let key = (format, samples);
        let (layout, entry_point) = if samples > 1 {
            (&self.layer_ms_layout, "fs_layer_ms")
        } else {
            (&self.layer_layout, "fs_layer")
        };
        let module = &self.module;
        self.translucent.layers.entry(key).or_insert_with(|| {
            additive_pipeline(
                gpu,
                "frame translucent layers",
                layout,
                module,
                ("vs_main", &[Some(POSITION_LAYOUT), Some(UV_LAYOUT)]),
                entry_point,
                (accumulate_target(format), samples),
            )
        });
        let t = &mut self.translucent;
        let (module, single, multi) = t.composite.get_or_insert_with(|| {
            let module = gpu.device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("frame/composite.wgsl"),
                source: wgpu::ShaderSource::Wgsl(COMPOSITE.into()),
            });
            (module, layer_layout(gpu, false), layer_layout(gpu, true))
        });
        let (bind_layout, entry_point) =
            if samples > 1 { (&*multi, "fs_composite_ms") } else { (&*single, "fs_composite") };
        t.composites.entry(key).or_insert_with(|| {
            let layout = gpu.device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("frame composite"),
                bind_group_layouts: &[Some(bind_layout)],
                immediate_size: 0,
            });
            gpu.device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("frame composite"),
                layout: Some(&layout),
                vertex: wgpu::VertexState {
                    module,
                    entry_point: Some("vs_full"),
                    compilation_options: Default::default(),
                    buffers: &[],
                },
                primitive: Default::default(),
                depth_stencil: None,
                multisample: wgpu::MultisampleState {
                    count: samples,
                    mask: !0,
                    alpha_to_coverage_enabled: false,
                },
                fragment: Some(wgpu::FragmentState {
                    module,
                    entry_point: Some(entry_point),
                    compilation_options: Default::default(),
                    targets: &[Some(over_target(format))],
                }),
                multiview_mask: None,
                cache: None,
            })
        });
    }

    /// The composite's bind group layout for `samples` per pixel (after
    /// [`FramePipelines::translucent_pipelines`]).
    fn composite_layout(&self, samples: u32) -> &wgpu::BindGroupLayout {
        let (_, single, multi) =
            self.translucent.composite.as_ref().expect("translucent pipelines compiled");
        if samples > 1 {
            multi
        } else {
            single
        }
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
            let b = bind(&texture, pipes.composite_layout(samples), multisampled as u32);
            (texture, b)
        });
    }
}

/// Records the composite: `layer` (the translucent colour and opacity of the frame's
/// samples) laid over `attachment` ("over"), resolved into `resolve_target` where given.
pub(super) fn composite(
    pipeline: &wgpu::RenderPipeline,
    layer: &wgpu::BindGroup,
    (attachment, resolve_target, store): (
        &wgpu::TextureView,
        Option<&wgpu::TextureView>,
        wgpu::StoreOp,
    ),
    encoder: &mut wgpu::CommandEncoder,
) {
    let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("translucent composite"),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view: attachment,
            depth_slice: None,
            resolve_target,
            ops: wgpu::Operations { load: wgpu::LoadOp::Load, store },
        })],
        depth_stencil_attachment: None,
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    });
    pass.set_pipeline(pipeline);
    pass.set_bind_group(0, layer, &[]);
    pass.draw(0..3, 0..1);
}
