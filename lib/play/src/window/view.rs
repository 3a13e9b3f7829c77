//! What the window shows: the parameter point, playback, blend, camera mode and the free
//! camera, and the frame request they make. No window here; the UI and the input handlers
//! change this state, the frame loop turns it into a [`FrameRequest`].

use crate::{CameraChoice, FrameRequest, ViewCamera};

use super::camera::FreeCamera;
use super::path::{PathKind, Playback};
use super::space::Space;

/// Radians the view turns per pixel of mouse movement.
pub const TURN_PER_PIXEL: f32 = 0.005;

/// Which camera frames are drawn from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CameraMode {
    /// The file's camera at the point (on the sampled views).
    Sample,
    /// Free: drag turns the eye around the target, the wheel zooms.
    Orbit,
    /// Free: WASD (Q/E down/up) moves the eye, drag turns the view.
    Fly,
}

/// The window's state.
#[derive(Clone, Debug)]
pub struct ViewState {
    pub space: Space,
    /// The point the sliders show, one value per dimension.
    pub point: Vec<f32>,
    pub playback: Playback,
    /// Multilinear blend of the samples around the point; else the nearest sample alone.
    pub multilinear: bool,
    pub mode: CameraMode,
    /// The free camera (orbit and fly), made from the sample camera when first needed.
    pub free: Option<FreeCamera>,
    /// Distance from the sample cameras to where they look, the orbit target's distance
    /// and the scale of fly speeds.
    pub focus_distance: f32,
    /// Show the ray-traced gold standard instead of the player's frame.
    pub show_gold: bool,
    pub show_ui: bool,
}

impl ViewState {
    pub fn new(space: Space, point: Vec<f32>, focus_distance: f32) -> ViewState {
        ViewState {
            space,
            point,
            playback: Playback::new(PathKind::Diagonal),
            multilinear: true,
            mode: CameraMode::Sample,
            free: None,
            focus_distance,
            show_gold: false,
            show_ui: true,
        }
    }

    /// The point frames are drawn at: the slider point, or its nearest sample when blending
    /// is off (the player draws a point on a sample from that sample alone).
    pub fn draw_point(&self) -> Vec<f32> {
        if self.multilinear {
            self.point.clone()
        } else {
            self.space.snap(&self.point)
        }
    }

    /// Switches the camera mode; leaving the sample camera the first time starts the free
    /// camera at `sample` (the sample camera at the current point), so the view does not jump.
    pub fn set_mode(&mut self, mode: CameraMode, sample: &ViewCamera) {
        if mode != CameraMode::Sample && self.free.is_none() {
            self.free = Some(FreeCamera::new(sample, self.focus_distance));
        }
        self.mode = mode;
    }

    /// Puts the free camera back on the sample camera.
    pub fn reset_free(&mut self, sample: &ViewCamera) {
        self.free = Some(FreeCamera::new(sample, self.focus_distance));
    }

    /// A mouse drag of (`dx`, `dy`) pixels over the frame.
    pub fn drag(&mut self, dx: f32, dy: f32) {
        let Some(f) = self.free.as_mut() else { return };
        match self.mode {
            CameraMode::Sample => {}
            // Dragging right carries the scene right: the eye goes left around the target.
            CameraMode::Orbit => f.orbit(-dx * TURN_PER_PIXEL, dy * TURN_PER_PIXEL),
            // Dragging right turns the view right, dragging up looks up.
            CameraMode::Fly => f.look(dx * TURN_PER_PIXEL, -dy * TURN_PER_PIXEL),
        }
    }

    /// Mouse wheel `steps` (> 0: away from the user): zoom in when orbiting, fly forward a
    /// tenth of the focus distance per step when flying.
    pub fn scroll(&mut self, steps: f32) {
        let step = 0.1 * self.focus_distance;
        let Some(f) = self.free.as_mut() else { return };
        match self.mode {
            CameraMode::Sample => {}
            CameraMode::Orbit => f.zoom(steps),
            CameraMode::Fly => f.fly(steps * step, 0.0, 0.0),
        }
    }

    /// Held movement keys over `dt` seconds when flying: `forward`, `right`, `up` in −1..1;
    /// the speed is half the focus distance per second, four times that when `fast`.
    pub fn fly_keys(&mut self, forward: f32, right: f32, up: f32, dt: f32, fast: bool) {
        let speed = 0.5 * self.focus_distance * if fast { 4.0 } else { 1.0 } * dt;
        if let (CameraMode::Fly, Some(f)) = (self.mode, self.free.as_mut()) {
            f.fly(forward * speed, right * speed, up * speed);
        }
    }

