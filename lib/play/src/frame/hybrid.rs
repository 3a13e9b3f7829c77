//! A lens object in the player's frame (SPEC.md 9, thesis 6.4): the frame's tessellation of
//! the object, traced on the workers ([`pis_compile::hybrid::tessellate`]), turned into one
//! vertex buffer per term — per corner its triangle's F·G and, per shell, the cube-map
//! vector of the outgoing ray — and drawn additively by `hybrid.wgsl` (appended to
//! `shell.wgsl`) once per term and parameter sample, the term's shells composited "over".
//! Both terms look up the same shells (a lens object's shells are stored in its refraction
//! term; SPEC.md 9). `encode.rs` encodes the draws.

use bytemuck::{Pod, Zeroable};
use pis_compile::hybrid::{
    corner_values, vertex_modulation, vertex_vectors, Missing, Term, Tessellation,
};
use pis_compile::shell::Shell;
use rayon::prelude::*;
use wgpu::util::DeviceExt;

use crate::gpu::Gpu;
use crate::shell::{ShellCode, ShellTexture};

/// The lens-term entry points, appended to [`crate::shell::SHELL_FUNCTIONS`].
pub const HYBRID_FRAME: &str = include_str!("hybrid.wgsl");
/// The most shells a lens object's term draws in one pass.
pub const MAX_LENS_SHELLS: usize = 4;

/// `HybridFrameUniforms` of `hybrid.wgsl` (160 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct HybridFrameUniforms {
    clip_from_world: [f32; 16],
    shells: [[u32; 4]; MAX_LENS_SHELLS],
    weight: [f32; 4],
    object: u32,
    count: u32,
    _pad: [u32; 2],
}

/// One corner of a drawn triangle as the vertex buffer holds it (88 bytes): world position,
/// F·G, and per shell slot the cube-map vector with w = 1 where the triangle draws the shell.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct LensCorner {
    pub position: [f32; 3],
    pub fg: [f32; 3],
    pub vectors: [[f32; 4]; MAX_LENS_SHELLS],
}

/// The vertex buffer layout of [`LensCorner`].
pub const LENS_CORNER_LAYOUT: wgpu::VertexBufferLayout<'static> = wgpu::VertexBufferLayout {
    array_stride: std::mem::size_of::<LensCorner>() as u64,
    step_mode: wgpu::VertexStepMode::Vertex,
    attributes: &[
        wgpu::VertexAttribute {
            format: wgpu::VertexFormat::Float32x3,
            offset: 0,
            shader_location: 0,
        },
        wgpu::VertexAttribute {
            format: wgpu::VertexFormat::Float32x3,
            offset: 12,
            shader_location: 1,
        },
        wgpu::VertexAttribute {
            format: wgpu::VertexFormat::Float32x4,
            offset: 24,
            shader_location: 2,
        },
        wgpu::VertexAttribute {
            format: wgpu::VertexFormat::Float32x4,
            offset: 40,
            shader_location: 3,
        },
        wgpu::VertexAttribute {
            format: wgpu::VertexFormat::Float32x4,
            offset: 56,
            shader_location: 4,
        },
        wgpu::VertexAttribute {
            format: wgpu::VertexFormat::Float32x4,
            offset: 72,
            shader_location: 5,
        },
    ],
};

/// The corners of the triangles of `tess` that draw `term`, with the cube vectors of
/// `shells` (at most [`MAX_LENS_SHELLS`]): a triangle draws the term where a corner has the
/// term's path (the others take F·G 0), and a shell where a corner's outgoing ray meets it
/// (the others take the mean vector), as pis-compile's `hybrid_pixels` and
/// `hybrid_render_matrix` draw it.
pub fn term_corners(tess: &Tessellation, term: Term, shells: &[Shell]) -> Vec<LensCorner> {
    let fg = corner_values(tess, &vertex_modulation(tess, term), Missing::Zero);
    let vectors: Vec<Vec<Option<[[f32; 3]; 3]>>> = shells
        .iter()
        .take(MAX_LENS_SHELLS)
        .map(|s| corner_values(tess, &vertex_vectors(tess, term, s), Missing::Mean))
        .collect();
    tess.triangles
        .par_iter()
        .enumerate()
        .filter_map(|(t, tri)| fg[t].map(|f| (t, tri, f)))
        .flat_map_iter(|(t, tri, f)| {
            let vectors = &vectors;
            (0..3).map(move |c| {
                let mut v = [[0.0f32; 4]; MAX_LENS_SHELLS];
                for (k, vs) in vectors.iter().enumerate() {
                    if let Some(x) = vs[t] {
                        v[k] = [x[c][0], x[c][1], x[c][2], 1.0];
                    }
                }
                LensCorner {
                    position: tess.vertices[tri[c] as usize].position.to_array(),
                    fg: f[c],
                    vectors: v,
                }
            })
        })
        .collect()
}

