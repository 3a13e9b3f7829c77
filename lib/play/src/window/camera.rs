//! The free camera: orbit (drag rotates the eye around a target, the wheel zooms) and fly
//! (WASD moves the eye, the mouse turns the view), both leaving the sampled viewpoints.
//!
//! One pose serves both modes: an eye, a view direction as yaw and pitch about the world up
//! of the file's cameras, and a focus distance; the orbit target is the point at that
//! distance along the view. Orbiting turns the direction and moves the eye so that the target
//! stays; looking turns the direction and keeps the eye; so switching modes never jumps.

use crate::ViewCamera;
use glam::Vec3;

/// Largest pitch, short of the pole, where the view direction would be along the up vector.
const MAX_PITCH: f32 = 89.0 * std::f32::consts::PI / 180.0;

/// A camera the user moves.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FreeCamera {
    /// World up (the pole of yaw and pitch) and two horizontal axes: yaw 0 looks along `a`,
    /// yaw π/2 along `b`.
    up: Vec3,
    a: Vec3,
    b: Vec3,
    pub eye: Vec3,
    pub yaw: f32,
    pub pitch: f32,
    /// Distance from the eye to the orbit target along the view direction.
    pub distance: f32,
    pub yfov_rad: f32,
    pub near: f32,
    pub far: f32,
}

impl FreeCamera {
    /// The pose of `cam` (eye, direction, lens) with the orbit target `focus_distance` ahead
    /// of the eye; yaw turns about the world axis nearest to the camera's up vector (a
    /// camera looking down at a scene still orbits about the vertical).
    pub fn new(cam: &ViewCamera, focus_distance: f32) -> FreeCamera {
        let up = world_up(cam.up);
        let a = up.any_orthonormal_vector();
        let b = up.cross(a);
        let dir = (cam.target - cam.eye).try_normalize().unwrap_or(-b);
        let pitch = dir.dot(up).clamp(-1.0, 1.0).asin().clamp(-MAX_PITCH, MAX_PITCH);
        let yaw = dir.dot(b).atan2(dir.dot(a));
        let distance =
            if focus_distance.is_finite() && focus_distance > 0.0 { focus_distance } else { 1.0 };
        FreeCamera {
            up,
            a,
            b,
            eye: cam.eye,
            yaw,
            pitch,
            distance,
            yfov_rad: cam.yfov_rad,
            near: cam.near,
            far: cam.far,
        }
    }

    /// Unit view direction.
    pub fn direction(&self) -> Vec3 {
        let (sy, cy) = self.yaw.sin_cos();
        let (sp, cp) = self.pitch.sin_cos();
        (cp * (cy * self.a + sy * self.b) + sp * self.up).normalize()
    }

    /// Unit vector to the right of the view, horizontal.
    pub fn right(&self) -> Vec3 {
        self.direction().cross(self.up).normalize()
    }

    /// The orbit target.
    pub fn target(&self) -> Vec3 {
        self.eye + self.distance * self.direction()
    }

    fn turn(&mut self, d_yaw: f32, d_pitch: f32) {
        self.yaw = (self.yaw + d_yaw).rem_euclid(std::f32::consts::TAU);
        self.pitch = (self.pitch + d_pitch).clamp(-MAX_PITCH, MAX_PITCH);
    }

    /// Orbit: turns the eye around the target by `d_yaw` (about the up vector) and `d_pitch`
    /// (up and down) radians; the target and the distance stay.
    pub fn orbit(&mut self, d_yaw: f32, d_pitch: f32) {
        let target = self.target();
        self.turn(d_yaw, d_pitch);
        self.eye = target - self.distance * self.direction();
    }

    /// Zoom: `steps` > 0 moves the eye towards the target (each step by 10 %), never closer
    /// than twice the near plane; the target stays.
    pub fn zoom(&mut self, steps: f32) {
        let target = self.target();
        let far = if self.far.is_finite() { self.far * 0.5 } else { f32::MAX };
        self.distance =
            (self.distance * (-0.1 * steps).exp()).clamp(2.0 * self.near, far.max(2.0 * self.near));
        self.eye = target - self.distance * self.direction();
    }

