//! Camera paths for accuracy and stability tests: the sampled views themselves, dense paths
//! between them (fractional values of the orbit's view dimension) and away from them (the
//! camera displaced off the orbit).

use anyhow::{anyhow, Result};
use pis_scene::orbit::orbit_camera;
use pis_scene::{Driver, Frame, Scene};

/// Which path a frame is on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum PathKind {
    /// At every sampled view: the cameras the set was traced from.
    Samples,
    /// On the orbit at fractional view samples.
    Between,
    /// Off the orbit: larger radius and higher elevation.
    Away,
}

impl PathKind {
    pub fn name(self) -> &'static str {
        match self {
            PathKind::Samples => "samples",
            PathKind::Between => "between",
            PathKind::Away => "away",
        }
    }
}

/// One frame of a path.
#[derive(Clone, Debug)]
pub struct PathFrame {
    pub kind: PathKind,
    /// Position along the view dimension in samples (fractional).
    pub view: f32,
    /// The nearest parameter point's sample indices (other dimensions fixed).
    pub point: Vec<u32>,
    /// The scene at that point with the path's camera.
    pub frame: Frame,
}

/// Radius factor and elevation offset (degrees) of the away path.
pub const AWAY_RADIUS: f32 = 1.2;
pub const AWAY_ELEVATION_DEG: f32 = 8.0;

/// The frames of each path of `kinds`, in that order: the sampled views, or `frames` frames
/// on the between or away path, view positions evenly from the first to the last view
/// sample; every other dimension at its middle sample. Also returns the view dimension.
pub fn paths(scene: &Scene, frames: usize, kinds: &[PathKind]) -> Result<(usize, Vec<PathFrame>)> {
    let dims = &scene.space.dims;
    let v =
        dims.iter().position(|d| matches!(d.driver, Driver::Orbit { .. })).ok_or_else(|| {
            anyhow!("scene {} has no orbit (view) dimension to move the camera along", scene.name)
        })?;
    let Driver::Orbit { target, radius, elevation_deg } = dims[v].driver.clone() else {
        unreachable!()
    };
    let values = &dims[v].values;
    let n = values.len();
    let base: Vec<u32> = dims.iter().map(|d| (d.values.len() / 2) as u32).collect();
    let mut out = Vec::new();
    for &kind in kinds {
        if kind == PathKind::Samples {
            for k in 0..n {
                let mut point = base.clone();
                point[v] = k as u32;
                let frame = scene.frame(&point)?;
                out.push(PathFrame { kind, view: k as f32, point, frame });
            }
            continue;
        }
        for i in 0..frames {
            let t = if frames <= 1 { 0.0 } else { i as f32 * (n - 1) as f32 / (frames - 1) as f32 };
            let (k0, f) = (t.floor() as usize, t.fract());
            let k1 = (k0 + 1).min(n - 1);
            let az = values[k0] + (values[k1] - values[k0]) * f;
            let mut point = base.clone();
            point[v] = t.round() as u32;
            let mut frame = scene.frame(&point)?;
            let (r, e) = match kind {
                PathKind::Samples | PathKind::Between => (radius, elevation_deg),
                PathKind::Away => (radius * AWAY_RADIUS, elevation_deg + AWAY_ELEVATION_DEG),
            };
            frame.camera.world_from_camera = orbit_camera(target, r, e, az);
            out.push(PathFrame { kind, view: t, point, frame });
        }
    }
    Ok((v, out))
}
