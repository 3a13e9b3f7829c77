//! The minimum-area bounding rectangle of the transformed texture coordinates over a set of
//! discrete directions (thesis 3.2, step 5); it fixes the rotation eq. 3.1 leaves free.

use glam::DVec2;

/// The best of `directions` rotations θ = k·90°/directions: returns θ and the rotated
/// points' bounding box (min, max). The points are rotated by −θ.
pub fn min_area_rectangle(points: &[DVec2], directions: u32) -> (f64, DVec2, DVec2) {
    let mut best = (f64::INFINITY, 0.0, DVec2::ZERO, DVec2::ZERO);
    for k in 0..directions.max(1) {
        let theta = k as f64 * std::f64::consts::FRAC_PI_2 / directions.max(1) as f64;
        let (lo, hi) = bounds(points, theta);
        let area = (hi.x - lo.x) * (hi.y - lo.y);
        if area < best.0 {
            best = (area, theta, lo, hi);
        }
    }
    (best.1, best.2, best.3)
}

/// Bounding box of the points rotated by −θ.
pub fn bounds(points: &[DVec2], theta: f64) -> (DVec2, DVec2) {
    let rot = DVec2::from_angle(-theta);
    points.iter().fold(
        (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
        |(lo, hi), p| {
            let q = rot.rotate(*p);
            (lo.min(q), hi.max(q))
        },
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_rotated_rectangle_is_found() {
        let rot = DVec2::from_angle(0.3);
        let pts: Vec<DVec2> = [(0.0, 0.0), (10.0, 0.0), (10.0, 2.0), (0.0, 2.0)]
            .iter()
            .map(|&(x, y)| rot.rotate(DVec2::new(x, y)))
            .collect();
        let (theta, lo, hi) = min_area_rectangle(&pts, 90);
        let area = (hi.x - lo.x) * (hi.y - lo.y);
        assert!(area < 20.0 * 1.02, "θ {theta} area {area}");
    }
}
