//! The player's textured-object pipeline (`textured.wgsl`): draws a mesh with its block's
//! texture transform (branch cuts, then the affine map) in the vertex shader, samples a float texture with its MIP chain
//! at the LOD the fragment shader computes from fine derivatives, into a float render target
//! that is read back. Its math is pis-compile's hardware model, function for function.
//!
//! # Textures of any used size
//!
//! A texture with used size w × h has model levels of `mip_size(w, h, m)` texels (halving
//! with rounding up, SPEC.md 8.3) and level-m texel coordinates `u = s·w/2^m`. WebGPU halves
//! level sizes rounding *down*, so the player allocates `W × H = next_pow2(w) × next_pow2(h)`
//! with the model's level count; then GPU level m has `max(1, W/2^m) ≥ ceil(w/2^m)` texels and
//! texel coordinates `s_gpu·W/2^m`, so with `s_gpu = s·w/W` (the `scale` uniform) GPU and
//! model texel coordinates coincide (a level 1 texel wide reads the same texel in both).
//! Each GPU level holds the model level in its top-left corner; the padding repeats the last
//! used column and row, so clamp-to-edge on the allocated texture equals clamp-to-edge on the
//! used region. Repeat addressing needs w (or h) to be a power of two (no padding).
//!
//! Textures are `Rgba32Float` where the adapter can filter it (feature `FLOAT32_FILTERABLE`,
//! see [`crate::Gpu::texture_format`]): the values filtered are those the model's A
//! multiplies. Elsewhere they are `Rgba16Float`, and texels are rounded to half floats on
//! upload (model and GPU then differ by that rounding only: above 70 dB for values in [0, 1]).

use bytemuck::{Pod, Zeroable};
use pis_compile::filter::max_level;
use pis_compile::{
    Address, DrawMesh, Filter, TextureLayout, TextureTransform, TexturedObject, Viewport,
};
use wgpu::util::DeviceExt;

use crate::error::PlayError;
use crate::gpu::Gpu;
use crate::image::FloatImage;

/// Format of the offscreen render target.
pub const TARGET_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;
/// Format of the depth buffer (the model's depth is f32 too).
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// The WGSL source: the texture math shared with the player's frame (`texture_lod.wgsl`,
/// `texture_transform.wgsl`, `texture_sample.wgsl`), then `textured.wgsl`.
pub const SHADER: &str = concat!(
    include_str!("texture_lod.wgsl"),
    include_str!("texture_transform.wgsl"),
    include_str!("texture_sample.wgsl"),
    include_str!("textured.wgsl")
);

/// `Uniforms` of `textured.wgsl` (128 bytes, std140-compatible order).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct Uniforms {
    clip_from_object: [f32; 16],
    affine_abcd: [f32; 4],
    affine_ef: [f32; 2],
    size: [f32; 2],
    scale: [f32; 2],
    max_level: f32,
    anisotropic: u32,
    cut: [f32; 4],
}

/// The `cut` uniform of a transform's branch cuts: (u_cut, v_cut, 1 if cut along u, 1 if
/// cut along v), slots without a cut 0.
pub fn cut_uniform(transform: &TextureTransform) -> [f32; 4] {
    let [cu, cv] = transform.cut;
    [cu.unwrap_or(0.0), cv.unwrap_or(0.0), cu.is_some() as u8 as f32, cv.is_some() as u8 as f32]
}

/// Size of the GPU texture allocated for a used size: the next power of two per axis.
pub fn allocated_size(layout: &TextureLayout) -> (u32, u32) {
    (layout.width.next_power_of_two(), layout.height.next_power_of_two())
}

/// The GPU image of every level: level m of the layout (RGBA per texel, `rgba` laid out as
/// the layout's x with 4 values per texel) in the top-left corner of a `max(1, W/2^m) ×
/// max(1, H/2^m)` image, the last used column and row repeated into the padding.
pub fn gpu_levels(
    layout: &TextureLayout,
    rgba: &[f32],
) -> Result<Vec<(u32, u32, Vec<f32>)>, PlayError> {
    let want = layout.texel_count() * 4;
    if rgba.len() != want {
        return Err(PlayError::TextureData {
            got: rgba.len(),
            want,
            width: layout.width,
            height: layout.height,
            levels: layout.levels,
        });
    }
    let (aw, ah) = allocated_size(layout);
    Ok((0..layout.levels)
        .map(|m| {
            let (w, h) = layout.level_size(m);
            let (gw, gh) = ((aw >> m).max(1), (ah >> m).max(1));
            let base = layout.level_offset(m);
            let mut img = vec![0.0f32; gw as usize * gh as usize * 4];
            for j in 0..gh {
                for i in 0..gw {
                    let src = base + (j.min(h - 1) * w + i.min(w - 1)) as usize;
                    let dst = (j * gw + i) as usize;
                    img[dst * 4..dst * 4 + 4].copy_from_slice(&rgba[src * 4..src * 4 + 4]);
                }
            }
            (gw, gh, img)
        })
        .collect())
}

