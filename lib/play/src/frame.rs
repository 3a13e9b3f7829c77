//! Drawing a frame (`frame.wgsl`): a pass that writes depth and the object index of every
//! pixel's nearest surface, then one additive draw per object, layer and parameter sample,
//! with the block's affine texture transform in the vertex shader and the hardware model's
//! LOD and sampler in the fragment shader. Layers add in linear space (SPEC.md "Combining
//! layers": surface layers combine by addition).

use std::collections::HashMap;

use bytemuck::{Pod, Zeroable};
use wgpu::util::DeviceExt;

use crate::error::PlayError;
use crate::gpu::Gpu;
use crate::image::FloatImage;
use crate::textured::{allocated_size, ObjectTexture, DEPTH_FORMAT};

/// The WGSL source.
pub const SHADER: &str = include_str!("frame.wgsl");
/// The object-index target's format.
pub const ID_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Uint;
/// Object index of pixels no object covers.
pub const NO_OBJECT: u32 = u32::MAX;

/// `Uniforms` of `frame.wgsl` (128 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct Uniforms {
    clip_from_object: [f32; 16],
    affine_abcd: [f32; 4],
    affine_ef: [f32; 2],
    size: [f32; 2],
    scale: [f32; 2],
    max_level: f32,
    weight: f32,
    object: u32,
    anisotropic: u32,
    _pad: [u32; 2],
}

/// An object's mesh on the GPU.
pub struct MeshGpu {
    pub positions: wgpu::Buffer,
    pub uvs: wgpu::Buffer,
    pub indices: wgpu::Buffer,
    pub count: u32,
}

impl MeshGpu {
    /// Uploads a mesh; the caller has checked every index against the positions, and that
    /// there is one texture coordinate per position.
    pub fn new(gpu: &Gpu, positions: &[[f32; 3]], uvs: &[[f32; 2]], indices: &[u32]) -> MeshGpu {
        let d = &gpu.device;
        let init = |label: &str, contents: &[u8], usage| d.create_buffer_init(&wgpu::util::BufferInitDescriptor { label: Some(label), contents, usage });
        // A zero-length buffer cannot be bound: pad empty inputs.
        let p: &[[f32; 3]] = if positions.is_empty() { &[[0.0; 3]] } else { positions };
        let t: &[[f32; 2]] = if uvs.is_empty() { &[[0.0; 2]] } else { uvs };
        let i: &[u32] = if indices.is_empty() { &[0] } else { indices };
        MeshGpu {
            positions: init("positions", bytemuck::cast_slice(p), wgpu::BufferUsages::VERTEX),
            uvs: init("uvs", bytemuck::cast_slice(t), wgpu::BufferUsages::VERTEX),
            indices: init("indices", bytemuck::cast_slice(i), wgpu::BufferUsages::INDEX),
            count: indices.len() as u32 / 3 * 3,
        }
    }
}

/// One object in a frame.
pub struct ObjectDraw<'a> {
    pub object: u32,
    pub mesh: &'a MeshGpu,
    pub clip_from_object: glam::Mat4,
}

/// One texture drawn on an object: a layer at one parameter sample, with its weight.
pub struct LayerDraw<'a> {
    /// Index into the frame's objects.
    pub draw: usize,
    pub texture: &'a ObjectTexture,
    pub sampler: &'a wgpu::Sampler,
    pub affine: [f32; 6],
    pub max_level: f32,
    pub weight: f32,
    /// Anisotropic filtering: the lookup takes the derivatives, the sampler its clamp.
    pub anisotropic: bool,
}

/// The frame's pipelines: object index and depth, and additive layers per target format.
pub struct FramePipelines {
    module: wgpu::ShaderModule,
    uniform_layout: wgpu::BindGroupLayout,
    draw_layout: wgpu::BindGroupLayout,
    ids_layout: wgpu::BindGroupLayout,
    layer_layout: wgpu::PipelineLayout,
    id_pipeline: wgpu::RenderPipeline,
    layer_pipelines: HashMap<wgpu::TextureFormat, wgpu::RenderPipeline>,
}

