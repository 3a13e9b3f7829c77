//! The frame's pipelines (`frame.wgsl`, and `reflection.wgsl` and `hybrid.wgsl` appended to
//! `shell.wgsl`): the object-index and depth pass per sample count, and the additive passes
//! of surface layers, reflection terms and lens terms per target format and sample count,
//! each compiled on first use.

use std::collections::HashMap;

use super::additive::{additive_pipeline, multisample, POSITION_LAYOUT, UV_LAYOUT};
use super::draw::ID_FORMAT;
use super::hybrid::{HYBRID_FRAME, LENS_CORNER_LAYOUT, MAX_LENS_SHELLS};
use super::reflection::REFLECTION;
use super::resolve::ResolvePipelines;
use super::translucent::TranslucentPipelines;
use crate::gpu::Gpu;
use crate::shell::{DepthTexture, ShellCode, SHELL_FUNCTIONS};
use crate::textured::DEPTH_FORMAT;

/// The WGSL source: the texture math shared with `textured.wgsl` (`texture_lod.wgsl`,
/// `texture_transform.wgsl`, `texture_sample.wgsl`), then `frame.wgsl`.
pub const SHADER: &str = concat!(
    include_str!("../texture_lod.wgsl"),
    include_str!("../texture_transform.wgsl"),
    include_str!("../texture_sample.wgsl"),
    include_str!("frame.wgsl")
);

/// The frame's pipelines: object index and depth per sample count, and additive layers and
/// reflection terms per target format and sample count.
pub struct FramePipelines {
    pub(super) module: wgpu::ShaderModule,
    reflection_module: wgpu::ShaderModule,
    hybrid_module: wgpu::ShaderModule,
    pub(super) uniform_layout: wgpu::BindGroupLayout,
    pub(super) draw_layout: wgpu::BindGroupLayout,
    pub(super) reflection_draw_layout: wgpu::BindGroupLayout,
    pub(super) hybrid_draw_layout: wgpu::BindGroupLayout,
    pub(super) ids_layout: wgpu::BindGroupLayout,
    pub(super) ids_ms_layout: wgpu::BindGroupLayout,
    id_layout: wgpu::PipelineLayout,
    pub(super) layer_layout: wgpu::PipelineLayout,
    pub(super) layer_ms_layout: wgpu::PipelineLayout,
    reflection_layout: wgpu::PipelineLayout,
    reflection_ms_layout: wgpu::PipelineLayout,
    hybrid_layout: wgpu::PipelineLayout,
    hybrid_ms_layout: wgpu::PipelineLayout,
    pub(super) id_pipelines: HashMap<u32, wgpu::RenderPipeline>,
    pub(super) layer_pipelines: HashMap<(wgpu::TextureFormat, u32), wgpu::RenderPipeline>,
    pub(super) reflection_pipelines: HashMap<PipelineKey, wgpu::RenderPipeline>,
    pub(super) hybrid_pipelines: HashMap<PipelineKey, wgpu::RenderPipeline>,
    pub(super) resolve: ResolvePipelines,
    pub(super) translucent: TranslucentPipelines,
    /// The depth cube bound for a shell that is not a depth shell.
    pub(super) no_depth: DepthTexture,
}

/// A pipeline of shell lookups: the target's format, samples per pixel and the code its
/// draws need.
pub(super) type PipelineKey = (wgpu::TextureFormat, u32, ShellCode);

const NORMAL_LAYOUT: wgpu::VertexBufferLayout<'static> = wgpu::VertexBufferLayout {
    array_stride: 12,
    step_mode: wgpu::VertexStepMode::Vertex,
    attributes: &[wgpu::VertexAttribute {
        format: wgpu::VertexFormat::Float32x3,
        offset: 0,
        shader_location: 2,
    }],
};
/// A cube map as `reflection.wgsl` reads it: a 2D array read with `textureLoad`.
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

impl FramePipelines {
    pub fn new(gpu: &Gpu) -> FramePipelines {
        let d = &gpu.device;
        let module = d.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("frame/frame.wgsl"),
            source: wgpu::ShaderSource::Wgsl(SHADER.into()),
        });
        let reflection_source = format!("{SHELL_FUNCTIONS}\n{REFLECTION}");
        let reflection_module = d.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("frame/reflection.wgsl"),
            source: wgpu::ShaderSource::Wgsl(reflection_source.into()),
        });
        let hybrid_source = format!("{SHELL_FUNCTIONS}\n{HYBRID_FRAME}");
        let hybrid_module = d.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("frame/hybrid.wgsl"),
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
            entries: &[
                entry(0, vf, UNIFORM),
                entry(1, fragment, CUBE),
                entry(2, fragment, CUBE),
                entry(3, fragment, CUBE),
                entry(4, fragment, CUBE),
            ],
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
            translucent: TranslucentPipelines::default(),
            no_depth: DepthTexture::none(gpu),
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
                (entry_point, &[]),
                (additive_target(format), samples),
            )
        })
    }

    /// The additive reflection-term pipeline for a target format, `samples` per pixel and
    /// the code of the shells it draws (compiled on first use): `fs_reflection`, or
    /// `fs_reflection_ms` with object indices per sample; positions and normals as vertex
    /// buffers 0 and 1.
    pub fn reflection_pipeline(&mut self, gpu: &Gpu, key: PipelineKey) -> &wgpu::RenderPipeline {
        let (format, samples, code) = key;
        let module = &self.reflection_module;
        let (layout, entry_point) = if samples > 1 {
            (&self.reflection_ms_layout, "fs_reflection_ms")
        } else {
            (&self.reflection_layout, "fs_reflection")
        };
        self.reflection_pipelines.entry(key).or_insert_with(|| {
            additive_pipeline(
                gpu,
                "frame reflections",
                layout,
                module,
                ("vs_reflection", &[Some(POSITION_LAYOUT), Some(NORMAL_LAYOUT)]),
                (entry_point, &code.constants()),
                (additive_target(format), samples),
            )
        })
    }

    /// The additive lens-term pipeline for a target format, `samples` per pixel and the code
    /// of the shells it draws (compiled on first use): `fs_hybrid_frame`, or
    /// `fs_hybrid_frame_ms` with object indices per sample; the corners
    /// ([`LENS_CORNER_LAYOUT`]) as vertex buffer 0.
    pub fn hybrid_pipeline(&mut self, gpu: &Gpu, key: PipelineKey) -> &wgpu::RenderPipeline {
        let (format, samples, code) = key;
        let module = &self.hybrid_module;
        let (layout, entry_point) = if samples > 1 {
            (&self.hybrid_ms_layout, "fs_hybrid_frame_ms")
        } else {
            (&self.hybrid_layout, "fs_hybrid_frame")
        };
        self.hybrid_pipelines.entry(key).or_insert_with(|| {
            additive_pipeline(
                gpu,
                "frame lens terms",
                layout,
                module,
                ("vs_hybrid_frame", &[Some(LENS_CORNER_LAYOUT)]),
                (entry_point, &code.constants()),
                (additive_target(format), samples),
            )
        })
    }

    /// Compiles the translucent layers' pipeline and the composite for a target format and
    /// `samples` per pixel, where not compiled yet.
    pub fn translucent_pipelines(&mut self, gpu: &Gpu, format: wgpu::TextureFormat, samples: u32) {
        let layout = if samples > 1 { &self.layer_ms_layout } else { &self.layer_layout };
        self.translucent.compile(gpu, (&self.module, layout), format, samples);
    }
}
