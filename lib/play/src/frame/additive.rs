//! The additive pass's pipeline pieces, shared by the frame's layers, reflection and lens
//! terms (`pipelines.rs`) and the translucent layers (`translucent.rs`): the vertex buffers,
//! the depth test against the id pass, and the pipeline itself.

use crate::gpu::Gpu;
use crate::textured::DEPTH_FORMAT;
pub(super) use crate::textured::{POSITION_LAYOUT, UV_LAYOUT};

/// `count` samples per pixel, every sample written.
pub(super) fn multisample(count: u32) -> wgpu::MultisampleState {
    wgpu::MultisampleState { count, mask: !0, alpha_to_coverage_enabled: false }
}

/// An additive pipeline of the frame's layer pass: `module`'s vertex entry point with its
/// vertex buffers, fragment entry point `fragment` with its overridable constants, for a colour target (its format and
/// blending: `pipelines.rs`'s additive target, or a translucent object's) and samples per pixel;
/// triangles unculled, tested against the id pass's depth without writing it.
pub(super) fn additive_pipeline(
    gpu: &Gpu,
    label: &str,
    layout: &wgpu::PipelineLayout,
    module: &wgpu::ShaderModule,
    vertex: (&str, &[Option<wgpu::VertexBufferLayout>]),
    fragment: (&str, &[(&str, f64)]),
    (target, samples): (wgpu::ColorTargetState, u32),
) -> wgpu::RenderPipeline {
    gpu.device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(label),
        layout: Some(layout),
        vertex: wgpu::VertexState {
            module,
            entry_point: Some(vertex.0),
            compilation_options: Default::default(),
            buffers: vertex.1,
        },
        primitive: wgpu::PrimitiveState {
            topology: wgpu::PrimitiveTopology::TriangleList,
            cull_mode: None,
            ..Default::default()
        },
        depth_stencil: Some(additive_depth()),
        multisample: multisample(samples),
        fragment: Some(wgpu::FragmentState {
            module,
            entry_point: Some(fragment.0),
            compilation_options: wgpu::PipelineCompilationOptions {
                constants: fragment.1,
                ..Default::default()
            },
            targets: &[Some(target)],
        }),
        multiview_mask: None,
        cache: None,
    })
}

/// The additive pass's depth state: tested against the id pass's depth (equal passes), not
/// written.
fn additive_depth() -> wgpu::DepthStencilState {
    wgpu::DepthStencilState {
        format: DEPTH_FORMAT,
        depth_write_enabled: Some(false),
        depth_compare: Some(wgpu::CompareFunction::LessEqual),
        stencil: Default::default(),
        bias: Default::default(),
    }
}
