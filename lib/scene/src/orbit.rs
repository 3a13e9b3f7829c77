//! The orbit camera: a viewpoint circling a target at a fixed radius and elevation
//! (the thesis's circular viewpoint paths, sections 4.8 and 5.10).

use glam::{Mat4, Vec3};

/// The eye position at `azimuth_deg` on the orbit about `target`. Azimuth 0 puts the eye on
/// the +Z side of the target; positive azimuth turns counter-clockwise seen from above (+Y),
/// towards +X. Elevation is the angle above the horizontal plane through the target.
pub fn orbit_eye(target: Vec3, radius: f32, elevation_deg: f32, azimuth_deg: f32) -> Vec3 {
    let (el, az) = (elevation_deg.to_radians(), azimuth_deg.to_radians());
    target + radius * Vec3::new(el.cos() * az.sin(), el.sin(), el.cos() * az.cos())
}

/// A rigid camera-to-world transform for a camera at `eye` looking at `target` (the camera
/// looks down its local -Z with +Y up, as in glTF). `up` is a hint; if it is parallel to the
/// view direction another axis is used.
pub fn look_at(eye: Vec3, target: Vec3, up: Vec3) -> Mat4 {
    let forward = (target - eye).normalize_or(Vec3::NEG_Z);
    let mut right = forward.cross(up);
    if right.length_squared() < 1e-12 {
        right = forward.cross(Vec3::Z);
        if right.length_squared() < 1e-12 {
            right = forward.cross(Vec3::X);
        }
    }
    let right = right.normalize();
    let true_up = right.cross(forward);
    Mat4::from_cols(right.extend(0.0), true_up.extend(0.0), (-forward).extend(0.0), eye.extend(1.0))
}

/// The camera transform at `azimuth_deg` on the orbit: [`orbit_eye`] looking at `target`.
pub fn orbit_camera(target: Vec3, radius: f32, elevation_deg: f32, azimuth_deg: f32) -> Mat4 {
    look_at(orbit_eye(target, radius, elevation_deg, azimuth_deg), target, Vec3::Y)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn orbit_camera_looks_at_target() {
        let target = Vec3::new(0.5, 0.8, -0.2);
        for az in [0.0f32, 37.0, 90.0, 181.0, -60.0] {
            for el in [0.0f32, 15.0, 60.0] {
                let m = orbit_camera(target, 3.0, el, az);
                let eye = m.transform_point3(Vec3::ZERO);
                assert!((eye.distance(target) - 3.0).abs() < 1e-5);
                // The target is straight ahead, on the local -Z axis.
                let local = m.inverse().transform_point3(target);
                assert!(local.x.abs() < 1e-5 && local.y.abs() < 1e-5 && local.z < 0.0, "{local}");
                // Rigid and upright: local +X stays horizontal.
                assert!(m.transform_vector3(Vec3::X).y.abs() < 1e-5);
                assert!((m.determinant() - 1.0).abs() < 1e-5);
            }
        }
    }

    #[test]
    fn azimuth_convention() {
        let e0 = orbit_eye(Vec3::ZERO, 2.0, 0.0, 0.0);
        assert!(e0.distance(Vec3::new(0.0, 0.0, 2.0)) < 1e-6);
        let e90 = orbit_eye(Vec3::ZERO, 2.0, 0.0, 90.0);
        assert!(e90.distance(Vec3::new(2.0, 0.0, 0.0)) < 1e-6);
        let up = orbit_eye(Vec3::ZERO, 2.0, 90.0, 0.0);
        assert!(up.distance(Vec3::new(0.0, 2.0, 0.0)) < 1e-6);
    }

    #[test]
    fn look_at_straight_down_is_finite() {
        let m = look_at(Vec3::new(0.0, 5.0, 0.0), Vec3::ZERO, Vec3::Y);
        assert!(m.is_finite());
        assert!(m.transform_vector3(Vec3::NEG_Z).distance(Vec3::NEG_Y) < 1e-6);
    }
}
