//! The perspective camera: primary rays and the matching projection matrix.

use glam::{Mat4, Vec2, Vec3, Vec4};
use pis_scene::Camera;

/// Generates primary rays for an image of `width` × `height` pixels.
///
/// Pixel (i, j) covers [i, i+1) × [j, j+1) in continuous image coordinates, row 0 at the top;
/// the centre of the image is the optical axis (camera −Z), +Y up, square pixels.
#[derive(Clone, Copy, Debug)]
pub struct PerspectiveCamera {
    pub world_from_camera: Mat4,
    pub origin: Vec3,
    tan_half_y: f32,
    aspect: f32,
    width: f32,
    height: f32,
}

impl PerspectiveCamera {
    /// The camera of `camera` rendering at `resolution`.
    pub fn new(camera: &Camera, resolution: (u32, u32)) -> PerspectiveCamera {
        let (w, h) = (resolution.0.max(1) as f32, resolution.1.max(1) as f32);
        PerspectiveCamera {
            world_from_camera: camera.world_from_camera,
            origin: camera.world_from_camera.transform_point3(Vec3::ZERO),
            tan_half_y: (camera.yfov * 0.5).tan(),
            aspect: w / h,
            width: w,
            height: h,
        }
    }

    /// Unit world-space direction of the ray through continuous image position `p` (pixels).
    pub fn direction(&self, p: Vec2) -> Vec3 {
        let x = (2.0 * p.x / self.width - 1.0) * self.tan_half_y * self.aspect;
        let y = (1.0 - 2.0 * p.y / self.height) * self.tan_half_y;
        self.world_from_camera.transform_vector3(Vec3::new(x, y, -1.0)).normalize()
    }

    /// Continuous image position of world point `p`, if it is in front of the camera.
    pub fn project(&self, p: Vec3) -> Option<Vec2> {
        let c = self.world_from_camera.inverse().transform_point3(p);
        if c.z >= 0.0 {
            return None;
        }
        let x = c.x / -c.z / (self.tan_half_y * self.aspect);
        let y = c.y / -c.z / self.tan_half_y;
        Some(Vec2::new((x + 1.0) * 0.5 * self.width, (1.0 - y) * 0.5 * self.height))
    }
}

/// The right-handed projection matrix of `camera` (clip depth in [0, 1], as wgpu uses) for an
/// image with aspect `width / height`; infinite far plane when `zfar` is infinite.
pub fn projection_matrix(camera: &Camera, resolution: (u32, u32)) -> Mat4 {
    let aspect = resolution.0.max(1) as f32 / resolution.1.max(1) as f32;
    let f = 1.0 / (camera.yfov * 0.5).tan();
    let (n, far) = (camera.znear, camera.zfar);
    let (c2z, c3z) =
        if far.is_finite() { (far / (n - far), n * far / (n - far)) } else { (-1.0, -n) };
    Mat4::from_cols(
        Vec4::new(f / aspect, 0.0, 0.0, 0.0),
        Vec4::new(0.0, f, 0.0, 0.0),
        Vec4::new(0.0, 0.0, c2z, -1.0),
        Vec4::new(0.0, 0.0, c3z, 0.0),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn centre_ray_is_the_optical_axis_and_projection_inverts_it() {
        let cam = Camera {
            world_from_camera: Mat4::from_translation(Vec3::new(1.0, 2.0, 3.0)),
            yfov: 0.8,
            znear: 0.1,
            zfar: f32::INFINITY,
        };
        let pc = PerspectiveCamera::new(&cam, (64, 48));
        let d = pc.direction(Vec2::new(32.0, 24.0));
        assert!((d - Vec3::NEG_Z).length() < 1e-6);
        let p = Vec2::new(10.25, 40.5);
        let q = pc.project(pc.origin + pc.direction(p) * 5.0).unwrap();
        assert!((p - q).length() < 1e-3);
    }

    #[test]
    fn projection_matrix_maps_points_to_the_pixels_rays_pass_through() {
        for zfar in [50.0, f32::INFINITY] {
            let eye = Vec3::new(0.3, 1.5, 2.0);
            let f = (Vec3::new(0.0, 0.5, 0.0) - eye).normalize();
            let r = f.cross(Vec3::Y).normalize();
            let u = r.cross(f);
            let cam = Camera {
                world_from_camera: Mat4::from_cols(
                    r.extend(0.0),
                    u.extend(0.0),
                    (-f).extend(0.0),
                    eye.extend(1.0),
                ),
                yfov: 0.7,
                znear: 0.1,
                zfar,
            };
            let (w, h) = (80u32, 60u32);
            let pc = PerspectiveCamera::new(&cam, (w, h));
            let clip_from_world = projection_matrix(&cam, (w, h)) * cam.world_from_camera.inverse();
            for (px, depth) in [
                (Vec2::new(3.25, 7.5), 1.0f32),
                (Vec2::new(70.0, 55.5), 4.0),
                (Vec2::new(40.0, 30.0), 20.0),
            ] {
                let p = pc.origin + pc.direction(px) * depth;
                let c = clip_from_world * p.extend(1.0);
                let ndc = c.truncate() / c.w;
                let back =
                    Vec2::new((ndc.x + 1.0) * 0.5 * w as f32, (1.0 - ndc.y) * 0.5 * h as f32);
                assert!((back - px).length() < 1e-3, "{back} vs {px}");
                assert!((0.0..=1.0).contains(&ndc.z), "depth {}", ndc.z);
            }
        }
    }
}
