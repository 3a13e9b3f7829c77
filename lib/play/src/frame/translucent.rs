//! Translucent objects (SPEC.md 9): an object whose surface layer carries its opacity is
//! left out of the id pass and drawn after the opaque surfaces. Its own id pass keeps, per
//! sample, the nearest translucent surface in front of the opaque ones; its layers then add
//! their premultiplied colour and, from the layer that carries it, weight × opacity into a
//! target of their own; `composite.wgsl` lays that target over the frame ("over": colour +
//! (1 − opacity) · frame). Here: the pipelines of those draws and the composite, and the
//! targets they draw into.

use std::collections::HashMap;

use super::additive::{additive_pipeline, POSITION_LAYOUT, UV_LAYOUT};
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

impl TranslucentPipelines {
    /// Compiles the translucent layers' pipeline (`module`'s layer entry point, through the
    /// frame's layer pipeline `layout` for `samples` per pixel) and the composite for a
    /// target format and `samples` per pixel, where not compiled yet.
    pub(super) fn compile(
        &mut self,
        gpu: &Gpu,
        (module, layout): (&wgpu::ShaderModule, &wgpu::PipelineLayout),
        format: wgpu::TextureFormat,
        samples: u32,
    ) {
        let key = (format, samples);
        let entry_point = if samples > 1 { "fs_layer_ms" } else { "fs_layer" };
        self.layers.entry(key).or_insert_with(|| {
            additive_pipeline(
                gpu,
                "frame translucent layers",
                layout,
                module,
                ("vs_main", &[Some(POSITION_LAYOUT), Some(UV_LAYOUT)]),
                (entry_point, &[]),
                (accumulate_target(format), samples),
            )
        });
        let (module, single, multi) = self.composite.get_or_insert_with(|| {
            let module = gpu.device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("frame/composite.wgsl"),
                source: wgpu::ShaderSource::Wgsl(COMPOSITE.into()),
            });
            (module, layer_layout(gpu, false), layer_layout(gpu, true))
        });
        let (bind_layout, entry_point) =
            if samples > 1 { (&*multi, "fs_composite_ms") } else { (&*single, "fs_composite") };
        self.composites.entry(key).or_insert_with(|| {
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
    /// [`TranslucentPipelines::compile`]).
    pub(super) fn composite_layout(&self, samples: u32) -> &wgpu::BindGroupLayout {
        let (_, single, multi) = self.composite.as_ref().expect("translucent pipelines compiled");
        if samples > 1 {
            multi
        } else {
            single
        }
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
