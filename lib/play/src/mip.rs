//! Textures uploaded at their finest level, MIP chains rebuilt on the GPU: one compute pass
//! per level with `mip.wgsl`, the box filter of pis-format's `mip::decimate` (the chain
//! pis-pack's prediction and the hardware model use), on the padded layout of `textured.rs`.

use bytemuck::{Pod, Zeroable};
use pis_compile::TextureLayout;
use wgpu::util::DeviceExt;

use crate::decode::TextureImage;
use crate::error::PlayError;
use crate::gpu::Gpu;
use crate::textured::ObjectTexture;

/// The WGSL source (`FORMAT` stands for the storage format).
pub const SHADER: &str = include_str!("mip.wgsl");

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct Sizes {
    src: [u32; 2],
    dst: [u32; 2],
    alloc: [u32; 2],
    _pad: [u32; 2],
}

/// The decimation pipeline for the GPU's texture format.
pub struct MipBuilder {
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::ComputePipeline,
}

pub(crate) fn storage_name(format: wgpu::TextureFormat) -> &'static str {
    match format {
        wgpu::TextureFormat::Rgba16Float => "rgba16float",
        _ => "rgba32float",
    }
}

impl MipBuilder {
    pub fn new(gpu: &Gpu) -> MipBuilder {
        let d = &gpu.device;
        let source = SHADER.replace("FORMAT", storage_name(gpu.texture_format));
        let module = d.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("mip.wgsl"),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
        let layout = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("mip"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::COMPUTE,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::COMPUTE,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: false },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 2,
                    visibility: wgpu::ShaderStages::COMPUTE,
                    ty: wgpu::BindingType::StorageTexture {
                        access: wgpu::StorageTextureAccess::WriteOnly,
                        format: gpu.texture_format,
                        view_dimension: wgpu::TextureViewDimension::D2,
                    },
                    count: None,
                },
            ],
        });
        let pl = d.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("mip"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = d.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("mip"),
            layout: Some(&pl),
            module: &module,
            entry_point: Some("decimate"),
            compilation_options: Default::default(),
            cache: None,
        });
        MipBuilder { layout, pipeline }
    }

    /// Allocates a texture for `layout` (padded to powers of two, every level) that can be
    /// uploaded, decimated into and copied from.
    pub fn texture(&self, gpu: &Gpu, layout: TextureLayout) -> ObjectTexture {
        let (w, h) = crate::textured::allocated_size(&layout);
        let texture = gpu.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("object texture"),
            size: wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 },
            mip_level_count: layout.levels,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: gpu.texture_format,
            usage: wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_DST
                | wgpu::TextureUsages::COPY_SRC
                | wgpu::TextureUsages::STORAGE_BINDING,
            view_formats: &[],
        });
        let view = texture.create_view(&wgpu::TextureViewDescriptor::default());
        ObjectTexture { layout, texture, view }
    }

    /// Uploads the finest level of `image` into `texture` and records the decimation of every
    /// coarser level into `encoder`. Returns the bytes uploaded.
    pub fn upload(
        &self,
        gpu: &Gpu,
        texture: &ObjectTexture,
        image: &TextureImage,
        encoder: &mut wgpu::CommandEncoder,
    ) -> Result<u64, PlayError> {
        let layout = texture.layout;
        let (aw, ah) = crate::textured::allocated_size(&layout);
        if (layout.width, layout.height, aw, ah)
            != (image.width, image.height, image.padded_width, image.padded_height)
            || image.rgba.len() != (aw * ah * 4) as usize
        {
            return Err(PlayError::TextureData {
                got: image.rgba.len(),
                want: (aw * ah * 4) as usize,
                width: layout.width,
                height: layout.height,
                levels: layout.levels,
            });
        }
        let bytes =
            crate::textured::write_level(gpu, &texture.texture, (0, 0), (aw, ah), &image.rgba);
        self.decimate(gpu, texture, encoder);
        Ok(bytes)
    }

    /// Records the decimation of every level of `texture` below the finest into `encoder`.
    pub fn decimate(&self, gpu: &Gpu, texture: &ObjectTexture, encoder: &mut wgpu::CommandEncoder) {
        let layout = texture.layout;
        let (aw, ah) = crate::textured::allocated_size(&layout);
        for m in 1..layout.levels {
            let view = |level: u32| {
                texture.texture.create_view(&wgpu::TextureViewDescriptor {
                    base_mip_level: level,
                    mip_level_count: Some(1),
                    ..Default::default()
                })
            };
            let (src, dst) = (view(m - 1), view(m));
            let (sw, sh) = layout.level_size(m - 1);
            let (dw, dh) = layout.level_size(m);
            let (gw, gh) = ((aw >> m).max(1), (ah >> m).max(1));
            let sizes = Sizes { src: [sw, sh], dst: [dw, dh], alloc: [gw, gh], _pad: [0; 2] };
            let ubuf = gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("mip sizes"),
                contents: bytemuck::bytes_of(&sizes),
                usage: wgpu::BufferUsages::UNIFORM,
            });
            let bg = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("mip"),
                layout: &self.layout,
                entries: &[
                    wgpu::BindGroupEntry { binding: 0, resource: ubuf.as_entire_binding() },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: wgpu::BindingResource::TextureView(&src),
                    },
                    wgpu::BindGroupEntry {
                        binding: 2,
                        resource: wgpu::BindingResource::TextureView(&dst),
                    },
                ],
            });
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("mip"),
                timestamp_writes: None,
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &bg, &[]);
            pass.dispatch_workgroups(gw.div_ceil(8), gh.div_ceil(8), 1);
        }
    }
}

