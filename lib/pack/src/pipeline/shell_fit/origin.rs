//! The environment-map origin of a reflective object (thesis 5.4).

use anyhow::{anyhow, Result};
use glam::{DVec3, Vec3};

use super::mesh::{area_normal, corners, triangle_count};

/// The object's environment-map origin: the area-weighted average of its triangle centroids
/// (thesis 5.4: "The EM origin is chosen as an area-weighted average of the object's
/// triangle centroids"). Reflection-ray hits with the shell, less this point, index the
/// cube map.
///
/// A mesh of zero total area gives the mean of its vertices; a mesh without vertices, or
/// with indices that do not make whole triangles of its vertices, is an error. Sums run in
/// f64 in triangle order, so the result is deterministic.
pub fn origin(positions: &[Vec3], indices: &[u32]) -> Result<Vec3> {
    if positions.is_empty() {
        return Err(anyhow!("the mesh has no vertices: it has no environment-map origin"));
    }
    let triangles = triangle_count(positions, indices)?;
    let (mut weighted, mut area) = (DVec3::ZERO, 0.0f64);
    for t in 0..triangles {
        let c = corners(positions, indices, t);
        let a = area_normal(c).as_dvec3().length() * 0.5;
        if a.is_finite() {
            weighted += a * (c[0].as_dvec3() + c[1].as_dvec3() + c[2].as_dvec3()) / 3.0;
            area += a;
        }
    }
    if area > 0.0 {
        return Ok((weighted / area).as_vec3());
    }
    let sum = positions.iter().fold(DVec3::ZERO, |s, p| s + p.as_dvec3());
    Ok((sum / positions.len() as f64).as_vec3())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weights_centroids_by_area() {
        // A unit right triangle at x = 0 and one four times its area at x = 10.
        let p = [
            Vec3::ZERO,
            Vec3::X,
            Vec3::Y,
            Vec3::new(10.0, 0.0, 0.0),
            Vec3::new(12.0, 0.0, 0.0),
            Vec3::new(10.0, 2.0, 0.0),
        ];
        let o = origin(&p, &[0, 1, 2, 3, 4, 5]).unwrap();
        let c1 = Vec3::new(1.0 / 3.0, 1.0 / 3.0, 0.0);
        let c2 = Vec3::new(32.0 / 3.0, 2.0 / 3.0, 0.0);
        assert!(o.distance((c1 + 4.0 * c2) / 5.0) < 1e-5, "{o}");
    }

    #[test]
    fn closed_box_centre() {
        let (p, i) = crate::pipeline::shell_fit::test_meshes::cuboid(
            Vec3::new(1.0, 2.0, 3.0),
            Vec3::new(2.0, 1.0, 0.5),
        );
        assert!(origin(&p, &i).unwrap().distance(Vec3::new(1.0, 2.0, 3.0)) < 1e-5);
    }

    #[test]
    fn degenerate_and_empty() {
        let p = [Vec3::ZERO, Vec3::X, Vec3::new(2.0, 0.0, 0.0), Vec3::new(3.0, 3.0, 0.0)];
        // Collinear corners: zero area, so the mean of all four vertices.
        assert_eq!(origin(&p, &[0, 1, 2]).unwrap(), Vec3::new(1.5, 0.75, 0.0));
        assert_eq!(origin(&p, &[]).unwrap(), Vec3::new(1.5, 0.75, 0.0));
        assert!(origin(&[], &[]).is_err());
        assert!(origin(&p, &[0, 1, 9]).is_err());
    }
}
