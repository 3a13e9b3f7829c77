//! Relightable layers summed on the GPU (SPEC.md 9; Wong et al.): the coefficient textures of
//! one term, order and parameter sample gathered as the slices of an array texture (once,
//! while they stay resident), and per set of lights their sum Σ_c w_c · x_c written into a
//! texture of the same layout by one compute pass (`relit.wgsl`), its MIP chain decimated as
//! a decoded texture's. The frame then draws the sum once, where it would draw every
//! coefficient times its weight: the same image, since filtering is linear.

use bytemuck::{Pod, Zeroable};
use wgpu::util::DeviceExt;

use crate::gpu::Gpu;
use crate::mip::{storage_name, MipBuilder};
use crate::textured::{allocated_size, ObjectTexture};

/// The most coefficients one sum adds: (8 + 1)², SPEC.md rule 6003.
pub const MAX_COEFFICIENTS: usize = 81;

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct SumUniform {
    count: u32,
    _pad: u32,
    used: [u32; 2],
    alloc: [u32; 2],
    _pad2: [u32; 2],
    weights: [[f32; 4]; MAX_COEFFICIENTS],
}

/// Coefficient textures of one layout gathered as the slices of one array texture.
pub struct CoefficientArray {
    texture: wgpu::Texture,
    view: wgpu::TextureView,
    count: u32,
    layout: pis_compile::TextureLayout,
}

/// The summing pipeline for the GPU's texture format.
pub struct RelitSum {
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::ComputePipeline,
}

fn entry(binding: u32, ty: wgpu::BindingType) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry { binding, visibility: wgpu::ShaderStages::COMPUTE, ty, count: None }
}

impl RelitSum {
    pub fn new(gpu: &Gpu) -> RelitSum {
        let d = &gpu.device;
        let source = include_str!("relit.wgsl").replace("FORMAT", storage_name(gpu.texture_format));
        let module = d.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("relit.wgsl"),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
        let uniform = wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        };
        let array = wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable: false },
            view_dimension: wgpu::TextureViewDimension::D2Array,
            multisampled: false,
        };
        let storage = wgpu::BindingType::StorageTexture {
            access: wgpu::StorageTextureAccess::WriteOnly,
            format: gpu.texture_format,
            view_dimension: wgpu::TextureViewDimension::D2,
        };
        let layout = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("relit sum"),
            entries: &[entry(0, uniform), entry(1, array), entry(2, storage)],
        });
        let pl = d.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("relit sum"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = d.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("relit sum"),
            layout: Some(&pl),
            module: &module,
            entry_point: Some("sum"),
            compilation_options: Default::default(),
            cache: None,
        });
        RelitSum { layout, pipeline }
    }

    /// Records the copy of the finest level of each of `textures` (one layout, at most
    /// [`MAX_COEFFICIENTS`], made by [`MipBuilder::texture`]) into a slice of a new array.
    pub fn gather(
        &self,
        gpu: &Gpu,
        textures: &[&ObjectTexture],
        encoder: &mut wgpu::CommandEncoder,
    ) -> CoefficientArray {
        let layout = textures[0].layout;
        let (w, h) = allocated_size(&layout);
        let count = textures.len().min(MAX_COEFFICIENTS) as u32;
        let texture = gpu.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("relit coefficients"),
            size: wgpu::Extent3d { width: w, height: h, depth_or_array_layers: count },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: gpu.texture_format,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        for (c, t) in textures.iter().take(count as usize).enumerate() {
            encoder.copy_texture_to_texture(
                t.texture.as_image_copy(),
                wgpu::TexelCopyTextureInfo {
                    texture: &texture,
                    mip_level: 0,
                    origin: wgpu::Origin3d { x: 0, y: 0, z: c as u32 },
                    aspect: wgpu::TextureAspect::All,
                },
                wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 },
            );
        }
        let view = texture.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        });
        CoefficientArray { texture, view, count, layout }
    }

    /// A texture of the array's layout holding Σ_c `weights[c]` · slice c, its MIP chain
    /// decimated by `mips`, recorded into `encoder`: `reuse` where it has that layout (a sum
    /// no longer drawn; every texel of it is written), else a new one.
    pub fn sum(
        &self,
        gpu: &Gpu,
        (array, weights): (&CoefficientArray, &[[f32; 3]]),
        (mips, reuse): (&MipBuilder, Option<ObjectTexture>),
        encoder: &mut wgpu::CommandEncoder,
    ) -> ObjectTexture {
        let out = match reuse {
            Some(t) if t.layout == array.layout => t,
            _ => mips.texture(gpu, array.layout),
        };
        let (w, h) = allocated_size(&array.layout);
        let used = [array.layout.width, array.layout.height];
        let mut u = SumUniform {
            count: array.count.min(weights.len() as u32),
            _pad: 0,
            used,
            alloc: [w, h],
            _pad2: [0; 2],
            weights: [[0.0; 4]; MAX_COEFFICIENTS],
        };
        for (slot, wc) in u.weights.iter_mut().zip(weights) {
            *slot = [wc[0], wc[1], wc[2], 0.0];
        }
        let ubuf = gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("relit weights"),
            contents: bytemuck::bytes_of(&u),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let finest = out.texture.create_view(&wgpu::TextureViewDescriptor {
            base_mip_level: 0,
            mip_level_count: Some(1),
            ..Default::default()
        });
        let bg = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("relit sum"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: ubuf.as_entire_binding() },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(&array.view),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: wgpu::BindingResource::TextureView(&finest),
                },
            ],
        });
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("relit sum"),
                timestamp_writes: None,
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &bg, &[]);
            // One invocation a used texel; those of the last column and row fill the padding.
            pass.dispatch_workgroups(used[0].div_ceil(8), used[1].div_ceil(8), 1);
        }
        mips.decimate(gpu, &out, encoder);
        out
    }
}

impl CoefficientArray {
    /// The layout of its slices, and of their sums.
    pub fn layout(&self) -> pis_compile::TextureLayout {
        self.layout
    }

    /// The array's bytes on the GPU.
    pub fn bytes(&self) -> u64 {
        let s = self.texture.size();
        let texel = if self.texture.format() == wgpu::TextureFormat::Rgba16Float { 8 } else { 16 };
        s.width as u64 * s.height as u64 * s.depth_or_array_layers as u64 * texel
    }
}
