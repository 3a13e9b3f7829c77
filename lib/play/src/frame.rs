//! Drawing a frame (`frame.wgsl`): a pass that writes depth and the object index of every
//! pixel's nearest surface, then one additive draw per object, layer and parameter sample,
//! with the block's texture transform (branch cuts, then the affine map) in the vertex
//! shader and the hardware model's LOD and sampler in the fragment shader, and one additive
//! draw of the reflection term per reflective object and parameter sample
//! (`frame_reflection.wgsl`: the environment-map shells looked up as the hardware model
//! does, composited "over", times Fresnel). Layers and terms add in linear space (SPEC.md 9:
//! surface layers combine by addition, radiance = surface + F · reflection). With more than
//! one sample per pixel (`multisample.rs`) depth and object indices are kept per sample and
//! the colour is resolved into the target: by the hardware's average of each pixel's own
//! samples, or, given the ray-traced set's display filter, by the display-filter resolve
//! (`resolve.rs`).

use std::collections::HashMap;

use bytemuck::{Pod, Zeroable};
use wgpu::util::DeviceExt;

use crate::error::PlayError;
use crate::frame_hybrid::{lens_bind, LensDraw, HYBRID_FRAME, LENS_CORNER_LAYOUT, MAX_LENS_SHELLS};
use crate::frame_reflection::{reflection_bind, REFLECTION};
pub use crate::frame_reflection::{ReflectionDraw, TermShell, MAX_TERM_SHELLS};
use crate::gpu::Gpu;
use crate::image::FloatImage;
use crate::resolve::ResolvePipelines;
use crate::shell::SHELL_FUNCTIONS;
use crate::textured::{allocated_size, cut_uniform, ObjectTexture, DEPTH_FORMAT};

/// The WGSL source.
pub const SHADER: &str = include_str!("frame.wgsl");
/// The object-index target's format.
pub const ID_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Uint;
/// Object index of pixels no object covers.
pub const NO_OBJECT: u32 = u32::MAX;

/// `Uniforms` of `frame.wgsl` (144 bytes).
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
    cut: [f32; 4],
}

/// An object's mesh on the GPU.
pub struct MeshGpu {
    pub positions: wgpu::Buffer,
    /// Object-space vertex normals (zeros for a mesh without normals).
    pub normals: wgpu::Buffer,
    pub uvs: wgpu::Buffer,
    pub indices: wgpu::Buffer,
    pub count: u32,
    /// Indices of the leading triangles on the object's convex hull (SPEC.md 6.5): the
    /// reflection term draws them with its most distant shell only.
    pub hull: u32,
}

impl MeshGpu {
    /// Uploads a mesh; the caller has checked every index against the positions, and that
    /// there is one texture coordinate and, if given, one normal per position. Without
    /// normals the normal buffer holds zeros.
    pub fn new(
        gpu: &Gpu,
        positions: &[[f32; 3]],
        normals: Option<&[[f32; 3]]>,
        uvs: &[[f32; 2]],
        indices: &[u32],
    ) -> MeshGpu {
        let d = &gpu.device;
        let init = |label: &str, contents: &[u8], usage| {
            d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage,
            })
        };
        // A zero-length buffer cannot be bound: pad empty inputs.
        let p: &[[f32; 3]] = if positions.is_empty() { &[[0.0; 3]] } else { positions };
        let zeros = vec![[0.0f32; 3]; p.len()];
        let n: &[[f32; 3]] = normals.filter(|n| !n.is_empty()).unwrap_or(&zeros);
        let t: &[[f32; 2]] = if uvs.is_empty() { &[[0.0; 2]] } else { uvs };
        let i: &[u32] = if indices.is_empty() { &[0] } else { indices };
        MeshGpu {
            positions: init("positions", bytemuck::cast_slice(p), wgpu::BufferUsages::VERTEX),
            normals: init("normals", bytemuck::cast_slice(n), wgpu::BufferUsages::VERTEX),
            uvs: init("uvs", bytemuck::cast_slice(t), wgpu::BufferUsages::VERTEX),
            indices: init("indices", bytemuck::cast_slice(i), wgpu::BufferUsages::INDEX),
            count: indices.len() as u32 / 3 * 3,
            hull: 0,
        }
    }

    /// The same mesh with its first `triangles` triangles on the convex hull (clamped to
    /// the mesh).
    pub fn with_hull(self, triangles: u32) -> MeshGpu {
        let hull = triangles.saturating_mul(3).min(self.count);
        MeshGpu { hull, ..self }
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
    /// The block's texture transform: branch cuts and affine map (SPEC.md 7.3).
    pub transform: pis_compile::TextureTransform,
    pub max_level: f32,
    pub weight: f32,
    /// Anisotropic filtering: the lookup takes the derivatives, the sampler its clamp.
    pub anisotropic: bool,
}