    /// The request for the next frame.
    /// The parameter samples playback reaches next, for the player to decode ahead
    /// ([`crate::Player::prefetch`]): the nearest samples of the points ahead along the path
    /// that differ from the current one, at most `count`, looked for over the time playback
    /// takes to pass two samples; none while paused. Each is drawn with the frame's camera.
    pub fn ahead(&self, count: usize) -> Vec<FrameRequest> {
        let samples = self.space.axes.iter().map(|a| a.samples.len()).max().unwrap_or(1);
        if !self.playback.playing || count == 0 || samples < 2 {
            return Vec::new();
        }
        let step = self.playback.seconds_per_traverse / (8 * samples) as f32;
        let now = self.space.snap(&self.point);
        let camera = self.request().camera;
        let mut playback = self.playback.clone();
        let mut out: Vec<FrameRequest> = Vec::new();
        // Two sample spacings of the densest dimension, in steps of an eighth of one.
        for _ in 0..=(16 * samples).div_ceil(samples - 1) {
            let next = self.space.snap(&playback.advance(&self.space, &self.point, step));
            if next != now && out.last().is_none_or(|r| r.point != next) {
                out.push(FrameRequest { point: next, camera });
                if out.len() == count {
                    break;
                }
            }
        }
        out
    }

    pub fn request(&self) -> FrameRequest {
        let camera = match (self.mode, &self.free) {
            (CameraMode::Orbit | CameraMode::Fly, Some(f)) => CameraChoice::Free(f.view_camera()),
            _ => CameraChoice::Sample,
        };
        FrameRequest { point: self.draw_point(), camera }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Playing along the diagonal of two dimensions, the samples ahead are the next ones on
    /// the path, nearest first; paused, none.
    #[test]
    fn the_samples_ahead_are_the_next_on_the_path() {
        use pis_format::{Dimension, DimensionKind};
        let dim = |values: Vec<f32>| Dimension {
            name: "d".into(),
            kind: DimensionKind::Other,
            periodic: false,
            unit: String::new(),
            block_size: 1,
            values,
        };
        let space = Space::new(&[dim(vec![0.0, 1.0, 2.0, 3.0]), dim(vec![0.0, 10.0, 20.0, 30.0])]);
        let mut v = ViewState::new(space, vec![0.0, 0.0], 1.0);
        assert!(v.ahead(2).is_empty(), "paused");
        v.playback.play_from(&v.space, &[0.0, 0.0]);
        let points: Vec<Vec<f32>> = v.ahead(2).into_iter().map(|r| r.point).collect();
        assert_eq!(points, vec![vec![1.0, 10.0], vec![2.0, 20.0]]);
    }
    use glam::Vec3;
    use pis_format::{Dimension, DimensionKind};

    fn state() -> ViewState {
        let d = |name: &str, values: Vec<f32>| Dimension {
            name: name.into(),
            kind: DimensionKind::Other,
            periodic: false,
            unit: String::new(),
            block_size: 1,
            values,
        };
        ViewState::new(
            Space::new(&[d("light", vec![0.0, 0.5, 1.0]), d("view", vec![-6.0, 6.0])]),
            vec![0.3, 1.0],
            2.0,
        )
    }

    fn sample() -> ViewCamera {
        ViewCamera {
            eye: Vec3::new(0.0, 0.0, 2.0),
            target: Vec3::new(0.0, 0.0, 1.0),
            up: Vec3::Y,
            yfov_rad: 0.7,
            near: 0.05,
            far: 50.0,
        }
    }

    #[test]
    fn nearest_mode_draws_the_nearest_sample() {
        let mut v = state();
        assert_eq!(v.request().point, vec![0.3, 1.0]);
        v.multilinear = false;
        assert_eq!(v.request().point, vec![0.5, 6.0]);
        assert_eq!(v.request().camera, CameraChoice::Sample);
    }

    #[test]
    fn leaving_the_sample_camera_starts_from_it() {
        let mut v = state();
        v.drag(100.0, 0.0);
        assert!(v.free.is_none(), "the sample camera ignores drags");
        v.set_mode(CameraMode::Orbit, &sample());
        let CameraChoice::Free(c) = v.request().camera else { panic!("free camera expected") };
        assert!((c.eye - sample().eye).length() < 1e-5);
        assert!(
            (c.target - Vec3::ZERO).length() < 1e-5,
            "orbit target at the focus distance: {:?}",
            c.target
        );
        v.drag(50.0, 20.0);
        let CameraChoice::Free(d) = v.request().camera else { panic!() };
        assert!((d.target - c.target).length() < 1e-4 && (d.eye - c.eye).length() > 0.1);
        v.set_mode(CameraMode::Sample, &sample());
        assert_eq!(v.request().camera, CameraChoice::Sample);
        v.set_mode(CameraMode::Fly, &sample());
        let CameraChoice::Free(e) = v.request().camera else { panic!() };
        assert_eq!(e, d, "the free camera is kept across modes");
    }

    #[test]
    fn flying_moves_at_the_focus_scale() {
        let mut v = state();
        v.set_mode(CameraMode::Fly, &sample());
        v.fly_keys(1.0, 0.0, 0.0, 0.5, false);
        let CameraChoice::Free(c) = v.request().camera else { panic!() };
        assert!((c.eye - Vec3::new(0.0, 0.0, 1.5)).length() < 1e-5, "{:?}", c.eye);
        v.fly_keys(1.0, 0.0, 0.0, 0.5, true);
        let CameraChoice::Free(c) = v.request().camera else { panic!() };
        assert!((c.eye - Vec3::new(0.0, 0.0, -0.5)).length() < 1e-5, "{:?}", c.eye);
        v.scroll(1.0);
        let CameraChoice::Free(c) = v.request().camera else { panic!() };
        assert!((c.eye.z + 0.7).abs() < 1e-5);
    }
}