/// An object's texture on the GPU, allocated as described in the module docs.
pub struct ObjectTexture {
    pub layout: TextureLayout,
    pub texture: wgpu::Texture,
    pub view: wgpu::TextureView,
}

impl ObjectTexture {
    /// Allocates the texture of a layout (contents zero).
    pub fn new(gpu: &Gpu, layout: TextureLayout) -> ObjectTexture {
        let (w, h) = allocated_size(&layout);
        let texture = gpu.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("object texture"),
            size: wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 },
            mip_level_count: layout.levels,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: gpu.texture_format,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        let view = texture.create_view(&wgpu::TextureViewDescriptor::default());
        ObjectTexture { layout, texture, view }
    }

    /// Uploads every level: `rgba` holds 4 values per texel of the layout (its x order).
    pub fn upload(&self, gpu: &Gpu, rgba: &[f32]) -> Result<(), PlayError> {
        for (m, (w, h, img)) in gpu_levels(&self.layout, rgba)?.into_iter().enumerate() {
            write_level(gpu, &self.texture, (m as u32, 0), (w, h), &img);
        }
        Ok(())
    }
}

thread_local! {
    /// Half floats on their way to a texture: one buffer per thread that uploads, grown to
    /// the largest level and kept, so that an upload allocates and zeroes no fresh memory.
    static HALVES: std::cell::RefCell<Vec<u16>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// Writes RGBA values (4 a texel, rows of `size.0` texels) into level `mip` of array layer
/// `layer` of `texture`: as they are into `Rgba32Float`, rounded to the nearest half floats
/// into `Rgba16Float`. Returns the bytes written.
pub(crate) fn write_level(
    gpu: &Gpu,
    texture: &wgpu::Texture,
    at: (u32, u32),
    size: (u32, u32),
    rgba: &[f32],
) -> u64 {
    use half::slice::{HalfBitsSliceExt, HalfFloatSliceExt};
    if texture.format() != wgpu::TextureFormat::Rgba16Float {
        return write_bytes(gpu, texture, at, size, bytemuck::cast_slice(rgba));
    }
    HALVES.with_borrow_mut(|bits| {
        if bits.len() < rgba.len() {
            bits.resize(rgba.len(), 0);
        }
        let halves = &mut bits[..rgba.len()];
        halves.reinterpret_cast_mut::<half::f16>().convert_from_f32_slice(rgba);
        write_bytes(gpu, texture, at, size, bytemuck::cast_slice(halves))
    })
}

/// Writes texel bytes (rows of `size.0` texels) into level `mip` of array layer `layer` of
/// `texture`. Returns the bytes written.
fn write_bytes(
    gpu: &Gpu,
    texture: &wgpu::Texture,
    (mip, layer): (u32, u32),
    (w, h): (u32, u32),
    bytes: &[u8],
) -> u64 {
    gpu.queue.write_texture(
        wgpu::TexelCopyTextureInfo {
            texture,
            mip_level: mip,
            origin: wgpu::Origin3d { x: 0, y: 0, z: layer },
            aspect: wgpu::TextureAspect::All,
        },
        bytes,
        wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(w * texture.format().block_copy_size(None).unwrap_or(16)),
            rows_per_image: Some(h),
        },
        wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 },
    );
    bytes.len() as u64
}

/// The compiled pipelines: textured colour + depth, and depth only for occluders.
pub struct TexturedPipeline {
    bind_group_layout: wgpu::BindGroupLayout,
    depth_layout: wgpu::BindGroupLayout,
    pipeline: wgpu::RenderPipeline,
    depth_pipeline: wgpu::RenderPipeline,
}

fn uniform_entry() -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding: 0,
        visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

/// A mesh's positions as the vertex shaders read them (location 0).
pub(crate) const POSITION_LAYOUT: wgpu::VertexBufferLayout<'static> = wgpu::VertexBufferLayout {
    array_stride: 12,
    step_mode: wgpu::VertexStepMode::Vertex,
    attributes: &[wgpu::VertexAttribute {
        format: wgpu::VertexFormat::Float32x3,
        offset: 0,
        shader_location: 0,
    }],
};
/// A mesh's texture coordinates as the vertex shaders read them (location 1).
pub(crate) const UV_LAYOUT: wgpu::VertexBufferLayout<'static> = wgpu::VertexBufferLayout {
    array_stride: 8,
    step_mode: wgpu::VertexStepMode::Vertex,
    attributes: &[wgpu::VertexAttribute {
        format: wgpu::VertexFormat::Float32x2,
        offset: 0,
        shader_location: 1,
    }],
};