const POSITION_LAYOUT: wgpu::VertexBufferLayout<'static> = wgpu::VertexBufferLayout {
    array_stride: 12,
    step_mode: wgpu::VertexStepMode::Vertex,
    attributes: &[wgpu::VertexAttribute { format: wgpu::VertexFormat::Float32x3, offset: 0, shader_location: 0 }],
};
const UV_LAYOUT: wgpu::VertexBufferLayout<'static> = wgpu::VertexBufferLayout {
    array_stride: 8,
    step_mode: wgpu::VertexStepMode::Vertex,
    attributes: &[wgpu::VertexAttribute { format: wgpu::VertexFormat::Float32x2, offset: 0, shader_location: 1 }],
};

fn entry(binding: u32, visibility: wgpu::ShaderStages, ty: wgpu::BindingType) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry { binding, visibility, ty, count: None }
}

const UNIFORM: wgpu::BindingType = wgpu::BindingType::Buffer { ty: wgpu::BufferBindingType::Uniform, has_dynamic_offset: false, min_binding_size: None };

impl FramePipelines {
    pub fn new(gpu: &Gpu) -> FramePipelines {
        let d = &gpu.device;
        let module = d.create_shader_module(wgpu::ShaderModuleDescriptor { label: Some("frame.wgsl"), source: wgpu::ShaderSource::Wgsl(SHADER.into()) });
        let vf = wgpu::ShaderStages::VERTEX_FRAGMENT;
        let uniform_layout = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some("frame uniforms"), entries: &[entry(0, vf, UNIFORM)] });
        let draw_layout = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("frame layer"),
            entries: &[
                entry(0, vf, UNIFORM),
                entry(1, wgpu::ShaderStages::FRAGMENT, wgpu::BindingType::Texture { sample_type: wgpu::TextureSampleType::Float { filterable: true }, view_dimension: wgpu::TextureViewDimension::D2, multisampled: false }),
                entry(2, wgpu::ShaderStages::FRAGMENT, wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering)),
            ],
        });
        let ids_layout = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("frame ids"),
            entries: &[entry(0, wgpu::ShaderStages::FRAGMENT, wgpu::BindingType::Texture { sample_type: wgpu::TextureSampleType::Uint, view_dimension: wgpu::TextureViewDimension::D2, multisampled: false })],
        });
        let id_layout = d.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor { label: Some("frame ids"), bind_group_layouts: &[Some(&uniform_layout)], immediate_size: 0 });
        let layer_layout = d.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor { label: Some("frame layers"), bind_group_layouts: &[Some(&draw_layout), Some(&ids_layout)], immediate_size: 0 });
        let id_pipeline = d.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("frame ids"),
            layout: Some(&id_layout),
            vertex: wgpu::VertexState { module: &module, entry_point: Some("vs_main"), compilation_options: Default::default(), buffers: &[Some(POSITION_LAYOUT), Some(UV_LAYOUT)] },
            primitive: wgpu::PrimitiveState { topology: wgpu::PrimitiveTopology::TriangleList, cull_mode: None, ..Default::default() },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: DEPTH_FORMAT,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Less),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_id"),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState { format: ID_FORMAT, blend: None, write_mask: wgpu::ColorWrites::ALL })],
            }),
            multiview_mask: None,
            cache: None,
        });
        FramePipelines { module, uniform_layout, draw_layout, ids_layout, layer_layout, id_pipeline, layer_pipelines: HashMap::new() }
    }

    /// The additive layer pipeline for a target format (compiled on first use).
    pub fn layer_pipeline(&mut self, gpu: &Gpu, format: wgpu::TextureFormat) -> &wgpu::RenderPipeline {
        let (module, layout) = (&self.module, &self.layer_layout);
        self.layer_pipelines.entry(format).or_insert_with(|| {
            let add = wgpu::BlendComponent { src_factor: wgpu::BlendFactor::One, dst_factor: wgpu::BlendFactor::One, operation: wgpu::BlendOperation::Add };
            let max = wgpu::BlendComponent { src_factor: wgpu::BlendFactor::One, dst_factor: wgpu::BlendFactor::One, operation: wgpu::BlendOperation::Max };
            gpu.device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("frame layers"),
                layout: Some(layout),
                vertex: wgpu::VertexState { module, entry_point: Some("vs_main"), compilation_options: Default::default(), buffers: &[Some(POSITION_LAYOUT), Some(UV_LAYOUT)] },
                primitive: wgpu::PrimitiveState { topology: wgpu::PrimitiveTopology::TriangleList, cull_mode: None, ..Default::default() },
                depth_stencil: Some(wgpu::DepthStencilState {
                    format: DEPTH_FORMAT,
                    depth_write_enabled: Some(false),
                    depth_compare: Some(wgpu::CompareFunction::LessEqual),
                    stencil: Default::default(),
                    bias: Default::default(),
                }),
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module,
                    entry_point: Some("fs_layer"),
                    compilation_options: Default::default(),
                    targets: &[Some(wgpu::ColorTargetState { format, blend: Some(wgpu::BlendState { color: add, alpha: max }), write_mask: wgpu::ColorWrites::ALL })],
                }),
                multiview_mask: None,
                cache: None,
            })
        })
    }
}

