//! What a frame draws: the objects' meshes on the GPU, the objects placed in the frame, and
//! the surface layers drawn on them; the object-index target's format. The rest of the frame
//! (pipelines, targets, the reflection and lens terms, the passes) builds on these.

use wgpu::util::DeviceExt;

use crate::gpu::Gpu;
use crate::textured::ObjectTexture;

/// The object-index target's format.
pub const ID_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Uint;
/// Object index of pixels no object covers.
pub const NO_OBJECT: u32 = u32::MAX;

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
    /// Composited over the opaque surfaces behind it (SPEC.md 9) rather than drawn as the
    /// nearest surface.
    pub translucent: bool,
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
    /// Per channel, a relightable layer's coefficient weight (SPEC.md 9); else 1.
    pub tint: [f32; 3],
    /// Anisotropic filtering: the lookup takes the derivatives, the sampler its clamp.
    pub anisotropic: bool,
    /// The texture's alpha is its translucent object's opacity (a 4-channel surface layer).
    pub opacity: bool,
}