    /// Fly: turns the view by `d_yaw` and `d_pitch` radians about the eye.
    pub fn look(&mut self, d_yaw: f32, d_pitch: f32) {
        self.turn(d_yaw, d_pitch);
    }

    /// Fly: moves the eye by `forward`, `right` and `up` units (the target moves along).
    pub fn fly(&mut self, forward: f32, right: f32, up: f32) {
        self.eye += forward * self.direction() + right * self.right() + up * self.up;
    }

    /// The camera the player draws from.
    pub fn view_camera(&self) -> ViewCamera {
        ViewCamera {
            eye: self.eye,
            target: self.target(),
            up: self.up,
            yfov_rad: self.yfov_rad,
            near: self.near,
            far: self.far,
        }
    }
}

/// The world axis (±X, ±Y, ±Z) nearest to `up`; +Y when `up` is zero or not finite.
pub fn world_up(up: Vec3) -> Vec3 {
    if !up.is_finite() || up.length_squared() == 0.0 {
        return Vec3::Y;
    }
    let a = up.abs();
    if a.y >= a.x && a.y >= a.z {
        Vec3::Y * up.y.signum()
    } else if a.x >= a.z {
        Vec3::X * up.x.signum()
    } else {
        Vec3::Z * up.z.signum()
    }
}

