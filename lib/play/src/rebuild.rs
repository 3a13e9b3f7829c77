//! Surface textures rebuilt from their level images on the GPU (thesis 4.7, SPEC.md 8.4): the
//! workers only decode codestreams; each decoded level image goes up once as a storage buffer
//! of its own (compact: its channels only, kept while the level-image cache keeps the image),
//! and a texture a frame needs is its level images stacked by buffer copies, summed, inverse
//! gamma applied and widened to RGBA by one compute pass (`rebuild.wgsl`) into the finest
//! level of the padded layout, its MIP chain decimated by `mip.wgsl`. decode.rs's `assemble`
//! is the reference it is held to (tests/rebuild_vs_cpu.rs) and the path where the GPU
//! rebuild does not apply (a resolution reduction, a stack beyond the device's limits).

use bytemuck::{Pod, Zeroable};
use wgpu::util::DeviceExt;

use crate::gpu::Gpu;
use crate::mip::{storage_name, MipBuilder};
use crate::textured::{allocated_size, ObjectTexture};

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct Params {
    used: [u32; 2],
    alloc: [u32; 2],
    channels: u32,
    levels: u32,
    plane: u32,
    mode: u32,
    gamma: f32,
    _pad: [u32; 3],
}

/// What a texture is rebuilt from: its level images on the GPU (top first, each at least
/// `width × height × channels` values), its channels (1 to 4) and its layer's gamma.
pub struct LevelStack<'a> {
    pub levels: &'a [&'a wgpu::Buffer],
    pub channels: u32,
    pub gamma: f32,
}

/// The rebuilding pipeline for the GPU's texture format.
pub struct LevelRebuild {
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::ComputePipeline,
}

fn entry(binding: u32, ty: wgpu::BindingType) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry { binding, visibility: wgpu::ShaderStages::COMPUTE, ty, count: None }
}

/// The shader's gamma mode: the identity, pis-codec's `pow_11_5` for the default gamma, or
/// the general power.
fn gamma_mode(gamma: f32) -> u32 {
    if gamma == 1.0 {
        0
    } else if gamma == pis_codec::gamma::DEFAULT_GAMMA {
        1
    } else {
        2
    }
}

/// Uploads a decoded level image as a storage buffer the rebuild reads.
pub fn level_buffer(gpu: &Gpu, values: &[f32]) -> wgpu::Buffer {
    gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("level image"),
        contents: bytemuck::cast_slice(values),
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
    })
}

/// Whether a `width × height` texture of `channels` summed from `levels` level images fits
/// the device's storage buffers (else it is rebuilt on the workers).
pub fn fits(gpu: &Gpu, (width, height, channels): (u32, u32, u32), levels: usize) -> bool {
    let bytes = width as u64 * height as u64 * channels as u64 * 4 * levels as u64;
    levels > 0
        && bytes <= gpu.limits.max_storage_buffer_binding_size
        && bytes <= gpu.limits.max_buffer_size
}

impl LevelRebuild {
    pub fn new(gpu: &Gpu) -> LevelRebuild {
        let d = &gpu.device;
        let source =
            include_str!("rebuild.wgsl").replace("FORMAT", storage_name(gpu.texture_format));
        let module = d.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("rebuild.wgsl"),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
        let uniform = wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        };
        let stack = wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only: true },
            has_dynamic_offset: false,
            min_binding_size: None,
        };
        let storage = wgpu::BindingType::StorageTexture {
            access: wgpu::StorageTextureAccess::WriteOnly,
            format: gpu.texture_format,
            view_dimension: wgpu::TextureViewDimension::D2,
        };
        let layout = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("rebuild"),
            entries: &[entry(0, uniform), entry(1, stack), entry(2, storage)],
        });
        let pl = d.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("rebuild"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = d.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("rebuild"),
            layout: Some(&pl),
            module: &module,
            entry_point: Some("rebuild"),
            compilation_options: Default::default(),
            cache: None,
        });
        LevelRebuild { layout, pipeline }
    }

    /// Records the rebuild of `texture` (made by [`MipBuilder::texture`] at full resolution)
    /// from `stack`: the level images copied into one buffer (one image is read where it
    /// lies), the pass that writes the finest level, and the decimated MIP chain.
    pub fn record(
        &self,
        gpu: &Gpu,
        (texture, stack): (&ObjectTexture, &LevelStack),
        mips: &MipBuilder,
        encoder: &mut wgpu::CommandEncoder,
    ) {
        let layout = texture.layout;
        let (aw, ah) = allocated_size(&layout);
        let plane = layout.width * layout.height * stack.channels;
        let plane_bytes = plane as u64 * 4;
        let stacked;
        let source = match stack.levels {
            [one] => *one,
            many => {
                stacked = gpu.device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("level stack"),
                    size: plane_bytes * many.len() as u64,
                    usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                });
                for (k, level) in many.iter().enumerate() {
                    encoder.copy_buffer_to_buffer(
                        level,
                        0,
                        &stacked,
                        k as u64 * plane_bytes,
                        plane_bytes,
                    );
                }
                &stacked
            }
        };
        let params = Params {
            used: [layout.width, layout.height],
            alloc: [aw, ah],
            channels: stack.channels,
            levels: stack.levels.len() as u32,
            plane,
            mode: gamma_mode(stack.gamma),
            gamma: stack.gamma,
            _pad: [0; 3],
        };
        let ubuf = gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("rebuild params"),
            contents: bytemuck::bytes_of(&params),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let finest = texture.texture.create_view(&wgpu::TextureViewDescriptor {
            base_mip_level: 0,
            mip_level_count: Some(1),
            ..Default::default()
        });
        let bg = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("rebuild"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: ubuf.as_entire_binding() },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                        buffer: source,
                        offset: 0,
                        size: wgpu::BufferSize::new(plane_bytes * stack.levels.len() as u64),
                    }),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: wgpu::BindingResource::TextureView(&finest),
                },
            ],
        });
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("rebuild"),
                timestamp_writes: None,
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &bg, &[]);
            pass.dispatch_workgroups(aw.div_ceil(8), ah.div_ceil(8), 1);
        }
        mips.decimate(gpu, texture, encoder);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_gamma_mode_names_the_fast_path_for_the_default_gamma() {
        assert_eq!(gamma_mode(1.0), 0);
        assert_eq!(gamma_mode(pis_codec::gamma::DEFAULT_GAMMA), 1);
        assert_eq!(gamma_mode(1.8), 2);
    }
}
