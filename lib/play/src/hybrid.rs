//! A lens object drawn by hybrid rendering on the GPU (`hybrid_object.wgsl`, thesis 6.4.2):
//! the frame's tessellation with one shell's cube vectors per corner, looked up with the
//! shell functions of `shell.wgsl` — the rendering that pis-compile's
//! `hybrid_render_matrix` predicts. Corners are not shared: each triangle's corners carry
//! the values [`pis_compile::hybrid::corner_values`] gives it.

use bytemuck::{Pod, Zeroable};
use glam::Mat4;
use pis_compile::hybrid::{corner_values, Missing, Tessellation};
use pis_compile::{TextureLayout, Viewport};
use wgpu::util::DeviceExt;

use crate::error::PlayError;
use crate::gpu::Gpu;
use crate::image::FloatImage;
use crate::shell::{check_viewport, object_pipelines, ShellTexture};
use crate::textured::{DEPTH_FORMAT, TARGET_FORMAT};

/// The hybrid pipeline's entry points.
pub const HYBRID_OBJECT: &str = include_str!("hybrid_object.wgsl");

/// `HybridUniforms` of `hybrid_object.wgsl` (80 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct HybridUniforms {
    clip_from_world: [f32; 16],
    size: u32,
    levels: u32,
    _pad: [u32; 2],
}

/// The compiled hybrid pipeline and its depth-only pass.
pub struct HybridPipeline {
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::RenderPipeline,
    depth_pipeline: wgpu::RenderPipeline,
}

impl HybridPipeline {
    pub fn new(gpu: &Gpu) -> HybridPipeline {
        let (layout, pipeline, depth_pipeline) = object_pipelines(
            gpu,
            "hybrid_object.wgsl",
            HYBRID_OBJECT,
            ("vs_hybrid", "fs_hybrid"),
            ("vs_hybrid_depth", "fs_hybrid_depth"),
            false,
        );
        HybridPipeline { layout, pipeline, depth_pipeline }
    }
}

/// Draws the tessellation `tess` (world positions, `clip_from_world`) with one shell's cube
/// map (its layout, and 4 values per texel: RGBA) looked up along the per-vertex cube
/// vectors `vectors` of one term; returns RGBA per pixel (rows from the top), alpha 1 where the
/// term is drawn. Triangles without the term write depth only.
pub fn render_hybrid(
    gpu: &Gpu,
    pipeline: &HybridPipeline,
    viewport: Viewport,
    tess: &Tessellation,
    clip_from_world: Mat4,
    vectors: &[Option<[f32; 3]>],
    (layout, rgba): (TextureLayout, &[f32]),
) -> Result<FloatImage, PlayError> {
    check_viewport(gpu, viewport)?;
    if vectors.len() != tess.vertices.len() {
        return Err(PlayError::Request(format!(
            "{} cube vectors for {} vertices",
            vectors.len(),
            tess.vertices.len()
        )));
    }
    let cube = ShellTexture::new(gpu, layout, "lens object")?;
    cube.upload(gpu, rgba)?;
    let corners = corner_values(tess, vectors, Missing::Mean);
    let (mut drawn_p, mut drawn_v, mut hidden_p) = (Vec::new(), Vec::new(), Vec::new());
    for (t, c) in tess.triangles.iter().zip(&corners) {
        let p = t.map(|i| tess.vertices[i as usize].position.to_array());
        match c {
            Some(v) => {
                drawn_p.extend(p);
                drawn_v.extend(*v);
            }
            None => hidden_p.extend(p),
        }
    }
    let d = &gpu.device;
    let init = |label: &str, contents: &[u8], usage| {
        d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(label),
            contents,
            usage,
        })
    };
    let u = HybridUniforms {
        clip_from_world: clip_from_world.to_cols_array(),
        size: layout.width,
        levels: layout.levels,
        _pad: [0; 2],
    };
    let ub = init("uniforms", bytemuck::bytes_of(&u), wgpu::BufferUsages::UNIFORM);
    let bind = d.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("hybrid"),
        layout: &pipeline.layout,
        entries: &[
            wgpu::BindGroupEntry { binding: 0, resource: ub.as_entire_binding() },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: wgpu::BindingResource::TextureView(&cube.view),
            },
        ],
    });
    let pad = |v: &[[f32; 3]]| if v.is_empty() { vec![[0.0f32; 3]] } else { v.to_vec() };
    let (dp, dv, hp) = (
        init("positions", bytemuck::cast_slice(&pad(&drawn_p)), wgpu::BufferUsages::VERTEX),
        init("vectors", bytemuck::cast_slice(&pad(&drawn_v)), wgpu::BufferUsages::VERTEX),
        init("hidden", bytemuck::cast_slice(&pad(&hidden_p)), wgpu::BufferUsages::VERTEX),
    );
    let size =
        wgpu::Extent3d { width: viewport.width, height: viewport.height, depth_or_array_layers: 1 };
    let target = |label, format, usage| {
        d.create_texture(&wgpu::TextureDescriptor {
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
    let (color_view, depth_view) =
        (color.create_view(&Default::default()), depth.create_view(&Default::default()));
    let mut enc =
        d.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("hybrid") });
    {
        let mut pass = crate::gpu::cleared_pass(&mut enc, "hybrid", &color_view, &depth_view);
        pass.set_bind_group(0, &bind, &[]);
        pass.set_pipeline(&pipeline.depth_pipeline);
        pass.set_vertex_buffer(0, hp.slice(..));
        pass.draw(0..hidden_p.len() as u32, 0..1);
        pass.set_pipeline(&pipeline.pipeline);
        pass.set_vertex_buffer(0, dp.slice(..));
        pass.set_vertex_buffer(1, dv.slice(..));
        pass.draw(0..drawn_p.len() as u32, 0..1);
    }
    crate::image::read_back(gpu, enc, &color, viewport)
}
