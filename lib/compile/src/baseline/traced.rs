//! Ray tracing directly into texture maps (thesis 3.3): rays from the eye through the
//! object points under the centres of a 3× supersampled texel grid, the radiance written
//! into the sub-texels, then down-sampled with a separable Lanczos-windowed sinc of
//! half-width 6 sub-texels (2 lobes of the output grid). Front- or back-facing does not
//! matter (thesis 3.6); sub-texels on no triangle are filled by boundary reflection. MIP
//! levels by decimation.

use glam::{Mat4, Vec3};

use super::hole_fill::fill_by_reflection;
use super::lanczos::decimate;
use super::texel_map::map_texels;
use super::with_mip_levels;
use crate::transform::{DrawMesh, TextureTransform, Viewport};
use crate::{CompileError, TextureLayout};

/// Supersampling factor per texel dimension (thesis 3.6).
pub const SUPERSAMPLING: u32 = 3;

/// One ray to trace: from `origin` along the unit `direction`; the object point it aims at
/// lies at distance `distance`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TexelRay {
    pub origin: Vec3,
    pub direction: Vec3,
    pub distance: f32,
}

/// The traced texture (n_t × 3). `world_from_object` places the mesh, `eye` is the camera
/// position; `trace` returns the object's radiance seen along each ray (the tracer).
pub fn trace_into_texture(
    mesh: &DrawMesh,
    transform: &TextureTransform,
    world_from_object: Mat4,
    eye: Vec3,
    layout: &TextureLayout,
    trace: impl FnOnce(&[TexelRay]) -> Vec<[f32; 3]>,
) -> Result<Vec<f32>, CompileError> {
    let (w, h) = (layout.width * SUPERSAMPLING, layout.height * SUPERSAMPLING);
    // The viewport only matters for screen positions, which are not used here.
    let points = map_texels(mesh, transform, Viewport { width: 1, height: 1 }, w, h);
    let mut rays = Vec::new();
    let mut slot = Vec::new();
    for (k, p) in points.iter().enumerate() {
        let Some(p) = p else { continue };
        let world = world_from_object.transform_point3(p.object);
        let d = world - eye;
        let distance = d.length();
        if distance > 0.0 && distance.is_finite() {
            rays.push(TexelRay { origin: eye, direction: d / distance, distance });
            slot.push(k);
        }
    }
    let radiance = trace(&rays);
    if radiance.len() != rays.len() {
        return Err(CompileError::Size {
            what: "traced radiance".into(),
            expected: rays.len(),
            found: radiance.len(),
        });
    }
    let mut fine = vec![0.0f32; w as usize * h as usize * 3];
    let mut defined = vec![false; w as usize * h as usize];
    for (&k, r) in slot.iter().zip(&radiance) {
        if r.iter().all(|v| v.is_finite()) {
            fine[k * 3..k * 3 + 3].copy_from_slice(r);
            defined[k] = true;
        }
    }
    fill_by_reflection(&mut fine, &defined, w, h);
    let level0 = decimate(&fine, w, h, SUPERSAMPLING, 2.0);
    Ok(with_mip_levels(level0, layout))
}
