//! The reflection term of an object (SPEC.md 9, thesis ch. 5) in the player's frame: the
//! uniforms and bind group of one draw that looks up the term's environment-map shells
//! (`reflection.wgsl`, appended to `shell.wgsl`), composites them "over" and
//! multiplies by the object's Fresnel factor. `encode.rs` encodes the draws.

use bytemuck::{Pod, Zeroable};
use wgpu::util::DeviceExt;

use super::draw::ObjectDraw;
use crate::gpu::Gpu;
use crate::shell::{shell_uniform, DepthTexture, ShellCode, ShellTexture};

/// The reflection term's entry points, appended to [`crate::shell::SHELL_FUNCTIONS`].
pub const REFLECTION: &str = include_str!("reflection.wgsl");
/// The most shells a reflection term draws in one pass (orders 0 and 1).
pub const MAX_TERM_SHELLS: usize = 2;

/// `ShellSlot` of `reflection.wgsl` (64 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct ShellSlot {
    origin_shape: [f32; 4],
    a: [f32; 4],
    b: [f32; 4],
    size_levels: [u32; 4],
}

/// `ReflectionUniforms` of `reflection.wgsl` (304 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct ReflectionUniforms {
    clip_from_object: [f32; 16],
    world_from_object: [f32; 16],
    eye: [f32; 4],
    f0_weight: [f32; 4],
    shells: [ShellSlot; MAX_TERM_SHELLS],
    object: u32,
    count: u32,
    _pad: [u32; 2],
}

/// One reflection term drawn on an object (SPEC.md 9, thesis ch. 5): its environment-map
/// shells at one parameter sample, with the sample's weight.
pub struct ReflectionDraw<'a> {
    /// Index into the frame's objects.
    pub draw: usize,
    /// The object's world transform (rigid): world positions and normals.
    pub world_from_object: glam::Mat4,
    /// The frame's camera position (world space).
    pub eye: glam::Vec3,
    /// The object's reflectance at normal incidence (Schlick's F0, linear RGB).
    pub f0: [f32; 3],
    /// Multilinear weight of this parameter sample.
    pub weight: f32,
    /// The term's shells in increasing order (order 0 nearest), each with its cube map:
    /// 1 to [`MAX_TERM_SHELLS`] (the player checks the count when it opens a file).
    pub shells: Vec<TermShell<'a>>,
}

impl ReflectionDraw<'_> {
    /// The code its pipeline needs (the hull draw's shells are some of the term's).
    pub fn code(&self) -> ShellCode {
        let code = |s: &TermShell| ShellCode::of(&s.shell.shape, s.lookups);
        self.shells.iter().map(code).fold(ShellCode::default(), ShellCode::union)
    }
}

/// One shell of a reflection term: its geometry, its lookups per pixel side (SPEC.md 8.2),
/// its cube map and, for a depth shell, its depth cube (SPEC.md 8.5).
#[derive(Clone)]
pub struct TermShell<'a> {
    pub shell: pis_compile::shell::Shell,
    pub lookups: u32,
    pub cube: &'a ShellTexture,
    pub depth: Option<&'a DepthTexture>,
}

/// The uniforms of a reflection term drawn on `object` with `shells` (the term's, or the
/// most distant alone on hull triangles).
fn reflection_uniforms(
    object: &ObjectDraw,
    r: &ReflectionDraw,
    shells_drawn: &[TermShell],
) -> ReflectionUniforms {
    let mut shells = [ShellSlot::zeroed(); MAX_TERM_SHELLS];
    for (slot, s) in shells.iter_mut().zip(shells_drawn) {
        let (origin_shape, a, b) = shell_uniform(&s.shell);
        *slot = ShellSlot {
            origin_shape,
            a,
            b,
            size_levels: [s.cube.layout.width, s.cube.layout.levels, s.lookups.max(1), 0],
        };
    }
    ReflectionUniforms {
        clip_from_object: object.clip_from_object.to_cols_array(),
        world_from_object: r.world_from_object.to_cols_array(),
        eye: [r.eye.x, r.eye.y, r.eye.z, 1.0],
        f0_weight: [r.f0[0], r.f0[1], r.f0[2], r.weight],
        shells,
        object: object.object,
        count: shells_drawn.len().min(MAX_TERM_SHELLS) as u32,
        _pad: [0; 2],
    }
}

/// The bind group of a reflection term drawn on `object` with `shells` (one or two of the
/// term's, in order): its uniforms, the cube maps of shells 0 and 1 (shell 0's twice for
/// one shell) and their depth cubes (`no_depth` for a shell of another shape).
pub fn reflection_bind(
    gpu: &Gpu,
    (layout, no_depth): (&wgpu::BindGroupLayout, &DepthTexture),
    object: &ObjectDraw,
    r: &ReflectionDraw,
    shells: &[TermShell],
) -> wgpu::BindGroup {
    let d = &gpu.device;
    let u = d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("reflection uniforms"),
        contents: bytemuck::bytes_of(&reflection_uniforms(object, r, shells)),
        usage: wgpu::BufferUsages::UNIFORM,
    });
    let shell = |k: usize| &shells[k.min(shells.len() - 1)];
    let cube = |k: usize| wgpu::BindingResource::TextureView(&shell(k).cube.view);
    let depth =
        |k: usize| wgpu::BindingResource::TextureView(&shell(k).depth.unwrap_or(no_depth).view);
    d.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("reflection"),
        layout,
        entries: &[
            wgpu::BindGroupEntry { binding: 0, resource: u.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 1, resource: cube(0) },
            wgpu::BindGroupEntry { binding: 2, resource: cube(1) },
            wgpu::BindGroupEntry { binding: 3, resource: depth(0) },
            wgpu::BindGroupEntry { binding: 4, resource: depth(1) },
        ],
    })
}

#[cfg(test)]
mod tests {
    #[test]
    fn reflection_uniforms_have_the_wgsl_layout() {
        // ShellSlot: 4 vec4s; ReflectionUniforms: 2 mat4x4, 2 vec4, 2 slots, 4 u32.
        assert_eq!(std::mem::size_of::<super::ShellSlot>(), 64);
        assert_eq!(std::mem::size_of::<super::ReflectionUniforms>(), 2 * 64 + 2 * 16 + 2 * 64 + 16);
    }
}
