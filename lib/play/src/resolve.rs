//! The display-filter resolve of multisampled frames (`resolve.wgsl`): instead of the
//! hardware's box average of each pixel's own samples, every output pixel mixes the objects
//! of its 3×3 neighbourhood's samples by their coverage under the ray-traced set's display
//! filter (the truncated Gaussian of RAYSET.md section 4, recorded by pis-pack in the file's
//! provenance settings, SPEC.md 6.6), each object at its radiance at the pixel. Silhouette
//! pixels then mix the surfaces as the gold standard's filtered pixels do, up to R pixels
//! from the edge; a pixel whose neighbourhood is one object keeps its single-sample value.

use std::collections::HashMap;

use bytemuck::{Pod, Zeroable};
use pis_format::DisplayFilter;
use wgpu::util::DeviceExt;

use crate::frame::ID_FORMAT;
use crate::gpu::Gpu;

/// The WGSL source.
pub const SHADER: &str = include_str!("resolve.wgsl");

/// The sample positions the resolve weighs samples at, in pixels from the pixel's top-left
/// corner, y down: the standard 4× pattern (WebGPU; Vulkan's standard sample locations).
pub const SAMPLE_POSITIONS: [[f32; 2]; 4] = [[0.375, 0.125], [0.875, 0.375], [0.125, 0.625], [0.625, 0.875]];

/// `Kernel` of `resolve.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct Kernel {
    inv_two_sigma2: f32,
    radius2: f32,
    _pad: [f32; 2],
}

impl Kernel {
    fn of(f: DisplayFilter) -> Kernel {
        Kernel { inv_two_sigma2: 1.0 / (2.0 * f.sigma_px * f.sigma_px), radius2: f.radius_px * f.radius_px, _pad: [0.0; 2] }
    }
}

/// The resolve pipelines: one per target format.
pub struct ResolvePipelines {
    module: wgpu::ShaderModule,
    bind_layout: wgpu::BindGroupLayout,
    layout: wgpu::PipelineLayout,
    pipelines: HashMap<wgpu::TextureFormat, wgpu::RenderPipeline>,
}

fn entry(binding: u32, ty: wgpu::BindingType) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry { binding, visibility: wgpu::ShaderStages::FRAGMENT, ty, count: None }
}

fn multisampled(sample_type: wgpu::TextureSampleType) -> wgpu::BindingType {
    wgpu::BindingType::Texture { sample_type, view_dimension: wgpu::TextureViewDimension::D2, multisampled: true }
}

impl ResolvePipelines {
    pub fn new(gpu: &Gpu) -> ResolvePipelines {
        let d = &gpu.device;
        let module = d.create_shader_module(wgpu::ShaderModuleDescriptor { label: Some("resolve.wgsl"), source: wgpu::ShaderSource::Wgsl(SHADER.into()) });
        let bind_layout = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("resolve"),
            entries: &[
                entry(0, multisampled(wgpu::TextureSampleType::Float { filterable: false })),
                entry(1, multisampled(wgpu::TextureSampleType::Uint)),
                entry(2, wgpu::BindingType::Buffer { ty: wgpu::BufferBindingType::Uniform, has_dynamic_offset: false, min_binding_size: None }),
            ],
        });
        let layout = d.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor { label: Some("resolve"), bind_group_layouts: &[Some(&bind_layout)], immediate_size: 0 });
        ResolvePipelines { module, bind_layout, layout, pipelines: HashMap::new() }
    }

    /// The pipeline writing targets of `format` (compiled on first use).
    pub fn pipeline(&mut self, gpu: &Gpu, format: wgpu::TextureFormat) -> &wgpu::RenderPipeline {
        let (module, layout) = (&self.module, &self.layout);
        self.pipelines.entry(format).or_insert_with(|| {
            gpu.device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("display-filter resolve"),
                layout: Some(layout),
                vertex: wgpu::VertexState { module, entry_point: Some("vs_full"), compilation_options: Default::default(), buffers: &[] },
                primitive: wgpu::PrimitiveState { topology: wgpu::PrimitiveTopology::TriangleList, cull_mode: None, ..Default::default() },
                depth_stencil: None,
                multisample: wgpu::MultisampleState::default(),
                fragment: Some(wgpu::FragmentState {
                    module,
                    entry_point: Some("fs_resolve"),
                    compilation_options: Default::default(),
                    targets: &[Some(wgpu::ColorTargetState { format, blend: None, write_mask: wgpu::ColorWrites::ALL })],
                }),
                multiview_mask: None,
                cache: None,
            })
        })
    }

    /// Records the resolve of `colour` (multisampled, float) and `ids` (multisampled object
    /// indices, [`ID_FORMAT`], as many samples) into `target` (format `format`, same size):
    /// every pixel written.
    #[allow(clippy::too_many_arguments)]
    pub fn encode(&mut self, gpu: &Gpu, filter: DisplayFilter, colour: &wgpu::Texture, ids: &wgpu::Texture, target: &wgpu::TextureView, format: wgpu::TextureFormat, encoder: &mut wgpu::CommandEncoder) {
        debug_assert_eq!(ids.format(), ID_FORMAT);
        self.pipeline(gpu, format);
        let d = &gpu.device;
        let kernel = d.create_buffer_init(&wgpu::util::BufferInitDescriptor { label: Some("resolve kernel"), contents: bytemuck::bytes_of(&Kernel::of(filter)), usage: wgpu::BufferUsages::UNIFORM });
        let (cv, iv) = (colour.create_view(&Default::default()), ids.create_view(&Default::default()));
        let bind = d.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("resolve"),
            layout: &self.bind_layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(&cv) },
                wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(&iv) },
                wgpu::BindGroupEntry { binding: 2, resource: kernel.as_entire_binding() },
            ],
        });
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("display-filter resolve"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: target,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations { load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT), store: wgpu::StoreOp::Store },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.pipelines[&format]);
        pass.set_bind_group(0, &bind, &[]);
        pass.draw(0..3, 0..1);
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_shader_weighs_the_documented_sample_positions() {
        let src = super::SHADER;
        for [x, y] in super::SAMPLE_POSITIONS {
            assert!(src.contains(&format!("vec2<f32>({x:?}, {y:?})")), "resolve.wgsl lacks sample position ({x}, {y})");
        }
    }
}