/// The format offscreen frames accumulate in: `Rgba32Float` where the device can blend it,
/// else `Rgba16Float`.
pub fn offscreen_format(gpu: &Gpu) -> wgpu::TextureFormat {
    if gpu.device.features().contains(wgpu::Features::FLOAT32_BLENDABLE) {
        wgpu::TextureFormat::Rgba32Float
    } else {
        wgpu::TextureFormat::Rgba16Float
    }
}

/// The per-size targets: object indices, depth, and the offscreen colour target.
pub struct Targets {
    pub size: (u32, u32),
    pub ids: wgpu::Texture,
    pub depth: wgpu::Texture,
    pub colour: wgpu::Texture,
    ids_bind: wgpu::BindGroup,
}

impl Targets {
    pub fn new(gpu: &Gpu, pipes: &FramePipelines, size: (u32, u32)) -> Result<Targets, PlayError> {
        let limit = gpu.limits.max_texture_dimension_2d;
        if size.0 == 0 || size.1 == 0 || size.0 > limit || size.1 > limit {
            return Err(PlayError::TargetSize { width: size.0, height: size.1, limit });
        }
        let extent = wgpu::Extent3d { width: size.0, height: size.1, depth_or_array_layers: 1 };
        let make = |label, format, usage| {
            gpu.device.create_texture(&wgpu::TextureDescriptor { label: Some(label), size: extent, mip_level_count: 1, sample_count: 1, dimension: wgpu::TextureDimension::D2, format, usage, view_formats: &[] })
        };
        let ids = make("object ids", ID_FORMAT, wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_SRC);
        let depth = make("depth", DEPTH_FORMAT, wgpu::TextureUsages::RENDER_ATTACHMENT);
        let colour = make("frame", offscreen_format(gpu), wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC);
        let ids_view = ids.create_view(&Default::default());
        let ids_bind = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("object ids"),
            layout: &pipes.ids_layout,
            entries: &[wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(&ids_view) }],
        });
        Ok(Targets { size, ids, depth, colour, ids_bind })
    }
}

fn uniforms(clip_from_object: glam::Mat4, object: u32, layer: Option<&LayerDraw>) -> Uniforms {
    let mut u = Uniforms {
        clip_from_object: clip_from_object.to_cols_array(),
        affine_abcd: [1.0, 0.0, 0.0, 1.0],
        affine_ef: [0.0; 2],
        size: [1.0; 2],
        scale: [1.0; 2],
        max_level: 0.0,
        weight: 0.0,
        object,
        anisotropic: 0,
        _pad: [0; 2],
    };
    if let Some(l) = layer {
        let [a, b, c, d, e, f] = l.affine;
        let layout = l.texture.layout;
        let (aw, ah) = allocated_size(&layout);
        u.affine_abcd = [a, b, c, d];
        u.affine_ef = [e, f];
        u.size = [layout.width as f32, layout.height as f32];
        u.scale = [layout.width as f32 / aw as f32, layout.height as f32 / ah as f32];
        u.max_level = l.max_level;
        u.weight = l.weight;
        u.anisotropic = l.anisotropic as u32;
    }
    u
}