/// One term of a lens object drawn at one parameter sample.
pub struct LensDraw<'a> {
    /// The object's index in the file (the id pass's).
    pub object: u32,
    pub clip_from_world: glam::Mat4,
    pub weight: f32,
    /// The term's corners ([`term_corners`]) on the GPU, and how many.
    pub corners: &'a wgpu::Buffer,
    pub count: u32,
    /// The term's shells in order, each its cube map and its lookups per pixel side
    /// (SPEC.md 8.2; 1 to [`MAX_LENS_SHELLS`] shells).
    pub shells: Vec<(&'a ShellTexture, u32)>,
}

impl LensDraw<'_> {
    /// The code its pipeline needs: a lens term's shells are looked up along the vectors of
    /// its corners, never marched.
    pub fn code(&self) -> ShellCode {
        ShellCode { depth: false, sub_pixel: self.shells.iter().any(|(_, k)| *k > 1) }
    }
}

/// The corners on the GPU (at least one corner's worth of bytes).
pub fn corner_buffer(gpu: &Gpu, corners: &[LensCorner]) -> wgpu::Buffer {
    let empty = [LensCorner::zeroed()];
    let bytes: &[u8] = bytemuck::cast_slice(if corners.is_empty() { &empty } else { corners });
    gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("lens corners"),
        contents: bytes,
        usage: wgpu::BufferUsages::VERTEX,
    })
}

/// The bind group of one lens draw: its uniforms and its shells' cube maps (the last
/// repeated in the unused slots).
pub fn lens_bind(gpu: &Gpu, layout: &wgpu::BindGroupLayout, draw: &LensDraw) -> wgpu::BindGroup {
    let d = &gpu.device;
    let mut shells = [[0u32; 4]; MAX_LENS_SHELLS];
    for (slot, (cube, lookups)) in shells.iter_mut().zip(&draw.shells) {
        *slot = [cube.layout.width, cube.layout.levels, (*lookups).max(1), 0];
    }
    let u = HybridFrameUniforms {
        clip_from_world: draw.clip_from_world.to_cols_array(),
        shells,
        weight: [draw.weight, 0.0, 0.0, 0.0],
        object: draw.object,
        count: draw.shells.len().min(MAX_LENS_SHELLS) as u32,
        _pad: [0; 2],
    };
    let ub = d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("lens uniforms"),
        contents: bytemuck::bytes_of(&u),
        usage: wgpu::BufferUsages::UNIFORM,
    });
    let cube = |k: usize| {
        wgpu::BindingResource::TextureView(&draw.shells[k.min(draw.shells.len() - 1)].0.view)
    };
    let mut entries = vec![wgpu::BindGroupEntry { binding: 0, resource: ub.as_entire_binding() }];
    entries.extend(
        (0..MAX_LENS_SHELLS)
            .map(|k| wgpu::BindGroupEntry { binding: k as u32 + 1, resource: cube(k) }),
    );
    d.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("lens term"),
        layout,
        entries: &entries,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lens_structs_have_the_wgsl_layout() {
        assert_eq!(std::mem::size_of::<HybridFrameUniforms>(), 64 + 64 + 16 + 16);
        assert_eq!(std::mem::size_of::<LensCorner>(), 88);
        assert_eq!(LENS_CORNER_LAYOUT.attributes.last().map(|a| a.offset + 16), Some(88));
    }
}
