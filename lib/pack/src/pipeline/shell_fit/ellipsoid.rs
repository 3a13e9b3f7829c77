//! The local shell: the least-volume axis-aligned bounding ellipsoid (thesis 5.7).

use glam::{DVec3, Vec3};
use rayon::prelude::*;

/// An axis-aligned ellipsoid: the points p with Σ_k ((p − centre)_k / radii_k)² ≤ 1.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ellipsoid {
    pub centre: Vec3,
    pub radii: Vec3,
}

impl Ellipsoid {
    /// Σ_k ((p − centre)_k / radii_k)²: below 1 strictly inside, 1 on the surface.
    pub fn level(&self, p: Vec3) -> f32 {
        ((p - self.centre) / self.radii).length_squared()
    }

    /// r_x · r_y · r_z, the volume over 4π/3.
    pub fn volume(&self) -> f32 {
        self.radii.x * self.radii.y * self.radii.z
    }
}

/// Relative margin added to the fitted radii so that every vertex is strictly inside.
pub const MARGIN: f32 = 1e-4;
/// No radius is below this fraction of the largest, nor below [`MIN_RADIUS`]: a flat or
/// degenerate object still gets a solid shell.
pub const MIN_AXIS_RATIO: f64 = 1e-3;
pub const MIN_RADIUS: f32 = 1e-6;

/// Grid points per log-ratio axis in each search round, and the number of rounds.
const GRID: usize = 17;
const ROUNDS: usize = 8;

/// The local environment-map shell (thesis 5.7: "an axis-aligned bounding ellipsoid
/// centered at the object centroid with axis scales that minimize resulting volume,
/// determined using brute force optimization"): the least-volume axis-aligned ellipsoid
/// centred at `centre` that contains every point.
///
/// The search runs over the axis ratios r_y/r_x and r_z/r_x on a log grid; for each pair
/// the smallest uniform scale that contains all points is exact
/// (s = max_p sqrt(Σ_k (d_k/a_k)²)), so only the ratios are searched. Each round refines a
/// grid around the best point of the last. The log-volume is convex in the log-ratios (a
/// maximum of log-sum-exps of linear functions, plus a linear term), so the refinement
/// converges to the least volume. Every radius is at least [`MIN_AXIS_RATIO`] of the
/// largest and at least [`MIN_RADIUS`], and the radii grow by [`MARGIN`] (more if rounding
/// needs it) so that every point is strictly inside in f32. Without points, or with all
/// points at the centre, the result is a sphere of radius [`MIN_RADIUS`].
pub fn bounding_ellipsoid(positions: &[Vec3], centre: Vec3) -> Ellipsoid {
    let d: Vec<DVec3> =
        positions.iter().map(|&p| (p - centre).as_dvec3()).filter(|d| d.is_finite()).collect();
    let extent = d.iter().fold(DVec3::ZERO, |e, v| e.max(v.abs()));
    let largest = extent.max_element();
    if largest <= 0.0 {
        return Ellipsoid { centre, radii: Vec3::splat(MIN_RADIUS) };
    }
    // Every containing ellipsoid has r_k ≥ extent_k, so a point inside the ellipsoid with
    // radii `extent` is inside all of them and never sets the scale.
    let inv = DVec3::select(extent.cmpgt(DVec3::ZERO), extent.recip(), DVec3::ZERO);
    let d: Vec<DVec3> =
        d.into_iter().filter(|v| (*v * inv).length_squared() >= 1.0 - 1e-9).collect();
    let floor = (largest * MIN_AXIS_RATIO).max(MIN_RADIUS as f64);
    let e = extent.max(DVec3::splat(floor));
    // An optimum's volume is at most that of the ellipsoid through the corners of the
    // bounding box (radii √3 · extent), so each ratio is within 3^1.5 of the extents'.
    let span = 1.5 * 3f64.ln();
    let mid = [(e.y / e.x).ln(), (e.z / e.x).ln()];
    let (lo, hi) = (mid.map(|m| m - span), mid.map(|m| m + span));
    let (mut best, mut half) = (mid, [span; 2]);
    let step = 2.0 / (GRID - 1) as f64;
    for _ in 0..ROUNDS {
        let cells: Vec<[f64; 2]> = (0..GRID * GRID)
            .map(|k| {
                let at = |i: usize, a: usize| {
                    (best[a] + half[a] * (step * i as f64 - 1.0)).clamp(lo[a], hi[a])
                };
                [at(k % GRID, 0), at(k / GRID, 1)]
            })
            .collect();
        let scored: Vec<f64> = cells.par_iter().map(|c| log_volume(&d, *c)).collect();
        let k = (0..scored.len()).fold(0, |b, k| if scored[k] < scored[b] { k } else { b });
        best = cells[k];
        half = half.map(|h| 2.0 * step * h);
    }
    let axes = DVec3::new(1.0, best[0].exp(), best[1].exp());
    let radii = (axes * scale(&d, axes)).max(DVec3::splat(floor)).as_vec3();
    let mut fit = Ellipsoid { centre, radii: radii * (1.0 + MARGIN) };
    while positions.iter().any(|&p| p.is_finite() && fit.level(p) >= 1.0) {
        fit.radii *= 1.0 + MARGIN;
    }
    fit
}

