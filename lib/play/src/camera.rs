//! Cameras: the file's view-sample cameras (CAMS) and free cameras, as view and projection
//! matrices. The projection is the tracer's (`pis_trace::camera::projection_matrix`): right
//! handed, looking down −z, depth 0 at the near plane and 1 at the far plane.

use glam::{Mat4, Vec3, Vec4};

/// A pinhole camera in world space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ViewCamera {
    pub eye: Vec3,
    pub target: Vec3,
    pub up: Vec3,
    /// Vertical field of view, radians.
    pub yfov_rad: f32,
    pub near: f32,
    pub far: f32,
}

/// Which camera a frame is drawn from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CameraChoice {
    /// The file's camera at the frame's parameter point (the nearest view sample).
    Sample,
    /// Any camera (off the view samples the player draws the nearest parameter sample's
    /// textures, thesis 4.7).
    Free(ViewCamera),
}

/// A 3×4 row-major matrix of the file as a `Mat4`.
pub fn mat4_from_rows(m: &[f32; 12]) -> Mat4 {
    Mat4::from_cols(
        Vec4::new(m[0], m[4], m[8], 0.0),
        Vec4::new(m[1], m[5], m[9], 0.0),
        Vec4::new(m[2], m[6], m[10], 0.0),
        Vec4::new(m[3], m[7], m[11], 1.0),
    )
}

/// The tracer's perspective projection for an image of `width × height`.
pub fn projection(yfov: f32, near: f32, far: f32, width: u32, height: u32) -> Mat4 {
    let aspect = width.max(1) as f32 / height.max(1) as f32;
    let f = 1.0 / (yfov * 0.5).tan();
    let (c2z, c3z) = if far.is_finite() && far > near {
        (far / (near - far), near * far / (near - far))
    } else {
        (-1.0, -near)
    };
    Mat4::from_cols(
        Vec4::new(f / aspect, 0.0, 0.0, 0.0),
        Vec4::new(0.0, f, 0.0, 0.0),
        Vec4::new(0.0, 0.0, c2z, -1.0),
        Vec4::new(0.0, 0.0, c3z, 0.0),
    )
}

impl ViewCamera {
    /// The camera of a file camera record: eye at its origin, looking down its −z, up its +y.
    pub fn from_file(c: &pis_format::Camera) -> ViewCamera {
        let m = mat4_from_rows(&c.world_from_camera);
        let eye = m.w_axis.truncate();
        let forward = -m.z_axis.truncate();
        ViewCamera {
            eye,
            target: eye + forward,
            up: m.y_axis.truncate(),
            yfov_rad: c.yfov,
            near: c.znear,
            far: c.zfar,
        }
    }

    /// World to camera.
    pub fn view_matrix(&self) -> Mat4 {
        let f = (self.target - self.eye).normalize();
        let s = f.cross(self.up).normalize();
        let u = s.cross(f);
        Mat4::from_cols(
            Vec4::new(s.x, u.x, -f.x, 0.0),
            Vec4::new(s.y, u.y, -f.y, 0.0),
            Vec4::new(s.z, u.z, -f.z, 0.0),
            Vec4::new(-s.dot(self.eye), -u.dot(self.eye), f.dot(self.eye), 1.0),
        )
    }

    /// Camera to clip for an image of `size`.
    pub fn projection(&self, size: (u32, u32)) -> Mat4 {
        projection(self.yfov_rad, self.near, self.far, size.0, size.1)
    }

    /// Whether the camera can be drawn from: finite values, eye ≠ target, up not along the
    /// view direction, 0 < yfov < π, 0 < near < far.
    pub fn check(&self) -> Result<(), String> {
        let finite = [self.eye, self.target, self.up].iter().all(|v| v.is_finite())
            && self.yfov_rad.is_finite()
            && self.near.is_finite();
        let dir = self.target - self.eye;
        if !finite
            || dir.length_squared() <= 0.0
            || dir.cross(self.up).length_squared()
                <= 1e-12 * dir.length_squared() * self.up.length_squared()
        {
            return Err(format!("camera {self:?}: eye, target and up must be finite, eye ≠ target, up not along the view direction"));
        }
        let fov_ok = self.yfov_rad > 0.0 && self.yfov_rad < std::f32::consts::PI;
        let near_ok = self.near > 0.0 && self.far > self.near;
        if !(fov_ok && near_ok) {
            return Err(format!("camera {self:?}: needs 0 < yfov < π and 0 < near < far"));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn file_camera_round_trips_through_look_at() {
        let world_from_camera = Mat4::from_translation(Vec3::new(1.0, 2.0, 3.0))
            * Mat4::from_rotation_y(0.7)
            * Mat4::from_rotation_x(-0.2);
        let mut rows = [0.0; 12];
        for r in 0..3 {
            rows[r * 4..r * 4 + 4].copy_from_slice(&world_from_camera.row(r).to_array());
        }
        let cam = ViewCamera::from_file(&pis_format::Camera {
            world_from_camera: rows,
            yfov: 0.8,
            znear: 0.1,
            zfar: 100.0,
        });
        let view = cam.view_matrix();
        let want = world_from_camera.inverse();
        for (a, b) in view.to_cols_array().iter().zip(want.to_cols_array()) {
            assert!((a - b).abs() < 1e-5, "{view:?} vs {want:?}");
        }
        assert!(cam.check().is_ok());
        assert!(ViewCamera { target: cam.eye, ..cam }.check().is_err());
    }
}