/// The frame's pipelines: object index and depth per sample count, and additive layers and
/// reflection terms per target format and sample count.
pub struct FramePipelines {
    module: wgpu::ShaderModule,
    reflection_module: wgpu::ShaderModule,
    hybrid_module: wgpu::ShaderModule,
    uniform_layout: wgpu::BindGroupLayout,
    draw_layout: wgpu::BindGroupLayout,
    reflection_draw_layout: wgpu::BindGroupLayout,
    hybrid_draw_layout: wgpu::BindGroupLayout,
    ids_layout: wgpu::BindGroupLayout,
    ids_ms_layout: wgpu::BindGroupLayout,
    id_layout: wgpu::PipelineLayout,
    layer_layout: wgpu::PipelineLayout,
    layer_ms_layout: wgpu::PipelineLayout,
    reflection_layout: wgpu::PipelineLayout,
    reflection_ms_layout: wgpu::PipelineLayout,
    hybrid_layout: wgpu::PipelineLayout,
    hybrid_ms_layout: wgpu::PipelineLayout,
    id_pipelines: HashMap<u32, wgpu::RenderPipeline>,
    layer_pipelines: HashMap<(wgpu::TextureFormat, u32), wgpu::RenderPipeline>,
    reflection_pipelines: HashMap<(wgpu::TextureFormat, u32), wgpu::RenderPipeline>,
    hybrid_pipelines: HashMap<(wgpu::TextureFormat, u32), wgpu::RenderPipeline>,
    resolve: ResolvePipelines,
}

const POSITION_LAYOUT: wgpu::VertexBufferLayout<'static> = wgpu::VertexBufferLayout {
    array_stride: 12,
    step_mode: wgpu::VertexStepMode::Vertex,
    attributes: &[wgpu::VertexAttribute {
        format: wgpu::VertexFormat::Float32x3,
        offset: 0,
        shader_location: 0,
    }],
};
const UV_LAYOUT: wgpu::VertexBufferLayout<'static> = wgpu::VertexBufferLayout {
    array_stride: 8,
    step_mode: wgpu::VertexStepMode::Vertex,
    attributes: &[wgpu::VertexAttribute {
        format: wgpu::VertexFormat::Float32x2,
        offset: 0,
        shader_location: 1,
    }],
};
const NORMAL_LAYOUT: wgpu::VertexBufferLayout<'static> = wgpu::VertexBufferLayout {
    array_stride: 12,
    step_mode: wgpu::VertexStepMode::Vertex,
    attributes: &[wgpu::VertexAttribute {
        format: wgpu::VertexFormat::Float32x3,
        offset: 0,
        shader_location: 2,
    }],
};
/// A cube map as `frame_reflection.wgsl` reads it: a 2D array read with `textureLoad`.
const CUBE: wgpu::BindingType = wgpu::BindingType::Texture {
    sample_type: wgpu::TextureSampleType::Float { filterable: false },
    view_dimension: wgpu::TextureViewDimension::D2Array,
    multisampled: false,
};

fn entry(
    binding: u32,
    visibility: wgpu::ShaderStages,
    ty: wgpu::BindingType,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry { binding, visibility, ty, count: None }
}

const UNIFORM: wgpu::BindingType = wgpu::BindingType::Buffer {
    ty: wgpu::BufferBindingType::Uniform,
    has_dynamic_offset: false,
    min_binding_size: None,
};

/// `count` samples per pixel, every sample written.
fn multisample(count: u32) -> wgpu::MultisampleState {
    wgpu::MultisampleState { count, mask: !0, alpha_to_coverage_enabled: false }
}

