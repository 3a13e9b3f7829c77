//! Light paths: a light moving along a polyline, parameterised by normalised arc length.

use glam::Vec3;

/// The point at normalised arc length `s` ∈ [0, 1] along the polyline `path` (clamped).
/// A one-point path is a fixed position; an empty path gives the origin.
pub fn point_on_path(path: &[Vec3], s: f32) -> Vec3 {
    match path {
        [] => Vec3::ZERO,
        [p] => *p,
        _ => {
            let total: f32 = path.windows(2).map(|w| w[0].distance(w[1])).sum();
            if total <= 0.0 {
                return path[0];
            }
            let mut remaining = s.clamp(0.0, 1.0) * total;
            for w in path.windows(2) {
                let len = w[0].distance(w[1]);
                if remaining <= len && len > 0.0 {
                    return w[0].lerp(w[1], remaining / len);
                }
                remaining -= len;
            }
            path[path.len() - 1]
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arc_length_parameterisation() {
        // Segments of length 1 and 3: s = 0.5 is 2 units along, i.e. 1 unit into the second.
        let path = [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 3.0, 0.0)];
        assert!(point_on_path(&path, 0.5).distance(Vec3::new(1.0, 1.0, 0.0)) < 1e-6);
        assert!(point_on_path(&path, 0.125).distance(Vec3::new(0.5, 0.0, 0.0)) < 1e-6);
        assert_eq!(point_on_path(&path, 0.0), Vec3::ZERO);
        assert_eq!(point_on_path(&path, 1.0), Vec3::new(1.0, 3.0, 0.0));
        assert_eq!(point_on_path(&path, 7.0), Vec3::new(1.0, 3.0, 0.0));
        assert_eq!(point_on_path(&[Vec3::ONE], 0.3), Vec3::ONE);
    }
}
