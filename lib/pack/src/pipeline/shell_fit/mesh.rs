//! Triangle-list access shared by the shell fits: index validation, corners, areas and the
//! bounding box.

use anyhow::{anyhow, Result};
use glam::Vec3;

/// Checks a triangle list (three indices per triangle, each naming a position) and returns
/// the number of triangles.
pub fn triangle_count(positions: &[Vec3], indices: &[u32]) -> Result<usize> {
    if !indices.len().is_multiple_of(3) {
        return Err(anyhow!("{} indices do not make whole triangles", indices.len()));
    }
    if let Some(&i) = indices.iter().find(|&&i| i as usize >= positions.len()) {
        return Err(anyhow!(
            "index {i} names no vertex: the mesh has {} vertices",
            positions.len()
        ));
    }
    Ok(indices.len() / 3)
}

/// The corners of triangle `t` of a validated triangle list.
pub fn corners(positions: &[Vec3], indices: &[u32], t: usize) -> [Vec3; 3] {
    let i = &indices[3 * t..3 * t + 3];
    [positions[i[0] as usize], positions[i[1] as usize], positions[i[2] as usize]]
}

/// The unnormalized front-face normal: counter-clockwise corners face the viewer, as in
/// glTF. Its length is twice the triangle's area.
pub fn area_normal([a, b, c]: [Vec3; 3]) -> Vec3 {
    (b - a).cross(c - a)
}

/// The axis-aligned bounding box `(min, max)` of the points; `None` when there are none.
pub fn bounds(points: &[Vec3]) -> Option<(Vec3, Vec3)> {
    let first = *points.first()?;
    Some(points.iter().fold((first, first), |(lo, hi), &p| (lo.min(p), hi.max(p))))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn validates_indices() {
        let p = [Vec3::ZERO, Vec3::X, Vec3::Y];
        assert_eq!(triangle_count(&p, &[0, 1, 2]).unwrap(), 1);
        assert!(triangle_count(&p, &[0, 1]).is_err());
        assert!(triangle_count(&p, &[0, 1, 3]).is_err());
    }

    #[test]
    fn counter_clockwise_faces_plus_z() {
        let n = area_normal([Vec3::ZERO, Vec3::X, Vec3::Y]);
        assert_eq!(n, Vec3::Z);
        assert_eq!(bounds(&[Vec3::X, -Vec3::Y]), Some((Vec3::new(0.0, -1.0, 0.0), Vec3::X)));
        assert_eq!(bounds(&[]), None);
    }
}