/// The additive pass's colour target: colour adds, alpha (coverage) takes the maximum.
fn additive_target(format: wgpu::TextureFormat) -> wgpu::ColorTargetState {
    let add = wgpu::BlendComponent {
        src_factor: wgpu::BlendFactor::One,
        dst_factor: wgpu::BlendFactor::One,
        operation: wgpu::BlendOperation::Add,
    };
    let max = wgpu::BlendComponent {
        src_factor: wgpu::BlendFactor::One,
        dst_factor: wgpu::BlendFactor::One,
        operation: wgpu::BlendOperation::Max,
    };
    wgpu::ColorTargetState {
        format,
        blend: Some(wgpu::BlendState { color: add, alpha: max }),
        write_mask: wgpu::ColorWrites::ALL,
    }
}

/// An additive pipeline of the frame's layer pass: `module`'s vertex entry point with its
/// vertex buffers, fragment entry point `fragment`, triangles unculled, tested against the id
/// pass's depth without writing it, colour added ([`additive_target`]).
#[allow(clippy::too_many_arguments)]
fn additive_pipeline(
    gpu: &Gpu,
    label: &str,
    layout: &wgpu::PipelineLayout,
    module: &wgpu::ShaderModule,
    vertex: (&str, &[Option<wgpu::VertexBufferLayout>]),
    fragment: &str,
    format: wgpu::TextureFormat,
    samples: u32,
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
            entry_point: Some(fragment),
            compilation_options: Default::default(),
            targets: &[Some(additive_target(format))],
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

impl FramePipelines {
    pub fn new(gpu: &Gpu) -> FramePipelines {
        let d = &gpu.device;
        let module = d.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("frame.wgsl"),
            source: wgpu::ShaderSource::Wgsl(SHADER.into()),
        });
        let reflection_source = format!("{SHELL_FUNCTIONS}\n{REFLECTION}");
        let reflection_module = d.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("frame_reflection.wgsl"),
            source: wgpu::ShaderSource::Wgsl(reflection_source.into()),
        });
        let hybrid_source = format!("{SHELL_FUNCTIONS}\n{HYBRID_FRAME}");
        let hybrid_module = d.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("frame_hybrid.wgsl"),
            source: wgpu::ShaderSource::Wgsl(hybrid_source.into()),
        });
        let vf = wgpu::ShaderStages::VERTEX_FRAGMENT;
        let uniform_layout = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("frame uniforms"),
            entries: &[entry(0, vf, UNIFORM)],
        });
        let draw_layout = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("frame layer"),
            entries: &[
                entry(0, vf, UNIFORM),
                entry(
                    1,
                    wgpu::ShaderStages::FRAGMENT,
                    wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: true },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                ),
                entry(
                    2,
                    wgpu::ShaderStages::FRAGMENT,
                    wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                ),
            ],
        });
        let fragment = wgpu::ShaderStages::FRAGMENT;
        let reflection_draw_layout = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("frame reflection"),
            entries: &[entry(0, vf, UNIFORM), entry(1, fragment, CUBE), entry(2, fragment, CUBE)],
        });
        let hybrid_entries: Vec<wgpu::BindGroupLayoutEntry> =
            std::iter::once(entry(0, vf, UNIFORM))
                .chain((0..MAX_LENS_SHELLS).map(|k| entry(k as u32 + 1, fragment, CUBE)))
                .collect();
        let hybrid_draw_layout = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("frame lens term"),
            entries: &hybrid_entries,
        });
        let ids_entry = |binding, multisampled| {
            entry(
                binding,
                wgpu::ShaderStages::FRAGMENT,
                wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Uint,
                    view_dimension: wgpu::TextureViewDimension::D2,
                    multisampled,
                },
            )
        };
        let ids_layout = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("frame ids"),
            entries: &[ids_entry(0, false)],
        });
        let ids_ms_layout = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("frame ids per sample"),
            entries: &[ids_entry(1, true)],
        });
        let id_layout = d.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("frame ids"),
            bind_group_layouts: &[Some(&uniform_layout)],
            immediate_size: 0,
        });
        let layer_layout = d.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("frame layers"),
            bind_group_layouts: &[Some(&draw_layout), Some(&ids_layout)],
            immediate_size: 0,
        });
        let layer_ms_layout = d.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("frame layers per sample"),
            bind_group_layouts: &[Some(&draw_layout), Some(&ids_ms_layout)],
            immediate_size: 0,
        });
        let reflection_layout = d.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("frame reflections"),
            bind_group_layouts: &[Some(&reflection_draw_layout), Some(&ids_layout)],
            immediate_size: 0,
        });
        let reflection_ms_layout = d.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("frame reflections per sample"),
            bind_group_layouts: &[Some(&reflection_draw_layout), Some(&ids_ms_layout)],
            immediate_size: 0,
        });
        let hybrid_layout = d.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("frame lens terms"),
            bind_group_layouts: &[Some(&hybrid_draw_layout), Some(&ids_layout)],
            immediate_size: 0,
        });
        let hybrid_ms_layout = d.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("frame lens terms per sample"),
            bind_group_layouts: &[Some(&hybrid_draw_layout), Some(&ids_ms_layout)],
            immediate_size: 0,
        });
        let mut pipes = FramePipelines {
            module,
            reflection_module,
            hybrid_module,
            uniform_layout,
            draw_layout,
            reflection_draw_layout,
            hybrid_draw_layout,
            ids_layout,
            ids_ms_layout,
            id_layout,
            layer_layout,
            layer_ms_layout,
            reflection_layout,
            reflection_ms_layout,
            hybrid_layout,
            hybrid_ms_layout,
            id_pipelines: HashMap::new(),
            layer_pipelines: HashMap::new(),
            reflection_pipelines: HashMap::new(),
            hybrid_pipelines: HashMap::new(),
            resolve: ResolvePipelines::new(gpu),
        };
        pipes.id_pipeline(gpu, 1);
        pipes
    }

    /// The object-index and depth pipeline for `samples` per pixel (compiled on first use).
    pub fn id_pipeline(&mut self, gpu: &Gpu, samples: u32) -> &wgpu::RenderPipeline {
        let (module, layout) = (&self.module, &self.id_layout);
        self.id_pipelines.entry(samples).or_insert_with(|| {
            gpu.device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("frame ids"),
                layout: Some(layout),
                vertex: wgpu::VertexState {
                    module,
                    entry_point: Some("vs_main"),
                    compilation_options: Default::default(),
                    buffers: &[Some(POSITION_LAYOUT), Some(UV_LAYOUT)],
                },
                primitive: wgpu::PrimitiveState {
                    topology: wgpu::PrimitiveTopology::TriangleList,
                    cull_mode: None,
                    ..Default::default()
                },
                depth_stencil: Some(wgpu::DepthStencilState {
                    format: DEPTH_FORMAT,
                    depth_write_enabled: Some(true),
                    depth_compare: Some(wgpu::CompareFunction::Less),
                    stencil: Default::default(),
                    bias: Default::default(),
                }),
                multisample: multisample(samples),
                fragment: Some(wgpu::FragmentState {
                    module,
                    entry_point: Some("fs_id"),
                    compilation_options: Default::default(),
                    targets: &[Some(wgpu::ColorTargetState {
                        format: ID_FORMAT,
                        blend: None,
                        write_mask: wgpu::ColorWrites::ALL,
                    })],
                }),
                multiview_mask: None,
                cache: None,
            })
        })
    }

    /// The additive layer pipeline for a target format and `samples` per pixel (compiled on
    /// first use): `fs_layer`, or `fs_layer_ms` with object indices per sample.
    pub fn layer_pipeline(
        &mut self,
        gpu: &Gpu,
        format: wgpu::TextureFormat,
        samples: u32,
    ) -> &wgpu::RenderPipeline {
        let module = &self.module;
        let (layout, entry_point) = if samples > 1 {
            (&self.layer_ms_layout, "fs_layer_ms")
        } else {
            (&self.layer_layout, "fs_layer")
        };
        self.layer_pipelines.entry((format, samples)).or_insert_with(|| {
            additive_pipeline(
                gpu,
                "frame layers",
                layout,
                module,
                ("vs_main", &[Some(POSITION_LAYOUT), Some(UV_LAYOUT)]),
                entry_point,
                format,
                samples,
            )
        })
    }

    /// The additive reflection-term pipeline for a target format and `samples` per pixel
    /// (compiled on first use): `fs_reflection`, or `fs_reflection_ms` with object indices
    /// per sample; positions and normals as vertex buffers 0 and 1.
    pub fn reflection_pipeline(
        &mut self,
        gpu: &Gpu,
        format: wgpu::TextureFormat,
        samples: u32,
    ) -> &wgpu::RenderPipeline {
        let module = &self.reflection_module;
        let (layout, entry_point) = if samples > 1 {
            (&self.reflection_ms_layout, "fs_reflection_ms")
        } else {
            (&self.reflection_layout, "fs_reflection")
        };
        self.reflection_pipelines.entry((format, samples)).or_insert_with(|| {
            additive_pipeline(
                gpu,
                "frame reflections",
                layout,
                module,
                ("vs_reflection", &[Some(POSITION_LAYOUT), Some(NORMAL_LAYOUT)]),
                entry_point,
                format,
                samples,
            )
        })
    }

    /// The additive lens-term pipeline for a target format and `samples` per pixel
    /// (compiled on first use): `fs_hybrid_frame`, or `fs_hybrid_frame_ms` with object
    /// indices per sample; the corners ([`LENS_CORNER_LAYOUT`]) as vertex buffer 0.
    pub fn hybrid_pipeline(
        &mut self,
        gpu: &Gpu,
        format: wgpu::TextureFormat,
        samples: u32,
    ) -> &wgpu::RenderPipeline {
        let module = &self.hybrid_module;
        let (layout, entry_point) = if samples > 1 {
            (&self.hybrid_ms_layout, "fs_hybrid_frame_ms")
        } else {
            (&self.hybrid_layout, "fs_hybrid_frame")
        };
        self.hybrid_pipelines.entry((format, samples)).or_insert_with(|| {
            additive_pipeline(
                gpu,
                "frame lens terms",
                layout,
                module,
                ("vs_hybrid_frame", &[Some(LENS_CORNER_LAYOUT)]),
                entry_point,
                format,
                samples,
            )
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

/// The multisampled attachments of a frame drawn with more than one sample per pixel: object
/// indices and depth per sample, and colour attachments resolved into the frame's target:
/// per target format for the hardware resolve, in the offscreen format (kept, for the shader
/// to read) for the display-filter resolve.
struct SampleTargets {
    ids: wgpu::Texture,
    depth: wgpu::Texture,
    ids_bind: wgpu::BindGroup,
    /// Keyed by format and whether the display-filter resolve reads it.
    colour: HashMap<(wgpu::TextureFormat, bool), wgpu::Texture>,
    /// The display-filter resolve's per-pixel shared object index (made on first use).
    shared_ids: Option<wgpu::Texture>,
}

/// The per-size targets: object indices (one per pixel, at its centre), depth, the offscreen
/// colour target, and with `samples` > 1 the multisampled attachments.
pub struct Targets {
    pub size: (u32, u32),
    pub samples: u32,
    pub ids: wgpu::Texture,
    pub depth: wgpu::Texture,
    pub colour: wgpu::Texture,
    ids_bind: wgpu::BindGroup,
    multi: Option<SampleTargets>,
}

fn target_texture(
    gpu: &Gpu,
    label: &str,
    size: (u32, u32),
    samples: u32,
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> wgpu::Texture {
    gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d { width: size.0, height: size.1, depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: samples,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage,
        view_formats: &[],
    })
}

impl Targets {
    /// Targets of `size` for frames of `samples` per pixel (1, or a count
    /// [`crate::multisample::choose`] found supported).
    pub fn new(
        gpu: &Gpu,
        pipes: &FramePipelines,
        size: (u32, u32),
        samples: u32,
    ) -> Result<Targets, PlayError> {
        let limit = gpu.limits.max_texture_dimension_2d;
        if size.0 == 0 || size.1 == 0 || size.0 > limit || size.1 > limit {
            return Err(PlayError::TargetSize { width: size.0, height: size.1, limit });
        }
        let attach = wgpu::TextureUsages::RENDER_ATTACHMENT;
        let ids = target_texture(
            gpu,
            "object ids",
            size,
            1,
            ID_FORMAT,
            attach | wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_SRC,
        );
        let depth = target_texture(gpu, "depth", size, 1, DEPTH_FORMAT, attach);
        let colour = target_texture(
            gpu,
            "frame",
            size,
            1,
            offscreen_format(gpu),
            attach | wgpu::TextureUsages::COPY_SRC,
        );
        let bind = |texture: &wgpu::Texture, layout, binding| {
            let view = texture.create_view(&Default::default());
            gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("object ids"),
                layout,
                entries: &[wgpu::BindGroupEntry {
                    binding,
                    resource: wgpu::BindingResource::TextureView(&view),
                }],
            })
        };
        let ids_bind = bind(&ids, &pipes.ids_layout, 0);
        let multi = (samples > 1).then(|| {
            let ids = target_texture(
                gpu,
                "object ids per sample",
                size,
                samples,
                ID_FORMAT,
                attach | wgpu::TextureUsages::TEXTURE_BINDING,
            );
            let depth =
                target_texture(gpu, "depth per sample", size, samples, DEPTH_FORMAT, attach);
            let ids_bind = bind(&ids, &pipes.ids_ms_layout, 1);
            SampleTargets { ids, depth, ids_bind, colour: HashMap::new(), shared_ids: None }
        });
        Ok(Targets { size, samples, ids, depth, colour, ids_bind, multi })
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
        cut: [0.0; 4],
    };
    if let Some(l) = layer {
        let [a, b, c, d, e, f] = l.transform.values;
        let layout = l.texture.layout;
        let (aw, ah) = allocated_size(&layout);
        u.affine_abcd = [a, b, c, d];
        u.affine_ef = [e, f];
        u.size = [layout.width as f32, layout.height as f32];
        u.scale = [layout.width as f32 / aw as f32, layout.height as f32 / ah as f32];
        u.max_level = l.max_level;
        u.weight = l.weight;
        u.anisotropic = l.anisotropic as u32;
        u.cut = cut_uniform(&l.transform);
    }
    u
}

/// The object-index pass: clears `ids` and `depth`, then draws every object's index and
/// depth, nearest surface winning.
fn id_pass(
    pipeline: &wgpu::RenderPipeline,
    ids: &wgpu::Texture,
    depth: &wgpu::Texture,
    objects: &[ObjectDraw],
    binds: &[wgpu::BindGroup],
    encoder: &mut wgpu::CommandEncoder,
) {
    let ids_view = ids.create_view(&Default::default());
    let depth_view = depth.create_view(&Default::default());
    let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("object ids"),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view: &ids_view,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load: wgpu::LoadOp::Clear(wgpu::Color {
                    r: NO_OBJECT as f64,
                    g: 0.0,
                    b: 0.0,
                    a: 0.0,
                }),
                store: wgpu::StoreOp::Store,
            },
        })],
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
    pass.set_pipeline(pipeline);
    for (o, bg) in objects.iter().zip(binds) {
        pass.set_bind_group(0, bg, &[]);
        pass.set_vertex_buffer(0, o.mesh.positions.slice(..));
        pass.set_vertex_buffer(1, o.mesh.uvs.slice(..));
        pass.set_index_buffer(o.mesh.indices.slice(..), wgpu::IndexFormat::Uint32);
        pass.draw_indexed(0..o.mesh.count, 0, 0..1);
    }
}