impl TexturedPipeline {
    pub fn new(gpu: &Gpu) -> TexturedPipeline {
        let device = &gpu.device;
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("textured.wgsl"),
            source: wgpu::ShaderSource::Wgsl(SHADER.into()),
        });
        let bind_group_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("textured"),
            entries: &[
                uniform_entry(),
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: true },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 2,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                    count: None,
                },
            ],
        });
        let depth_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("depth"),
            entries: &[uniform_entry()],
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("textured"),
            bind_group_layouts: &[Some(&bind_group_layout)],
            immediate_size: 0,
        });
        let dlayout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("depth"),
            bind_group_layouts: &[Some(&depth_layout)],
            immediate_size: 0,
        });
        let primitive = wgpu::PrimitiveState {
            topology: wgpu::PrimitiveTopology::TriangleList,
            cull_mode: None,
            ..Default::default()
        };
        let depth_state = wgpu::DepthStencilState {
            format: DEPTH_FORMAT,
            depth_write_enabled: Some(true),
            depth_compare: Some(wgpu::CompareFunction::Less),
            stencil: Default::default(),
            bias: Default::default(),
        };
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("textured"),
            layout: Some(&layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &[Some(POSITION_LAYOUT), Some(UV_LAYOUT)],
            },
            primitive,
            depth_stencil: Some(depth_state.clone()),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_main"),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState {
                    format: TARGET_FORMAT,
                    blend: None,
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: None,
        });
        let depth_pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("depth"),
            layout: Some(&dlayout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_depth"),
                compilation_options: Default::default(),
                buffers: &[Some(POSITION_LAYOUT)],
            },
            primitive,
            depth_stencil: Some(depth_state),
            multisample: Default::default(),
            fragment: None,
            multiview_mask: None,
            cache: None,
        });
        TexturedPipeline { bind_group_layout, depth_layout, pipeline, depth_pipeline }
    }
}

/// The sampler of a model sampler state: nearest or linear texel filtering, linear MIP
/// blending for trilinear and anisotropic, the anisotropy clamp of anisotropic filtering,
/// addressing per axis. The LOD comes from the shader (the adapter's, for anisotropic).
pub fn create_sampler(gpu: &Gpu, sampler: &pis_compile::Sampler) -> wgpu::Sampler {
    let mode = |a: Address| match a {
        Address::ClampToEdge => wgpu::AddressMode::ClampToEdge,
        Address::Repeat => wgpu::AddressMode::Repeat,
    };
    let texel = if sampler.filter == Filter::Nearest {
        wgpu::FilterMode::Nearest
    } else {
        wgpu::FilterMode::Linear
    };
    let mip = if sampler.filter.uses_mips() {
        wgpu::MipmapFilterMode::Linear
    } else {
        wgpu::MipmapFilterMode::Nearest
    };
    // Anisotropy needs linear filters everywhere (it is); WebGPU clamps to 1..=16.
    let anisotropy_clamp = match sampler.filter {
        Filter::Anisotropic(n) => u16::from(n.clamp(1, pis_compile::MAX_ANISOTROPY)),
        _ => 1,
    };
    gpu.device.create_sampler(&wgpu::SamplerDescriptor {
        label: Some("object sampler"),
        address_mode_u: mode(sampler.address[0]),
        address_mode_v: mode(sampler.address[1]),
        address_mode_w: wgpu::AddressMode::ClampToEdge,
        mag_filter: texel,
        min_filter: texel,
        mipmap_filter: mip,
        lod_min_clamp: 0.0,
        lod_max_clamp: 32.0,
        compare: None,
        anisotropy_clamp,
        border_color: None,
    })
}

struct MeshBuffers {
    positions: wgpu::Buffer,
    uvs: wgpu::Buffer,
    indices: wgpu::Buffer,
    count: u32,
    uniforms: wgpu::Buffer,
}