/// Records a frame into `encoder`: clears `colour` (format `format`, size `targets.size`) to
/// transparent black, then draws.
#[allow(clippy::too_many_arguments)]
pub fn encode(
    gpu: &Gpu,
    pipes: &mut FramePipelines,
    targets: &Targets,
    colour: &wgpu::TextureView,
    format: wgpu::TextureFormat,
    objects: &[ObjectDraw],
    layers: &[LayerDraw],
    encoder: &mut wgpu::CommandEncoder,
) {
    let d = &gpu.device;
    let ubuf = |u: Uniforms| d.create_buffer_init(&wgpu::util::BufferInitDescriptor { label: Some("frame uniforms"), contents: bytemuck::bytes_of(&u), usage: wgpu::BufferUsages::UNIFORM });
    let id_binds: Vec<wgpu::BindGroup> = objects
        .iter()
        .map(|o| {
            let b = ubuf(uniforms(o.clip_from_object, o.object, None));
            d.create_bind_group(&wgpu::BindGroupDescriptor { label: Some("object id"), layout: &pipes.uniform_layout, entries: &[wgpu::BindGroupEntry { binding: 0, resource: b.as_entire_binding() }] })
        })
        .collect();
    let layer_binds: Vec<wgpu::BindGroup> = layers
        .iter()
        .map(|l| {
            let o = &objects[l.draw];
            let b = ubuf(uniforms(o.clip_from_object, o.object, Some(l)));
            d.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("layer"),
                layout: &pipes.draw_layout,
                entries: &[
                    wgpu::BindGroupEntry { binding: 0, resource: b.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(&l.texture.view) },
                    wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::Sampler(l.sampler) },
                ],
            })
        })
        .collect();
    let ids_view = targets.ids.create_view(&Default::default());
    let depth_view = targets.depth.create_view(&Default::default());
    {
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("object ids"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &ids_view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations { load: wgpu::LoadOp::Clear(wgpu::Color { r: NO_OBJECT as f64, g: 0.0, b: 0.0, a: 0.0 }), store: wgpu::StoreOp::Store },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &depth_view,
                depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(1.0), store: wgpu::StoreOp::Store }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&pipes.id_pipeline);
        for (o, bg) in objects.iter().zip(&id_binds) {
            pass.set_bind_group(0, bg, &[]);
            pass.set_vertex_buffer(0, o.mesh.positions.slice(..));
            pass.set_vertex_buffer(1, o.mesh.uvs.slice(..));
            pass.set_index_buffer(o.mesh.indices.slice(..), wgpu::IndexFormat::Uint32);
            pass.draw_indexed(0..o.mesh.count, 0, 0..1);
        }
    }
    let pipeline = pipes.layer_pipeline(gpu, format);
    let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("layers"),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view: colour,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations { load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT), store: wgpu::StoreOp::Store },
        })],
        depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
            view: &depth_view,
            depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store }),
            stencil_ops: None,
        }),
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    });
    pass.set_pipeline(pipeline);
    pass.set_bind_group(1, &targets.ids_bind, &[]);
    for (l, bg) in layers.iter().zip(&layer_binds) {
        let m = objects[l.draw].mesh;
        pass.set_bind_group(0, bg, &[]);
        pass.set_vertex_buffer(0, m.positions.slice(..));
        pass.set_vertex_buffer(1, m.uvs.slice(..));
        pass.set_index_buffer(m.indices.slice(..), wgpu::IndexFormat::Uint32);
        pass.draw_indexed(0..m.count, 0, 0..1);
    }
}

