//! Light directions: a light turned over the sphere or a hemisphere of directions, sampled by
//! a spherical Fibonacci set (equal area per sample, low discrepancy: every prefix of the
//! spiral spreads over the whole cap, so neighbouring samples are never bunched along a
//! meridian as a θ × φ grid bunches them at the pole).

use glam::{Quat, Vec3};

/// Which directions a `light_direction` dimension covers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Cover {
    /// The hemisphere about `up` (the directions above the horizon).
    Hemisphere,
    /// Every direction.
    Sphere,
}

/// The golden-ratio increment of the spiral's azimuth, in turns.
const GOLDEN_TURN: f64 = 0.618_033_988_749_894_9;

/// `n` unit directions over `cover` about the pole `up` (unit), each pointing from the scene
/// towards the light. Sample i has cos θ = 1 − (i + ½)/n over a hemisphere (1 − 2(i + ½)/n
/// over the sphere) and azimuth φ = 2π·frac(i·(√5 − 1)/2), in a frame whose +Y is `up` and
/// whose φ = 0 lies along +X turned with it.
pub fn light_directions(n: u32, cover: Cover, up: Vec3) -> Vec<Vec3> {
    let turn = Quat::from_rotation_arc(Vec3::Y, up.normalize());
    let span = match cover {
        Cover::Hemisphere => 1.0,
        Cover::Sphere => 2.0,
    };
    (0..n)
        .map(|i| {
            let cos_t = 1.0 - span * (i as f64 + 0.5) / n as f64;
            let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
            let phi = std::f64::consts::TAU * (i as f64 * GOLDEN_TURN).fract();
            let d = Vec3::new((sin_t * phi.cos()) as f32, cos_t as f32, (sin_t * phi.sin()) as f32);
            (turn * d).normalize()
        })
        .collect()
}

/// `n` unit directions along the arc of elevation `elevation_deg` above the horizon of `up`,
/// from azimuth `azimuth_deg[0]` to `azimuth_deg[1]` inclusive (degrees, φ as in
/// [`light_directions`]): a light moving continuously.
pub fn arc_directions(n: u32, elevation_deg: f32, azimuth_deg: [f32; 2], up: Vec3) -> Vec<Vec3> {
    let turn = Quat::from_rotation_arc(Vec3::Y, up.normalize());
    let (sin_e, cos_e) = elevation_deg.to_radians().sin_cos();
    (0..n)
        .map(|i| {
            let f = if n > 1 { i as f32 / (n - 1) as f32 } else { 0.0 };
            let phi = (azimuth_deg[0] + (azimuth_deg[1] - azimuth_deg[0]) * f).to_radians();
            (turn * Vec3::new(cos_e * phi.cos(), sin_e, cos_e * phi.sin())).normalize()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_hemisphere_lies_above_its_horizon_and_covers_it_evenly() {
        let d = light_directions(64, Cover::Hemisphere, Vec3::Y);
        assert_eq!(d.len(), 64);
        assert!(d.iter().all(|v| v.y > 0.0 && (v.length() - 1.0).abs() < 1e-5));
        // Equal area: the mean of cos θ over a uniformly covered hemisphere is ½, and the
        // mean direction has no sideways part.
        let mean = d.iter().copied().sum::<Vec3>() / 64.0;
        assert!((mean.y - 0.5).abs() < 1e-3, "{mean}");
        assert!(mean.x.abs() < 0.05 && mean.z.abs() < 0.05, "{mean}");
        // No two samples coincide: the nearest pair is more than half the spacing apart.
        let spacing = (std::f32::consts::TAU / 64.0).sqrt();
        for (i, a) in d.iter().enumerate() {
            for b in &d[i + 1..] {
                assert!(a.distance(*b) > 0.5 * spacing, "{a} {b}");
            }
        }
    }

    #[test]
    fn the_sphere_and_a_turned_pole() {
        let d = light_directions(100, Cover::Sphere, Vec3::Y);
        let below = d.iter().filter(|v| v.y < 0.0).count();
        assert_eq!(below, 50);
        let up = Vec3::new(1.0, 1.0, 0.0).normalize();
        let h = light_directions(32, Cover::Hemisphere, up);
        assert!(h.iter().all(|v| v.dot(up) > 0.0));
        assert!(light_directions(0, Cover::Sphere, Vec3::Y).is_empty());
    }
}
