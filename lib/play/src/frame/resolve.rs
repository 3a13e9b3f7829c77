//! The display-filter resolve of multisampled frames (`resolve.wgsl`): instead of the
//! hardware's box average of each pixel's own samples, every output pixel mixes the objects
//! of its 3×3 neighbourhood's samples by their coverage under the ray-traced set's display
//! filter (the truncated Gaussian of RAYSET.md section 4, recorded by pis-pack in the file's
//! provenance settings, SPEC.md 6.6), each object at its radiance at the pixel. Silhouette
//! pixels then mix the surfaces as the gold standard's filtered pixels do, up to R pixels
//! from the edge; a pixel whose neighbourhood is one object keeps its single-sample value.
//!
//! Two full-screen passes: the first writes each pixel's shared object index (that of all
//! its samples, or "mixed"), from which the second tells the pixels whose neighbourhood is
//! one object's (9 reads) and returns their own samples' mean; only the others group and
//! weigh the neighbourhood's 36 samples.

use std::collections::HashMap;

use bytemuck::{Pod, Zeroable};
use pis_format::DisplayFilter;
use wgpu::util::DeviceExt;

use super::draw::ID_FORMAT;
use crate::gpu::Gpu;

/// The WGSL source.
pub const SHADER: &str = include_str!("resolve.wgsl");

/// The sample positions the resolve weighs samples at, in pixels from the pixel's top-left
/// corner, y down: the standard 4× pattern (WebGPU; Vulkan's standard sample locations).
pub const SAMPLE_POSITIONS: [[f32; 2]; 4] =
    [[0.375, 0.125], [0.875, 0.375], [0.125, 0.625], [0.625, 0.875]];

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
        Kernel {
            inv_two_sigma2: 1.0 / (2.0 * f.sigma_px * f.sigma_px),
            radius2: f.radius_px * f.radius_px,
            _pad: [0.0; 2],
        }
    }
}

/// The format of the per-pixel shared object index the first pass writes.
pub const SHARED_ID_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Uint;

/// The resolve pipelines: the first pass (each pixel's shared object index) and the resolve
/// per target format.
pub struct ResolvePipelines {
    module: wgpu::ShaderModule,
    bind_layout: wgpu::BindGroupLayout,
    shared_layout: wgpu::BindGroupLayout,
    layout: wgpu::PipelineLayout,
    classify: wgpu::RenderPipeline,
    pipelines: HashMap<wgpu::TextureFormat, wgpu::RenderPipeline>,
}

fn full_screen(
    d: &wgpu::Device,
    module: &wgpu::ShaderModule,
    layout: &wgpu::PipelineLayout,
    entry_point: &str,
    format: wgpu::TextureFormat,
) -> wgpu::RenderPipeline {
    d.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(entry_point),
        layout: Some(layout),
        vertex: wgpu::VertexState {
            module,
            entry_point: Some("vs_full"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        primitive: wgpu::PrimitiveState {
            topology: wgpu::PrimitiveTopology::TriangleList,
            cull_mode: None,
            ..Default::default()
        },
        depth_stencil: None,
        multisample: wgpu::MultisampleState::default(),
        fragment: Some(wgpu::FragmentState {
            module,
            entry_point: Some(entry_point),
            compilation_options: Default::default(),
            targets: &[Some(wgpu::ColorTargetState {
                format,
                blend: None,
                write_mask: wgpu::ColorWrites::ALL,
            })],
        }),
        multiview_mask: None,
        cache: None,
    })
}

fn full_screen_pass<'e>(
    encoder: &'e mut wgpu::CommandEncoder,
    label: &str,
    target: &wgpu::TextureView,
) -> wgpu::RenderPass<'e> {
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view: target,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                store: wgpu::StoreOp::Store,
            },
        })],
        depth_stencil_attachment: None,
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    })
}

fn entry(binding: u32, ty: wgpu::BindingType) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty,
        count: None,
    }
}

fn multisampled(sample_type: wgpu::TextureSampleType) -> wgpu::BindingType {
    wgpu::BindingType::Texture {
        sample_type,
        view_dimension: wgpu::TextureViewDimension::D2,
        multisampled: true,
    }
}