/// Records a frame into `encoder`: clears `colour` (format `format`, size `targets.size`) to
/// transparent black, then draws with `targets.samples` per pixel (multisampled frames are
/// drawn into the sample attachments and resolved into `colour`: with `display`, the
/// ray-traced set's display filter, by the display-filter resolve over each pixel's 3×3
/// neighbourhood, the samples drawn in the offscreen format; without, by the hardware's
/// average of each pixel's own samples). `object_ids`: also leave every pixel's object index
/// at its centre in `targets.ids` (single-sample frames always do; multisampled ones draw one
/// more index pass for it). Single-sample frames ignore `display`. The additive pass draws
/// `layers`, then `reflections` (a draw without shells draws nothing).
#[allow(clippy::too_many_arguments)]
pub fn encode(
    gpu: &Gpu,
    pipes: &mut FramePipelines,
    targets: &mut Targets,
    colour: &wgpu::TextureView,
    format: wgpu::TextureFormat,
    objects: &[ObjectDraw],
    layers: &[LayerDraw],
    reflections: &[ReflectionDraw],
    lenses: &[LensDraw],
    object_ids: bool,
    display: Option<pis_format::DisplayFilter>,
    encoder: &mut wgpu::CommandEncoder,
) {
    let d = &gpu.device;
    let samples = targets.samples;
    // The display filter applies to multisampled frames; their samples are then drawn in
    // the offscreen (float) format, whatever the target's.
    let display = display.filter(|_| samples > 1);
    let sample_format = if display.is_some() { offscreen_format(gpu) } else { format };
    pipes.id_pipeline(gpu, samples);
    pipes.layer_pipeline(gpu, sample_format, samples);
    let reflections: Vec<&ReflectionDraw> =
        reflections.iter().filter(|r| !r.shells.is_empty()).collect();
    if !reflections.is_empty() {
        pipes.reflection_pipeline(gpu, sample_format, samples);
    }
    let lenses: Vec<&LensDraw> =
        lenses.iter().filter(|l| !l.shells.is_empty() && l.count > 0).collect();
    if !lenses.is_empty() {
        pipes.hybrid_pipeline(gpu, sample_format, samples);
    }
    let lens_binds: Vec<wgpu::BindGroup> =
        lenses.iter().map(|l| lens_bind(gpu, &pipes.hybrid_draw_layout, l)).collect();
    let ubuf = |u: Uniforms| {
        d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("frame uniforms"),
            contents: bytemuck::bytes_of(&u),
            usage: wgpu::BufferUsages::UNIFORM,
        })
    };
    let id_binds: Vec<wgpu::BindGroup> = objects
        .iter()
        .map(|o| {
            let b = ubuf(uniforms(o.clip_from_object, o.object, None));
            d.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("object id"),
                layout: &pipes.uniform_layout,
                entries: &[wgpu::BindGroupEntry { binding: 0, resource: b.as_entire_binding() }],
            })
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
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: wgpu::BindingResource::TextureView(&l.texture.view),
                    },
                    wgpu::BindGroupEntry {
                        binding: 2,
                        resource: wgpu::BindingResource::Sampler(l.sampler),
                    },
                ],
            })
        })
        .collect();
    // Per reflection term: the bind group of its whole shell stack and, where the mesh has
    // hull triangles and the term more than one shell, the bind group of its most distant
    // shell alone (thesis 5.7: hull polygons never see the object itself).
    let reflection_binds: Vec<(wgpu::BindGroup, Option<wgpu::BindGroup>)> = reflections
        .iter()
        .map(|r| {
            let o = &objects[r.draw];
            let hull = (o.mesh.hull > 0 && r.shells.len() > 1).then(|| {
                reflection_bind(
                    gpu,
                    &pipes.reflection_draw_layout,
                    o,
                    r,
                    &r.shells[r.shells.len() - 1..],
                )
            });
            (reflection_bind(gpu, &pipes.reflection_draw_layout, o, r, &r.shells), hull)
        })
        .collect();
    let size = targets.size;
    // The attachments the layers are drawn into: (colour, resolve target, depth, ids).
    let (sample_colour, depth, ids_bind) = match &mut targets.multi {
        Some(m) => {
            let usage = if display.is_some() {
                wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING
            } else {
                wgpu::TextureUsages::RENDER_ATTACHMENT
            };
            let c = m.colour.entry((sample_format, display.is_some())).or_insert_with(|| {
                target_texture(gpu, "frame per sample", size, samples, sample_format, usage)
            });
            id_pass(&pipes.id_pipelines[&samples], &m.ids, &m.depth, objects, &id_binds, encoder);
            if object_ids {
                id_pass(
                    &pipes.id_pipelines[&1],
                    &targets.ids,
                    &targets.depth,
                    objects,
                    &id_binds,
                    encoder,
                );
            }
            (Some(c.create_view(&Default::default())), &m.depth, &m.ids_bind)
        }
        None => {
            id_pass(
                &pipes.id_pipelines[&1],
                &targets.ids,
                &targets.depth,
                objects,
                &id_binds,
                encoder,
            );
            (None, &targets.depth, &targets.ids_bind)
        }
    };
    let depth_view = depth.create_view(&Default::default());
    // Multisampled: the samples are resolved into `colour` by the hardware and then not
    // kept, or kept for the display-filter resolve.
    let (view, resolve_target, store) = match (&sample_colour, display) {
        (Some(v), None) => (v, Some(colour), wgpu::StoreOp::Discard),
        (Some(v), Some(_)) => (v, None, wgpu::StoreOp::Store),
        (None, _) => (colour, None, wgpu::StoreOp::Store),
    };
    let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("layers"),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view,
            depth_slice: None,
            resolve_target,
            ops: wgpu::Operations { load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT), store },
        })],
        depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
            view: &depth_view,
            depth_ops: Some(wgpu::Operations {
                load: wgpu::LoadOp::Load,
                store: if sample_colour.is_some() {
                    wgpu::StoreOp::Discard
                } else {
                    wgpu::StoreOp::Store
                },
            }),
            stencil_ops: None,
        }),
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    });
    pass.set_pipeline(&pipes.layer_pipelines[&(sample_format, samples)]);
    pass.set_bind_group(1, ids_bind, &[]);
    for (l, bg) in layers.iter().zip(&layer_binds) {
        let m = objects[l.draw].mesh;
        pass.set_bind_group(0, bg, &[]);
        pass.set_vertex_buffer(0, m.positions.slice(..));
        pass.set_vertex_buffer(1, m.uvs.slice(..));
        pass.set_index_buffer(m.indices.slice(..), wgpu::IndexFormat::Uint32);
        pass.draw_indexed(0..m.count, 0, 0..1);
    }
    if !reflections.is_empty() {
        pass.set_pipeline(&pipes.reflection_pipelines[&(sample_format, samples)]);
        pass.set_bind_group(1, ids_bind, &[]);
        for (r, (all, hull)) in reflections.iter().zip(&reflection_binds) {
            let m = objects[r.draw].mesh;
            pass.set_vertex_buffer(0, m.positions.slice(..));
            pass.set_vertex_buffer(1, m.normals.slice(..));
            pass.set_index_buffer(m.indices.slice(..), wgpu::IndexFormat::Uint32);
            let rest = match hull {
                Some(bg) => {
                    pass.set_bind_group(0, bg, &[]);
                    pass.draw_indexed(0..m.hull, 0, 0..1);
                    m.hull
                }
                None => 0,
            };
            pass.set_bind_group(0, all, &[]);
            pass.draw_indexed(rest..m.count, 0, 0..1);
        }
    }
    if !lenses.is_empty() {
        pass.set_pipeline(&pipes.hybrid_pipelines[&(sample_format, samples)]);
        pass.set_bind_group(1, ids_bind, &[]);
        for (l, bg) in lenses.iter().zip(&lens_binds) {
            pass.set_bind_group(0, bg, &[]);
            pass.set_vertex_buffer(0, l.corners.slice(..));
            pass.draw(0..l.count, 0..1);
        }
    }
    drop(pass);
    if let (Some(filter), Some(m)) = (display, &mut targets.multi) {
        let shared = m.shared_ids.get_or_insert_with(|| {
            target_texture(
                gpu,
                "shared object ids",
                size,
                1,
                crate::resolve::SHARED_ID_FORMAT,
                wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            )
        });
        pipes.resolve.encode(
            gpu,
            filter,
            &m.colour[&(sample_format, true)],
            &m.ids,
            shared,
            colour,
            format,
            encoder,
        );
    }
}