fn mesh_buffers(gpu: &Gpu, mesh: &DrawMesh, uniforms: Uniforms) -> MeshBuffers {
    let d = &gpu.device;
    let init = |label: &str, contents: &[u8], usage| {
        d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(label),
            contents,
            usage,
        })
    };
    // A zero-length buffer cannot be bound: pad empty inputs.
    let uvs: Vec<[f32; 2]> = if mesh.uvs.is_empty() { vec![[0.0; 2]] } else { mesh.uvs.to_vec() };
    let positions: Vec<[f32; 3]> =
        if mesh.positions.is_empty() { vec![[0.0; 3]] } else { mesh.positions.to_vec() };
    let indices: Vec<u32> = if mesh.indices.is_empty() { vec![0] } else { mesh.indices.to_vec() };
    MeshBuffers {
        positions: init("positions", bytemuck::cast_slice(&positions), wgpu::BufferUsages::VERTEX),
        uvs: init("uvs", bytemuck::cast_slice(&uvs), wgpu::BufferUsages::VERTEX),
        indices: init("indices", bytemuck::cast_slice(&indices), wgpu::BufferUsages::INDEX),
        count: mesh.indices.len() as u32 / 3 * 3,
        uniforms: init("uniforms", bytemuck::bytes_of(&uniforms), wgpu::BufferUsages::UNIFORM),
    }
}

fn uniforms_of(clip_from_object: glam::Mat4, object: Option<&TexturedObject>) -> Uniforms {
    let mut u = Uniforms {
        clip_from_object: clip_from_object.to_cols_array(),
        affine_abcd: [1.0, 0.0, 0.0, 1.0],
        affine_ef: [0.0; 2],
        size: [1.0; 2],
        scale: [1.0; 2],
        max_level: 0.0,
        anisotropic: 0,
        cut: [0.0; 4],
    };
    if let Some(o) = object {
        let [a, b, c, d, e, f] = o.transform.values;
        let (aw, ah) = allocated_size(&o.layout);
        u.affine_abcd = [a, b, c, d];
        u.affine_ef = [e, f];
        u.size = [o.layout.width as f32, o.layout.height as f32];
        u.scale = [o.layout.width as f32 / aw as f32, o.layout.height as f32 / ah as f32];
        u.max_level = max_level(&o.layout, &o.sampler) as f32;
        u.anisotropic = u32::from(matches!(o.sampler.filter, Filter::Anisotropic(_)));
        u.cut = cut_uniform(&o.transform);
    }
    u
}

/// One object with its occluders, uploaded and ready to render offscreen any number of
/// times with different texture contents (the player's frame, and probe mode's renderings).
pub struct ObjectScene {
    viewport: Viewport,
    occluders: Vec<(MeshBuffers, wgpu::BindGroup)>,
    object: MeshBuffers,
    sampler: wgpu::Sampler,
    color: wgpu::Texture,
    depth: wgpu::Texture,
    readback: wgpu::Buffer,
    row_bytes: u32,
}