impl ResolvePipelines {
    pub fn new(gpu: &Gpu) -> ResolvePipelines {
        let d = &gpu.device;
        let module = d.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("resolve.wgsl"),
            source: wgpu::ShaderSource::Wgsl(SHADER.into()),
        });
        let bind_layout = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("resolve"),
            entries: &[
                entry(0, multisampled(wgpu::TextureSampleType::Float { filterable: false })),
                entry(1, multisampled(wgpu::TextureSampleType::Uint)),
                entry(
                    2,
                    wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                ),
            ],
        });
        let shared_layout = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("shared object indices"),
            entries: &[entry(
                0,
                wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Uint,
                    view_dimension: wgpu::TextureViewDimension::D2,
                    multisampled: false,
                },
            )],
        });
        let classify_layout = d.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("shared object indices"),
            bind_group_layouts: &[Some(&bind_layout)],
            immediate_size: 0,
        });
        let layout = d.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("resolve"),
            bind_group_layouts: &[Some(&bind_layout), Some(&shared_layout)],
            immediate_size: 0,
        });
        let classify = full_screen(d, &module, &classify_layout, "fs_classify", SHARED_ID_FORMAT);
        ResolvePipelines {
            module,
            bind_layout,
            shared_layout,
            layout,
            classify,
            pipelines: HashMap::new(),
        }
    }

    /// The pipeline writing targets of `format` (compiled on first use).
    pub fn pipeline(&mut self, gpu: &Gpu, format: wgpu::TextureFormat) -> &wgpu::RenderPipeline {
        let (module, layout) = (&self.module, &self.layout);
        self.pipelines
            .entry(format)
            .or_insert_with(|| full_screen(&gpu.device, module, layout, "fs_resolve", format))
    }

    /// Records the resolve of `colour` (multisampled, float) and `ids` (multisampled object
    /// indices, [`ID_FORMAT`], as many samples) into `target` (of format `format`, same
    /// size): every pixel written. `shared` (single-sample, [`SHARED_ID_FORMAT`], same size,
    /// render attachment and texture binding) holds each pixel's shared object index
    /// between the two passes.
    pub fn encode(
        &mut self,
        gpu: &Gpu,
        filter: DisplayFilter,
        (colour, ids, shared): (&wgpu::Texture, &wgpu::Texture, &wgpu::Texture),
        (target, format): (&wgpu::TextureView, wgpu::TextureFormat),
        encoder: &mut wgpu::CommandEncoder,
    ) {
        debug_assert_eq!(ids.format(), ID_FORMAT);
        self.pipeline(gpu, format);
        let d = &gpu.device;
        let kernel = d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("resolve kernel"),
            contents: bytemuck::bytes_of(&Kernel::of(filter)),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let (cv, iv) =
            (colour.create_view(&Default::default()), ids.create_view(&Default::default()));
        let bind = d.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("resolve"),
            layout: &self.bind_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(&cv),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(&iv),
                },
                wgpu::BindGroupEntry { binding: 2, resource: kernel.as_entire_binding() },
            ],
        });
        let shared_view = shared.create_view(&Default::default());
        {
            let mut pass = full_screen_pass(encoder, "shared object indices", &shared_view);
            pass.set_pipeline(&self.classify);
            pass.set_bind_group(0, &bind, &[]);
            pass.draw(0..3, 0..1);
        }
        let shared_bind = d.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("shared object indices"),
            layout: &self.shared_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::TextureView(&shared_view),
            }],
        });
        let mut pass = full_screen_pass(encoder, "display-filter resolve", target);
        pass.set_pipeline(&self.pipelines[&format]);
        pass.set_bind_group(0, &bind, &[]);
        pass.set_bind_group(1, &shared_bind, &[]);
        pass.draw(0..3, 0..1);
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_shader_weighs_the_documented_sample_positions() {
        let src = super::SHADER;
        for [x, y] in super::SAMPLE_POSITIONS {
            assert!(
                src.contains(&format!("vec2<f32>({x:?}, {y:?})")),
                "resolve.wgsl lacks sample position ({x}, {y})"
            );
        }
    }
}