/// Maps a buffer the GPU has been told to fill and returns its bytes.
pub fn map_read(gpu: &Gpu, buffer: &wgpu::Buffer) -> Result<Vec<u8>, PlayError> {
    let (tx, rx) = std::sync::mpsc::channel();
    buffer.slice(..).map_async(wgpu::MapMode::Read, move |r| {
        let _ = tx.send(r);
    });
    gpu.device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| PlayError::Readback(e.to_string()))?;
    rx.recv()
        .map_err(|e| PlayError::Readback(e.to_string()))?
        .map_err(|e| PlayError::Readback(e.to_string()))?;
    let bytes = buffer
        .slice(..)
        .get_mapped_range()
        .map_err(|e| PlayError::Readback(e.to_string()))?
        .to_vec();
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
        let buffer = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback"),
            size: row as u64 * size.1 as u64,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        Readback { buffer, row, texel_bytes, size }
    }

    pub fn copy(&self, texture: &wgpu::Texture, encoder: &mut wgpu::CommandEncoder) {
        encoder.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                texture,
                mip_level: 0,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            wgpu::TexelCopyBufferInfo {
                buffer: &self.buffer,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(self.row),
                    rows_per_image: Some(self.size.1),
                },
            },
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
        bytes
            .chunks_exact(2)
            .map(|b| half::f16::from_bits(u16::from_le_bytes([b[0], b[1]])).to_f32())
            .collect()
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
        for f in ["cut_uv", "texcoord", "texture_lod"] {
            assert_eq!(
                function(super::SHADER, f),
                function(crate::textured::SHADER, f),
                "{f} differs between frame.wgsl and textured.wgsl"
            );
        }
        assert_eq!(
            function(crate::shell::SHELL_FUNCTIONS, "texture_lod"),
            function(crate::textured::SHADER, "texture_lod"),
            "texture_lod differs between shell.wgsl and textured.wgsl"
        );
    }
}