/// The smallest s with every point inside the ellipsoid of radii s · axes.
fn scale(d: &[DVec3], axes: DVec3) -> f64 {
    d.iter().map(|v| (*v / axes).length_squared()).fold(0.0, f64::max).sqrt()
}

/// ln(r_x r_y r_z) of the smallest containing ellipsoid with ratios e^c.
fn log_volume(d: &[DVec3], c: [f64; 2]) -> f64 {
    3.0 * scale(d, DVec3::new(1.0, c[0].exp(), c[1].exp())).ln() + c[0] + c[1]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pipeline::shell_fit::test_meshes::{sphere_points, uv_sphere};

    fn contains_all(e: &Ellipsoid, points: &[Vec3]) {
        for p in points {
            assert!(e.level(*p) < 1.0, "{p} is not strictly inside {e:?}");
        }
    }

    #[test]
    fn recovers_a_known_ellipsoid() {
        let centre = Vec3::new(1.0, -2.0, 0.5);
        let radii = Vec3::new(3.0, 1.0, 0.5);
        let points: Vec<Vec3> =
            sphere_points(2000).into_iter().map(|u| centre + u * radii).collect();
        let e = bounding_ellipsoid(&points, centre);
        contains_all(&e, &points);
        let rel = (e.radii / radii - Vec3::ONE).abs().max_element();
        assert!(rel < 0.03, "{:?} vs {radii}", e.radii);
    }

    #[test]
    fn a_sphere_gives_equal_radii() {
        let (points, _) = uv_sphere(Vec3::ZERO, 2.0, 48, 24);
        let e = bounding_ellipsoid(&points, Vec3::ZERO);
        contains_all(&e, &points);
        assert!((e.radii.max_element() / e.radii.min_element() - 1.0) < 0.01, "{:?}", e.radii);
        assert!((e.radii.x - 2.0).abs() < 0.02);
    }

    #[test]
    fn never_larger_than_the_bounding_sphere() {
        // A box's corners, an off-centre blob and a flat disc.
        let clouds: [(Vec<Vec3>, Vec3); 3] = [
            (
                (0..8)
                    .map(|k| {
                        Vec3::new((k & 1) as f32 * 4.0, (k >> 1 & 1) as f32, (k >> 2) as f32 * 0.25)
                    })
                    .collect(),
                Vec3::new(2.0, 0.5, 0.125),
            ),
            (
                sphere_points(500)
                    .iter()
                    .enumerate()
                    .map(|(k, u)| *u * (1.0 + (k % 7) as f32 * 0.3) + Vec3::X * 0.4)
                    .collect(),
                Vec3::ZERO,
            ),
            (
                sphere_points(300).iter().map(|u| Vec3::new(u.x, 0.0, u.z) * 5.0).collect(),
                Vec3::ZERO,
            ),
        ];
        for (points, centre) in &clouds {
            let e = bounding_ellipsoid(points, *centre);
            contains_all(&e, points);
            let r = points.iter().map(|p| p.distance(*centre)).fold(0.0, f32::max);
            assert!(e.volume() <= r * r * r * (1.0 + 1e-3), "{:?} vs sphere {r}", e.radii);
            assert!(e.radii.min_element() > 0.0);
        }
        // The box's corners are on the √3-scaled box ellipsoid, which is the optimum.
        let e = bounding_ellipsoid(&clouds[0].0, clouds[0].1);
        let want = Vec3::new(2.0, 0.5, 0.125) * 3f32.sqrt();
        assert!((e.radii / want - Vec3::ONE).abs().max_element() < 0.01, "{:?}", e.radii);
    }

    #[test]
    fn degenerate_inputs() {
        assert_eq!(bounding_ellipsoid(&[], Vec3::ONE).radii, Vec3::splat(MIN_RADIUS));
        assert_eq!(bounding_ellipsoid(&[Vec3::ONE; 3], Vec3::ONE).radii, Vec3::splat(MIN_RADIUS));
        let e = bounding_ellipsoid(&[Vec3::X, -Vec3::X], Vec3::ZERO);
        contains_all(&e, &[Vec3::X, -Vec3::X]);
        assert!(e.radii.x < 1.01 && e.radii.y > 0.0 && e.radii.z > 0.0, "{:?}", e.radii);
    }
}
