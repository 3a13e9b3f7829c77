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
/// its mesh ([`baked`]). The product with the baked part's inverse is taken in double
/// precision, so that a node scaled by 10⁻⁴ (an exporter's millimetres) or 10³ stores a
/// transform as rigid as a unit one.
pub fn stored_transform(f: &pis_scene::Frame, o: usize, bake: Option<glam::Mat4>) -> glam::Mat4 {
    let m = f.instances[o].world_from_object;
    bake.map_or(m, |b| (m.as_dmat4() * b.as_dmat4().inverse()).as_mat4())
}

/// Whether the baked linear part `b` can be inverted, whatever its scale: finite, with axes
/// of non-zero length that are far from coplanar — |det| over the product of the axes'
/// lengths (1 for any rotation times any scale, 0 for coplanar axes) above 10⁻⁶ — and an
/// inverse that is finite in single precision (the mesh and the player work in `f32`).
fn invertible(b: glam::Mat4) -> bool {
    let d = b.as_dmat4();
    let lengths =
        d.x_axis.truncate().length() * d.y_axis.truncate().length() * d.z_axis.truncate().length();
    b.is_finite()
        && lengths > 0.0
        && d.determinant().abs() / lengths > 1e-6
        && d.inverse().as_mat4().is_finite()
}

/// Every object's transforms can be stored: finite, and rigid once the first point's scale
/// is baked into the mesh. Checked before any work: an object whose scale or shear changes
/// over the space cannot be.
pub fn check_transforms(scene: &pis_scene::Scene, frames: &[pis_scene::Frame]) -> Result<()> {
    for (o, object) in scene.objects.iter().enumerate() {
        let bake = baked(frames, o);
        if bake.is_some_and(|b| !invertible(b)) {
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

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Mat4, Quat, Vec3};

    /// A node scaled by 10⁻⁴ (its mesh in tenths of a millimetre) once failed as "singular":
    /// the test was |det| < 10⁻¹², and 10⁻⁴ cubed is 10⁻¹².
    #[test]
    fn a_scale_of_1e_4_is_invertible_and_coplanar_axes_are_not() {
        let spin = Quat::from_rotation_y(0.7);
        for k in [1e-4, 1e-3, 1.0, 1e3] {
            assert!(
                invertible(Mat4::from_scale_rotation_translation(Vec3::splat(k), spin, Vec3::ZERO)),
                "scale {k}"
            );
        }
        let flat = Mat4::from_cols_array(&[
            1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0, 1e-9, 0.0, 0.0, 0.0, 0.0, 1.0,
        ]);
        assert!(!invertible(flat));
        assert!(!invertible(Mat4::from_scale(Vec3::new(1.0, 0.0, 1.0))));
        assert!(!invertible(Mat4::from_scale(Vec3::splat(f32::NAN))));
        assert!(!invertible(Mat4::from_scale(Vec3::splat(1e-39))), "an inverse beyond f32");
    }

    /// With 10⁻⁴ baked in, the stored transform of a moved point is rigid.
    #[test]
    fn a_transform_over_a_baked_1e_4_scale_is_rigid() {
        let scale = Vec3::splat(1e-4);
        let first =
            Mat4::from_scale_rotation_translation(scale, Quat::from_rotation_x(0.3), Vec3::X);
        let later = Mat4::from_rotation_y(1.1) * first;
        let camera = pis_scene::Camera {
            world_from_camera: Mat4::IDENTITY,
            yfov: 0.8,
            znear: 0.1,
            zfar: f32::INFINITY,
        };
        let frame = |m: Mat4| pis_scene::Frame {
            camera,
            lights: vec![],
            instances: vec![pis_scene::Instance { world_from_object: m }],
        };
        let bake = baked(&[frame(first)], 0);
        assert!(bake.is_some());
        assert!(checks::rigid(&row3x4(stored_transform(&frame(later), 0, bake))));
    }
}
