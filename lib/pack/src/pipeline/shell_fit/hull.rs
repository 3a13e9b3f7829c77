//! Which triangles of a reflector lie on its convex hull (thesis 5.7).

use anyhow::Result;
use glam::Vec3;
use rayon::prelude::*;

use super::mesh::{area_normal, bounds, corners, triangle_count};
use super::point_tree::PointTree;

/// A vertex this fraction of the bounding-box diagonal in front of a triangle's plane still
/// counts as on it.
pub const HULL_TOLERANCE: f32 = 1e-4;
/// A triangle whose height is below this fraction of its longest edge has no reliable plane
/// and counts as degenerate.
pub const DEGENERATE: f32 = 1e-6;

/// Per triangle, whether it lies on the object's convex hull (thesis 5.7: "polygons lying
/// on the convex hull are rendered only with the distant EM, since they can never exhibit
/// self-reflections"). A triangle is on the hull when every vertex of the mesh lies on or
/// behind its plane, within [`HULL_TOLERANCE`] of the bounding-box diagonal. Its front is
/// the counter-clockwise side, the side that reflects (glTF's convention): the inside of a
/// bowl faces the rest of the bowl and is not on the hull. Degenerate (zero-area)
/// triangles are not on the hull.
///
/// Only the points farthest along a triangle's normal decide, and those are hull vertices;
/// a bounding-box tree over the vertices finds them by branch and bound, so a closed convex
/// mesh costs about a logarithmic number of boxes per triangle rather than a scan of every
/// vertex. Triangles run in parallel; the result is deterministic. Indices that do not make
/// whole triangles of the vertices are an error.
pub fn convex_hull_triangles(positions: &[Vec3], indices: &[u32]) -> Result<Vec<bool>> {
    let triangles = triangle_count(positions, indices)?;
    let finite: Vec<Vec3> = positions.iter().copied().filter(|p| p.is_finite()).collect();
    let Some((lo, hi)) = bounds(&finite) else {
        return Ok(vec![false; triangles]);
    };
    // Planes are evaluated about the box's centre, where f32 keeps the most precision.
    let mid = (lo + hi) * 0.5;
    let local: Vec<Vec3> = finite.iter().map(|p| *p - mid).collect();
    let tolerance = HULL_TOLERANCE * (hi - lo).length();
    let tree = PointTree::new(&local);
    Ok((0..triangles)
        .into_par_iter()
        .map(|t| {
            let c = corners(positions, indices, t).map(|p| p - mid);
            let normal = area_normal(c);
            let longest = (c[1] - c[0])
                .length_squared()
                .max((c[2] - c[1]).length_squared())
                .max((c[0] - c[2]).length_squared());
            if !normal.is_finite() || normal.length() <= DEGENERATE * longest || longest == 0.0 {
                return false;
            }
            let n = normal.normalize();
            !tree.any_above(n, n.dot((c[0] + c[1] + c[2]) / 3.0) + tolerance)
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pipeline::shell_fit::test_meshes::{cuboid, torus, uv_sphere};

    #[test]
    fn convex_meshes_are_all_hull() {
        let (p, i) = cuboid(Vec3::new(5.0, 0.0, -3.0), Vec3::new(1.0, 0.1, 2.0));
        assert!(convex_hull_triangles(&p, &i).unwrap().iter().all(|&h| h));
        let (p, i) = uv_sphere(Vec3::new(100.0, 2.0, 0.0), 0.5, 32, 16);
        assert!(convex_hull_triangles(&p, &i).unwrap().iter().all(|&h| h));
    }

    #[test]
    fn inward_faces_are_not_hull() {
        let (p, mut i) = cuboid(Vec3::ZERO, Vec3::ONE);
        i.chunks_exact_mut(3).for_each(|t| t.swap(1, 2));
        assert!(convex_hull_triangles(&p, &i).unwrap().iter().all(|&h| !h));
    }

    #[test]
    fn a_dent_takes_its_triangles_off_the_hull() {
        let (mut p, i) = uv_sphere(Vec3::ZERO, 1.0, 24, 12);
        let dent = 1 + 5 * 24 + 7;
        p[dent] *= 0.9;
        let hull = convex_hull_triangles(&p, &i).unwrap();
        for (t, tri) in i.chunks_exact(3).enumerate() {
            assert_eq!(hull[t], !tri.contains(&(dent as u32)), "triangle {t}: {tri:?}");
        }
    }

    #[test]
    fn the_inside_of_a_torus_is_not_hull() {
        let (around, tube) = (48, 24);
        let (p, i) = torus(2.0, 0.5, around, tube);
        let hull = convex_hull_triangles(&p, &i).unwrap();
        for (t, &h) in hull.iter().enumerate() {
            // Triangle t is in the tube row t / (2 · around), between angles φ and φ + step.
            let step = 360.0 / tube as f32;
            let phi = (t / (2 * around as usize)) as f32 * step;
            let (a, b) = (phi, phi + step);
            if b <= 60.0 || a >= 300.0 {
                assert!(h, "outer triangle {t} at {a}°");
            } else if a >= 120.0 && b <= 240.0 {
                assert!(!h, "inner triangle {t} at {a}°");
            }
        }
    }

    #[test]
    fn degenerate_triangles_are_not_hull() {
        let (mut p, mut i) = cuboid(Vec3::ZERO, Vec3::ONE);
        p.push(Vec3::new(1.0, 0.0, -1.0)); // between vertices 1 and 3
        i.extend([0, 0, 1, 1, 3, 8]);
        assert_eq!(convex_hull_triangles(&p, &i).unwrap()[12..], [false, false]);
        assert_eq!(convex_hull_triangles(&p, &[]).unwrap(), Vec::<bool>::new());
        assert!(convex_hull_triangles(&p, &[0, 1, 99]).is_err());
    }

    #[test]
    fn fifty_thousand_triangles() {
        let (p, i) = uv_sphere(Vec3::ZERO, 1.0, 160, 160);
        assert!(i.len() / 3 > 50_000);
        assert!(convex_hull_triangles(&p, &i).unwrap().iter().all(|&h| h));
        let (p, i) = torus(3.0, 1.0, 250, 100);
        let hull = convex_hull_triangles(&p, &i).unwrap();
        let on = hull.iter().filter(|&&h| h).count();
        assert!(on > 20_000 && on < 30_000, "{on} of {} on the hull", hull.len());
    }
}
