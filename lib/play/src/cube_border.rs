//! The compute pass that writes a cube map's atlas images, borders included, from its
//! levels (`cube_border.wgsl`), reading the sources cube_atlas.rs lists: the GPU rebuild's
//! twin of [`CubeAtlas::fill_borders`].

use bytemuck::{Pod, Zeroable};
use wgpu::util::DeviceExt;

use crate::cube_atlas::{level_side, CubeAtlas};
use crate::gpu::Gpu;
use crate::mip::storage_name;

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct BorderParams {
    origin: [u32; 2],
    n: u32,
    map_offset: u32,
}

/// The compute pass that writes a cube map's atlas images from its levels (`cube_border.wgsl`).
pub struct BorderPass {
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::ComputePipeline,
}

fn entry(binding: u32, ty: wgpu::BindingType) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry { binding, visibility: wgpu::ShaderStages::COMPUTE, ty, count: None }
}

fn buffer(ty: wgpu::BufferBindingType) -> wgpu::BindingType {
    wgpu::BindingType::Buffer { ty, has_dynamic_offset: false, min_binding_size: None }
}

impl BorderPass {
    pub fn new(gpu: &Gpu) -> BorderPass {
        let d = &gpu.device;
        let source =
            include_str!("cube_border.wgsl").replace("CUBE_FORMAT", storage_name(gpu.cube_format));
        let module = d.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("cube_border.wgsl"),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
        let entries = [
            entry(0, buffer(wgpu::BufferBindingType::Uniform)),
            entry(
                1,
                wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Float { filterable: false },
                    view_dimension: wgpu::TextureViewDimension::D2Array,
                    multisampled: false,
                },
            ),
            entry(
                2,
                wgpu::BindingType::StorageTexture {
                    access: wgpu::StorageTextureAccess::WriteOnly,
                    format: gpu.cube_format,
                    view_dimension: wgpu::TextureViewDimension::D2Array,
                },
            ),
            entry(3, buffer(wgpu::BufferBindingType::Storage { read_only: true })),
        ];
        let layout = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("cube border"),
            entries: &entries,
        });
        let pl = d.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("cube border"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = d.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("cube border"),
            layout: Some(&pl),
            module: &module,
            entry_point: Some("cube_border"),
            compilation_options: Default::default(),
            cache: None,
        });
        BorderPass { layout, pipeline }
    }

    /// Records the atlas images `atlas` (a view of every face) of `atlas_layout` from the
    /// cube map `levels` (a texture of six layers whose level m holds level m's texels at
    /// its top left): one dispatch per level.
    pub fn record(
        &self,
        gpu: &Gpu,
        (levels, atlas_layout): (&wgpu::Texture, &CubeAtlas),
        atlas: &wgpu::TextureView,
        encoder: &mut wgpu::CommandEncoder,
    ) {
        let map = gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("cube border map"),
            contents: bytemuck::cast_slice(&atlas_layout.border_map()),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let mut map_offset = 0;
        for m in 0..atlas_layout.levels {
            let n = level_side(atlas_layout.size, m);
            let (ox, oy) = atlas_layout.origin(m);
            let params = BorderParams { origin: [ox, oy], n, map_offset };
            map_offset += 6 * (4 * n + 4);
            let ubuf = gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("cube border params"),
                contents: bytemuck::bytes_of(&params),
                usage: wgpu::BufferUsages::UNIFORM,
            });
            let level = levels.create_view(&wgpu::TextureViewDescriptor {
                dimension: Some(wgpu::TextureViewDimension::D2Array),
                base_mip_level: m,
                mip_level_count: Some(1),
                ..Default::default()
            });
            let bg = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("cube border"),
                layout: &self.layout,
                entries: &[
                    wgpu::BindGroupEntry { binding: 0, resource: ubuf.as_entire_binding() },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: wgpu::BindingResource::TextureView(&level),
                    },
                    wgpu::BindGroupEntry {
                        binding: 2,
                        resource: wgpu::BindingResource::TextureView(atlas),
                    },
                    wgpu::BindGroupEntry { binding: 3, resource: map.as_entire_binding() },
                ],
            });
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("cube border"),
                timestamp_writes: None,
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &bg, &[]);
            pass.dispatch_workgroups((n + 2).div_ceil(8), (n + 2).div_ceil(8), 6);
        }
    }
}