/// Reads every level of a texture back (test and diagnostics): per level, the allocated
/// `max(1, W/2^m) × max(1, H/2^m)` image, RGBA f32.
pub fn read_levels(
    gpu: &Gpu,
    texture: &ObjectTexture,
) -> Result<Vec<(u32, u32, Vec<f32>)>, PlayError> {
    let (aw, ah) = crate::textured::allocated_size(&texture.layout);
    let mut out = Vec::new();
    for m in 0..texture.layout.levels {
        let (w, h) = ((aw >> m).max(1), (ah >> m).max(1));
        out.push((w, h, read_level(gpu, &texture.texture, (m, 0), (w, h))?));
    }
    Ok(out)
}

/// Reads one level of one layer of an RGBA float texture back (tests and diagnostics): the
/// `w × h` texels at its origin, row after row, as f32 (half floats widened).
pub(crate) fn read_level(
    gpu: &Gpu,
    texture: &wgpu::Texture,
    (m, layer): (u32, u32),
    (w, h): (u32, u32),
) -> Result<Vec<f32>, PlayError> {
    let half = texture.format() == wgpu::TextureFormat::Rgba16Float;
    let texel = if half { 8 } else { 16 };
    let row = (w * texel).div_ceil(256) * 256;
    let buf = gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("level readback"),
        size: row as u64 * h as u64,
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let mut enc = gpu.device.create_command_encoder(&Default::default());
    enc.copy_texture_to_buffer(
        wgpu::TexelCopyTextureInfo {
            texture,
            mip_level: m,
            origin: wgpu::Origin3d { x: 0, y: 0, z: layer },
            aspect: wgpu::TextureAspect::All,
        },
        wgpu::TexelCopyBufferInfo {
            buffer: &buf,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(row),
                rows_per_image: Some(h),
            },
        },
        wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 },
    );
    gpu.queue.submit([enc.finish()]);
    let bytes = crate::frame::map_read(gpu, &buf)?;
    let mut img = Vec::with_capacity((w * h * 4) as usize);
    for y in 0..h as usize {
        let r = &bytes[y * row as usize..y * row as usize + (w * texel) as usize];
        if half {
            img.extend(
                r.chunks_exact(2)
                    .map(|b| half::f16::from_bits(u16::from_le_bytes([b[0], b[1]])).to_f32()),
            );
        } else {
            img.extend(r.chunks_exact(4).map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]])));
        }
    }
    Ok(img)
}