impl ObjectScene {
    /// Uploads the occluders' and the object's meshes; checks them as the model does.
    pub fn new(
        gpu: &Gpu,
        pipeline: &TexturedPipeline,
        viewport: Viewport,
        occluders: &[DrawMesh],
        object: &TexturedObject,
    ) -> Result<ObjectScene, PlayError> {
        let limit = gpu.limits.max_texture_dimension_2d;
        if viewport.width == 0
            || viewport.height == 0
            || viewport.width > limit
            || viewport.height > limit
        {
            return Err(PlayError::TargetSize {
                width: viewport.width,
                height: viewport.height,
                limit,
            });
        }
        pis_compile::model::render_matrix_inputs_ok(viewport, object)?;
        for (axis, k, size) in [('s', 0, object.layout.width), ('t', 1, object.layout.height)] {
            if object.sampler.address[k] == Address::Repeat && !size.is_power_of_two() {
                return Err(PlayError::RepeatSize { axis, size });
            }
        }
        let mut occ = Vec::with_capacity(occluders.len());
        for m in occluders {
            pis_compile::model::check_mesh(m)?;
            let b = mesh_buffers(gpu, m, uniforms_of(m.clip_from_object, None));
            let bg = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("occluder"),
                layout: &pipeline.depth_layout,
                entries: &[wgpu::BindGroupEntry {
                    binding: 0,
                    resource: b.uniforms.as_entire_binding(),
                }],
            });
            occ.push((b, bg));
        }
        let object_buffers = mesh_buffers(
            gpu,
            &object.mesh,
            uniforms_of(object.mesh.clip_from_object, Some(object)),
        );
        let size = wgpu::Extent3d {
            width: viewport.width,
            height: viewport.height,
            depth_or_array_layers: 1,
        };
        let target = |label, format, usage| {
            gpu.device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size,
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage,
                view_formats: &[],
            })
        };
        let color = target(
            "frame",
            TARGET_FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        );
        let depth = target("depth", DEPTH_FORMAT, wgpu::TextureUsages::RENDER_ATTACHMENT);
        let row_bytes = (viewport.width * 16).div_ceil(256) * 256;
        let readback = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback"),
            size: row_bytes as u64 * viewport.height as u64,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        Ok(ObjectScene {
            viewport,
            occluders: occ,
            object: object_buffers,
            sampler: create_sampler(gpu, &object.sampler),
            color,
            depth,
            readback,
            row_bytes,
        })
    }

    /// The render target's size.
    pub fn viewport(&self) -> Viewport {
        self.viewport
    }

    /// Renders the object with `texture` over the occluders' depth; returns RGBA per pixel
    /// (rows from the top), alpha 1 where the object is visible, 0 elsewhere.
    pub fn render(
        &self,
        gpu: &Gpu,
        pipeline: &TexturedPipeline,
        texture: &ObjectTexture,
    ) -> Result<FloatImage, PlayError> {
        let bind_group = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("textured"),
            layout: &pipeline.bind_group_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: self.object.uniforms.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(&texture.view),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: wgpu::BindingResource::Sampler(&self.sampler),
                },
            ],
        });
        let color_view = self.color.create_view(&Default::default());
        let depth_view = self.depth.create_view(&Default::default());
        let mut enc = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("frame") });
        {
            let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("occluders"),
                color_attachments: &[],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &depth_view,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(1.0),
                        store: wgpu::StoreOp::Store,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&pipeline.depth_pipeline);
            for (b, bg) in &self.occluders {
                pass.set_bind_group(0, bg, &[]);
                pass.set_vertex_buffer(0, b.positions.slice(..));
                pass.set_index_buffer(b.indices.slice(..), wgpu::IndexFormat::Uint32);
                pass.draw_indexed(0..b.count, 0, 0..1);
            }
        }
        {
            let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("object"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &color_view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &depth_view,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Load,
                        store: wgpu::StoreOp::Store,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&pipeline.pipeline);
            pass.set_bind_group(0, &bind_group, &[]);
            pass.set_vertex_buffer(0, self.object.positions.slice(..));
            pass.set_vertex_buffer(1, self.object.uvs.slice(..));
            pass.set_index_buffer(self.object.indices.slice(..), wgpu::IndexFormat::Uint32);
            pass.draw_indexed(0..self.object.count, 0, 0..1);
        }
        let (w, h) = (self.viewport.width, self.viewport.height);
        enc.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                texture: &self.color,
                mip_level: 0,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            wgpu::TexelCopyBufferInfo {
                buffer: &self.readback,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(self.row_bytes),
                    rows_per_image: Some(h),
                },
            },
            wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 },
        );
        gpu.queue.submit([enc.finish()]);
        crate::image::map_rows(gpu, &self.readback, self.row_bytes, w, h)
    }
}

/// Renders one object once: uploads `rgba` (4 values per texel of the layout) and draws it
/// over its occluders' depth.
pub fn render_object(
    gpu: &Gpu,
    pipeline: &TexturedPipeline,
    viewport: Viewport,
    occluders: &[DrawMesh],
    object: &TexturedObject,
    rgba: &[f32],
) -> Result<FloatImage, PlayError> {
    let scene = ObjectScene::new(gpu, pipeline, viewport, occluders, object)?;
    let texture = ObjectTexture::new(gpu, object.layout);
    texture.upload(gpu, rgba)?;
    scene.render(gpu, pipeline, &texture)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn padding_replicates_the_used_edge() {
        let layout = TextureLayout::full(3, 2);
        let rgba: Vec<f32> = (0..layout.texel_count() * 4).map(|k| (k / 4) as f32).collect();
        let levels = gpu_levels(&layout, &rgba).unwrap();
        assert_eq!(levels.len(), 3);
        let (w, h, img) = &levels[0];
        assert_eq!((*w, *h), (4, 2));
        let texel = |i: usize, j: usize| img[(j * 4 + i) * 4];
        assert_eq!([texel(0, 0), texel(2, 0), texel(3, 0), texel(3, 1)], [0.0, 2.0, 2.0, 5.0]);
        // Level 1: used 2×1 in a 2×1 GPU level; level 2: 1×1.
        assert_eq!((levels[1].0, levels[1].1), (2, 1));
        assert_eq!(levels[1].2[0], 6.0);
        assert_eq!((levels[2].0, levels[2].1), (1, 1));
        assert!(gpu_levels(&layout, &rgba[4..]).is_err());
    }
}