/// Maps a buffer the GPU has been told to fill and returns its bytes.
pub fn map_read(gpu: &Gpu, buffer: &wgpu::Buffer) -> Result<Vec<u8>, PlayError> {
    let (tx, rx) = std::sync::mpsc::channel();
    buffer.slice(..).map_async(wgpu::MapMode::Read, move |r| {
        let _ = tx.send(r);
    });
    gpu.device.poll(wgpu::PollType::wait_indefinitely()).map_err(|e| PlayError::Readback(e.to_string()))?;
    rx.recv().map_err(|e| PlayError::Readback(e.to_string()))?.map_err(|e| PlayError::Readback(e.to_string()))?;
    let bytes = buffer.slice(..).get_mapped_range().map_err(|e| PlayError::Readback(e.to_string()))?.to_vec();
    buffer.unmap();
    Ok(bytes)
}

/// Readback buffers for a target texture of `texel_bytes` per texel.
pub struct Readback {
    buffer: wgpu::Buffer,
    row: u32,
    texel_bytes: u32,
    size: (u32, u32),
}

impl Readback {
    pub fn new(gpu: &Gpu, size: (u32, u32), texel_bytes: u32) -> Readback {
        let row = (size.0 * texel_bytes).div_ceil(256) * 256;
        let buffer = gpu.device.create_buffer(&wgpu::BufferDescriptor { label: Some("readback"), size: row as u64 * size.1 as u64, usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ, mapped_at_creation: false });
        Readback { buffer, row, texel_bytes, size }
    }

    pub fn copy(&self, texture: &wgpu::Texture, encoder: &mut wgpu::CommandEncoder) {
        encoder.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo { texture, mip_level: 0, origin: wgpu::Origin3d::ZERO, aspect: wgpu::TextureAspect::All },
            wgpu::TexelCopyBufferInfo { buffer: &self.buffer, layout: wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(self.row), rows_per_image: Some(self.size.1) } },
            wgpu::Extent3d { width: self.size.0, height: self.size.1, depth_or_array_layers: 1 },
        );
    }

    /// The rows, padding removed.
    pub fn read(&self, gpu: &Gpu) -> Result<Vec<u8>, PlayError> {
        let bytes = map_read(gpu, &self.buffer)?;
        let w = (self.size.0 * self.texel_bytes) as usize;
        let mut out = Vec::with_capacity(w * self.size.1 as usize);
        for y in 0..self.size.1 as usize {
            out.extend_from_slice(&bytes[y * self.row as usize..y * self.row as usize + w]);
        }
        Ok(out)
    }
}

/// Decodes colour readback bytes (`Rgba32Float` or `Rgba16Float`) into an image.
pub fn colour_image(bytes: &[u8], format: wgpu::TextureFormat, size: (u32, u32)) -> FloatImage {
    let rgba = if format == wgpu::TextureFormat::Rgba16Float {
        bytes.chunks_exact(2).map(|b| half::f16::from_bits(u16::from_le_bytes([b[0], b[1]])).to_f32()).collect()
    } else {
        bytes.chunks_exact(4).map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect()
    };
    FloatImage { width: size.0, height: size.1, rgba }
}

#[cfg(test)]
mod tests {
    /// The text of WGSL function `name` in `src`: from `fn name(` to the closing brace at
    /// the start of a line.
    fn function(src: &str, name: &str) -> String {
        let start = src.find(&format!("fn {name}(")).unwrap_or_else(|| panic!("no fn {name}"));
        let end = src[start..].find("\n}").expect("closing brace") + start + 2;
        src[start..end].to_string()
    }

    #[test]
    fn texture_math_is_the_textured_pipelines() {
        for f in ["texcoord", "texture_lod"] {
            assert_eq!(function(super::SHADER, f), function(crate::textured::SHADER, f), "{f} differs between frame.wgsl and textured.wgsl");
        }
    }
}