/// The point nearest to every camera's line of sight in the least-squares sense: where the
/// sampled views look (the centre of an orbit). None when the lines are (nearly) parallel, as
/// for a single camera.
pub fn sight_convergence(cams: &[ViewCamera]) -> Option<Vec3> {
    // Σ (I − d dᵀ) p = Σ (I − d dᵀ) e over the lines e + t d.
    let mut m = glam::Mat3::ZERO;
    let mut rhs = Vec3::ZERO;
    for c in cams {
        let d = (c.target - c.eye).try_normalize()?;
        let p = glam::Mat3::IDENTITY - glam::Mat3::from_cols(d * d.x, d * d.y, d * d.z);
        m += p;
        rhs += p * c.eye;
    }
    // Parallel lines leave m singular along their direction: demand a well-conditioned system.
    let det = m.determinant();
    let scale = (m.x_axis.length() * m.y_axis.length() * m.z_axis.length()).max(f32::MIN_POSITIVE);
    if cams.len() < 2 || det.abs() < 1e-6 * scale {
        return None;
    }
    let p = m.inverse() * rhs;
    p.is_finite().then_some(p)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cam(eye: Vec3, target: Vec3) -> ViewCamera {
        ViewCamera { eye, target, up: Vec3::Y, yfov_rad: 0.7, near: 0.05, far: 100.0 }
    }

    fn close(a: Vec3, b: Vec3) -> bool {
        (a - b).length() < 1e-4
    }

    #[test]
    fn the_pose_of_a_camera_is_kept() {
        let c = cam(Vec3::new(1.0, 2.0, 3.0), Vec3::new(0.0, 0.85, 0.0));
        let f = FreeCamera::new(&c, 2.0);
        let v = f.view_camera();
        assert!(close(v.eye, c.eye));
        assert!(close((v.target - v.eye).normalize(), (c.target - c.eye).normalize()));
        assert!(close(f.target(), c.eye + 2.0 * (c.target - c.eye).normalize()));
        assert_eq!((v.yfov_rad, v.near, v.far, v.up), (0.7, 0.05, 100.0, Vec3::Y));
        assert!(v.check().is_ok());
    }

    #[test]
    fn orbit_keeps_target_and_distance() {
        let c = cam(Vec3::new(0.0, 1.5, 2.0), Vec3::new(0.0, 0.85, 0.0));
        let mut f = FreeCamera::new(&c, (c.target - c.eye).length());
        let target = f.target();
        assert!(close(target, c.target));
        f.orbit(0.8, 0.3);
        assert!(close(f.target(), target));
        assert!(((f.eye - target).length() - f.distance).abs() < 1e-4);
        assert!(!close(f.eye, c.eye), "the eye moved");
        // A quarter turn about +Y takes an eye on +Z to ±X, at the same height.
        let mut g = FreeCamera::new(&cam(Vec3::new(0.0, 0.0, 2.0), Vec3::ZERO), 2.0);
        g.orbit(std::f32::consts::FRAC_PI_2, 0.0);
        assert!(
            (g.eye.x.abs() - 2.0).abs() < 1e-4 && g.eye.y.abs() < 1e-4 && g.eye.z.abs() < 1e-4,
            "{:?}",
            g.eye
        );
    }

    #[test]
    fn a_tilted_camera_orbits_about_the_vertical() {
        // Looking down at 22°, as demo1's views: the camera's up leans back, the pole is +Y.
        let eye = Vec3::new(0.0, 0.85 + 1.7 * 0.3746, 1.7 * 0.9272);
        let target = Vec3::new(0.0, 0.85, 0.0);
        let dir = (target - eye).normalize();
        let up = dir.cross(Vec3::Y).normalize().cross(dir);
        assert!(up.y > 0.9 && up.z < -0.3, "{up:?}");
        let mut f = FreeCamera::new(
            &ViewCamera { eye, target, up, yfov_rad: 0.7, near: 0.05, far: 50.0 },
            1.7,
        );
        f.orbit(1.0, 0.0);
        assert!((f.eye.y - eye.y).abs() < 1e-4, "the eye stays at its height: {:?}", f.eye);
        assert!(close(f.target(), target));
        assert_eq!(
            (world_up(Vec3::new(0.1, -0.9, 0.3)), world_up(Vec3::ZERO)),
            (-Vec3::Y, Vec3::Y)
        );
    }

    #[test]
    fn pitch_stops_short_of_the_pole() {
        let mut f = FreeCamera::new(&cam(Vec3::new(0.0, 0.0, 2.0), Vec3::ZERO), 2.0);
        f.orbit(0.0, 10.0);
        assert_eq!(f.pitch, MAX_PITCH);
        assert!(f.view_camera().check().is_ok(), "up is never along the view");
    }

    #[test]
    fn zoom_moves_along_the_view_and_stays_outside_the_near_plane() {
        let mut f = FreeCamera::new(&cam(Vec3::new(0.0, 0.0, 2.0), Vec3::ZERO), 2.0);
        f.zoom(1.0);
        assert!((f.distance - 2.0 * (-0.1f32).exp()).abs() < 1e-5);
        assert!(close(f.target(), Vec3::ZERO) && f.eye.x.abs() < 1e-5 && f.eye.y.abs() < 1e-5);
        f.zoom(1000.0);
        assert!((f.distance - 0.1).abs() < 1e-6);
    }

    #[test]
    fn look_keeps_the_eye_and_fly_moves_it() {
        let mut f = FreeCamera::new(&cam(Vec3::new(0.0, 0.0, 2.0), Vec3::ZERO), 2.0);
        f.look(0.5, -0.2);
        assert!(close(f.eye, Vec3::new(0.0, 0.0, 2.0)));
        let mut g = FreeCamera::new(&cam(Vec3::new(0.0, 0.0, 2.0), Vec3::ZERO), 2.0);
        g.fly(0.5, 0.0, 0.0);
        assert!(close(g.eye, Vec3::new(0.0, 0.0, 1.5)));
        g.fly(0.0, 1.0, 0.25);
        assert!(close(g.eye, Vec3::new(1.0, 0.25, 1.5)), "right of −Z is +X: {:?}", g.eye);
    }

    #[test]
    fn sight_lines_of_an_orbit_meet_at_its_centre() {
        let centre = Vec3::new(0.0, 0.85, 0.0);
        let cams: Vec<_> = (0..4)
            .map(|i| {
                let az = (i as f32 - 1.5) * 0.1;
                cam(centre + 1.7 * Vec3::new(az.sin() * 0.93, 0.37, az.cos() * 0.93), centre)
            })
            .collect();
        let p = sight_convergence(&cams).expect("converging views");
        assert!(close(p, centre), "{p:?}");
        assert_eq!(sight_convergence(&cams[..1]), None);
        let parallel = [cam(Vec3::ZERO, -Vec3::Z), cam(Vec3::X, Vec3::X - Vec3::Z)];
        assert_eq!(sight_convergence(&parallel), None);
    }
}
