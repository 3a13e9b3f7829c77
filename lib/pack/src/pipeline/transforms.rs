//! An object's transforms as the container stores them: rigid, the first point's scale or
//! shear baked into the mesh (SPEC.md rule 5106), and the check before any work that every
//! object's can be.

use anyhow::{anyhow, Result};
use pis_format::checks;

/// Rows 0–2 of `m`, row-major: the 3×4 transform the container stores.
pub fn row3x4(m: glam::Mat4) -> [f32; 12] {
    let mut out = [0.0; 12];
    for r in 0..3 {
        out[r * 4..r * 4 + 4].copy_from_slice(&m.row(r).to_array());
    }
    out
}

/// The linear part of object `o`'s transform at the set's first point when it is not a
/// rotation (a scaled, sheared or mirrored glTF node): the container stores rigid transforms
/// only (SPEC.md rule 5106), so pis-pack bakes it into the object's mesh and stores every
/// transform times its inverse. `None` for a rigid object.
pub fn baked(frames: &[pis_scene::Frame], o: usize) -> Option<glam::Mat4> {
    let first = frames.first()?.instances[o].world_from_object;
    if checks::rigid(&row3x4(first)) {
        return None;
    }
    let mut linear = first;
    linear.w_axis = glam::Vec4::W;
    Some(linear)
}

/// Object `o`'s transform at frame `f` as stored: rigid once its first point's scale is in
/// its mesh ([`baked`]).
pub fn stored_transform(f: &pis_scene::Frame, o: usize, bake: Option<glam::Mat4>) -> glam::Mat4 {
    let m = f.instances[o].world_from_object;
    bake.map_or(m, |b| m * b.inverse())
}

/// Every object's transforms can be stored: finite, and rigid once the first point's scale
/// is baked into the mesh. Checked before any work: an object whose scale or shear changes
/// over the space cannot be.
pub fn check_transforms(scene: &pis_scene::Scene, frames: &[pis_scene::Frame]) -> Result<()> {
    for (o, object) in scene.objects.iter().enumerate() {
        let bake = baked(frames, o);
        if bake.is_some_and(|b| !b.is_finite() || b.determinant().abs() < 1e-12) {
            return Err(anyhow!(
                "object {}: its transform at the first point is singular or not finite",
                object.name
            ));
        }
        for (p, f) in frames.iter().enumerate() {
            let m = row3x4(stored_transform(f, o, bake));
            if !m.iter().all(|v| v.is_finite()) || !checks::rigid(&m) {
                return Err(anyhow!(
                    "object {}: its scale or shear changes over the parameter space (point {p}), and the container stores one mesh and rigid transforms per object (SPEC.md rule 5106): animate its translation and rotation only",
                    object.name
                ));
            }
        }
    }
    Ok(())
}
