//! The flat surface an object rests on, which the distant box's bottom follows (thesis 5.4).

use glam::Vec3;

use super::mesh::bounds;

/// Vertices within this fraction of the object's height above its lowest point cast rays.
pub const BASE_BAND: f32 = 0.02;
/// At most this many rays are cast.
pub const MAX_RAYS: usize = 64;
/// A surface counts as a support when hit within this fraction of the object's height of
/// its lowest point (below, or above where the object sinks into it).
pub const CONTACT_BAND: f32 = 0.05;
/// The fraction of rays that must find the support.
pub const QUORUM: f32 = 0.75;
/// The object's height for the bands is at least this fraction of its bounding-box
/// diagonal, so a flat object still has bands.
pub const MIN_HEIGHT_RATIO: f32 = 0.01;

/// The height of the flat surface the object rests on, if it rests on one (thesis 5.4: "For
/// objects resting on flat surfaces, it is effective to align the box bottom with this flat
/// surface").
///
/// `positions` are the object's world-space vertices; `cast(origin, dir)` gives the
/// distance along the unit `dir` to the nearest scene surface that is not the object. Rays
/// go straight down (−Y) from the vertices within [`BASE_BAND`] of the object's height above
/// its lowest point (at most [`MAX_RAYS`] of them, evenly spaced in vertex order), each
/// starting [`CONTACT_BAND`] of the height above its vertex so that a surface the object
/// sinks into slightly is still found. When at least [`QUORUM`] of the rays hit within
/// [`CONTACT_BAND`] of the height of the lowest point, the mean height of those hits is the
/// support; otherwise, or without vertices, there is none.
pub fn support_plane(positions: &[Vec3], cast: impl Fn(Vec3, Vec3) -> Option<f32>) -> Option<f32> {
    let finite: Vec<Vec3> = positions.iter().copied().filter(|p| p.is_finite()).collect();
    let (lo, hi) = bounds(&finite)?;
    let height = (hi.y - lo.y).max(MIN_HEIGHT_RATIO * (hi - lo).length());
    let base: Vec<Vec3> = finite.into_iter().filter(|p| p.y <= lo.y + BASE_BAND * height).collect();
    let rays = base.len().min(MAX_RAYS);
    let band = CONTACT_BAND * height;
    let hits: Vec<f32> = (0..rays)
        .filter_map(|k| {
            let from = base[k * base.len() / rays] + Vec3::Y * band;
            let t = cast(from, Vec3::NEG_Y).filter(|t| t.is_finite() && *t >= 0.0)?;
            let y = from.y - t;
            ((y - lo.y).abs() <= band).then_some(y)
        })
        .collect();
    if height <= 0.0 || (hits.len() as f32) < QUORUM * rays as f32 {
        return None;
    }
    Some((hits.iter().map(|&y| f64::from(y)).sum::<f64>() / hits.len() as f64) as f32)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pipeline::shell_fit::test_meshes::{cuboid, uv_sphere};

    /// The plane y = `y` over the square |x|, |z| ≤ `half`, seen from above.
    fn floor(y: f32, half: f32) -> impl Fn(Vec3, Vec3) -> Option<f32> {
        move |o: Vec3, d: Vec3| {
            let t = (y - o.y) / d.y;
            let p = o + d * t;
            (t > 0.0 && d.y < 0.0 && p.x.abs() <= half && p.z.abs() <= half).then_some(t)
        }
    }

    #[test]
    fn finds_the_floor_under_a_box() {
        let (p, _) = cuboid(Vec3::new(0.0, 1.0, 0.0), Vec3::ONE);
        assert_eq!(support_plane(&p, floor(0.0, 10.0)), Some(0.0));
        // Sunk slightly into the floor, or hovering just above it.
        assert!((support_plane(&p, floor(0.05, 10.0)).unwrap() - 0.05).abs() < 1e-6);
        assert!((support_plane(&p, floor(-0.05, 10.0)).unwrap() + 0.05).abs() < 1e-6);
    }

    #[test]
    fn no_support_when_far_or_missing() {
        let (p, _) = cuboid(Vec3::new(0.0, 1.0, 0.0), Vec3::ONE);
        assert_eq!(support_plane(&p, floor(-1.0, 10.0)), None);
        assert_eq!(support_plane(&p, |_, _| None), None);
        assert_eq!(support_plane(&[], floor(0.0, 10.0)), None);
        // A box hanging over the floor's edge: only half its base is supported.
        let (p, _) = cuboid(Vec3::new(10.0, 1.0, 0.0), Vec3::ONE);
        assert_eq!(support_plane(&p, floor(0.0, 10.0)), None);
    }

    #[test]
    fn a_sphere_on_a_floor() {
        let (p, _) = uv_sphere(Vec3::new(0.0, 1.0, 0.0), 1.0, 32, 16);
        assert_eq!(support_plane(&p, floor(0.0, 10.0)), Some(0.0));
    }
}
