//! Where the object's reflections meet the environment: the samples that size the distant
//! shell (thesis 5.4).

use anyhow::{anyhow, Result};
use glam::Vec3;
use rayon::prelude::*;

use super::mesh::{area_normal, corners, triangle_count};

/// Surface points sampled per object.
pub const MAX_SURFACE_SAMPLES: usize = 4096;

/// A point on the object's surface with its triangle's unit front-face normal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceSample {
    pub point: Vec3,
    pub normal: Vec3,
}

/// [`MAX_SURFACE_SAMPLES`] points spread over the surface by area, stratified: sample k
/// sits where the running area reaches (k + ½)/N of the total, at a fraction of its
/// triangle given by that position and the golden-ratio sequence, so the set is fixed for a
/// mesh. A mesh without area has no samples.
pub fn surface_samples(positions: &[Vec3], indices: &[u32]) -> Result<Vec<SurfaceSample>> {
    let triangles = triangle_count(positions, indices)?;
    let mut running = Vec::with_capacity(triangles);
    let mut total = 0.0f64;
    for t in 0..triangles {
        let a = f64::from(area_normal(corners(positions, indices, t)).length());
        total += if a.is_finite() { a } else { 0.0 };
        running.push(total);
    }
    if total <= 0.0 || !total.is_finite() {
        return Ok(Vec::new());
    }
    let n = MAX_SURFACE_SAMPLES;
    let golden = (5f64.sqrt() - 1.0) * 0.5;
    Ok((0..n)
        .map(|k| {
            let s = (k as f64 + 0.5) / n as f64 * total;
            let t = running.partition_point(|&r| r <= s).min(triangles - 1);
            let start = if t > 0 { running[t - 1] } else { 0.0 };
            let f = ((s - start) / (running[t] - start)).clamp(0.0, 1.0).sqrt() as f32;
            let g = (k as f64 * golden).fract() as f32;
            let [a, b, c] = corners(positions, indices, t);
            let point = a * (1.0 - f) + b * (f * (1.0 - g)) + c * (f * g);
            SurfaceSample { point, normal: area_normal([a, b, c]).normalize() }
        })
        .collect())
}

/// The world points where the object's reflections meet the environment, over the
/// cameras: the hits that size the distant box and sphere ([`super::distant_box`],
/// [`super::distant_sphere`]) at "the average distance to environmental geometry"
/// (thesis 5.4).
///
/// `positions` and `indices` are the object's world-space triangles, `eyes` the camera
/// positions (one per parameter point), and `cast(origin, dir)` the distance along the
/// unit `dir` to the nearest scene surface that is not the object. For each of the
/// [`surface_samples`] and each eye, the view direction (point − eye, normalized) is
/// reflected about the triangle's geometric normal and cast; a hit adds origin + t · dir.
/// Triangles whose front (counter-clockwise) side faces away from the eye are skipped: on a
/// closed object they are hidden behind its front. The hits come sample by sample, eye by
/// eye, so the result is deterministic for a deterministic `cast`. A non-finite eye or
/// indices that do not make whole triangles of the vertices are an error.
pub fn hit_points(
    positions: &[Vec3],
    indices: &[u32],
    eyes: &[Vec3],
    cast: impl Fn(Vec3, Vec3) -> Option<f32> + Sync,
) -> Result<Vec<Vec3>> {
    if let Some(e) = eyes.iter().find(|e| !e.is_finite()) {
        return Err(anyhow!("camera position {e} is not finite"));
    }
    let samples = surface_samples(positions, indices)?;
    Ok(samples
        .par_iter()
        .filter(|s| s.normal.is_finite())
        .flat_map_iter(|s| {
            eyes.iter().filter_map(|&eye| {
                let view = (s.point - eye).normalize_or_zero();
                let cos = view.dot(s.normal);
                if cos >= 0.0 {
                    return None;
                }
                let dir = (view - 2.0 * cos * s.normal).normalize();
                let t = cast(s.point, dir).filter(|t| t.is_finite() && *t >= 0.0)?;
                Some(s.point + dir * t)
            })
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pipeline::shell_fit::distant::{distant_box, distant_sphere};
    use crate::pipeline::shell_fit::test_meshes::uv_sphere;

    /// The inside of the axis-aligned cube |x|, |y|, |z| ≤ `half`.
    fn room(half: f32) -> impl Fn(Vec3, Vec3) -> Option<f32> + Sync {
        move |o: Vec3, d: Vec3| {
            let exit = (Vec3::splat(half) * d.signum() - o) / d;
            Some(exit.min_element())
        }
    }

    #[test]
    fn samples_follow_area() {
        // Two triangles, the second three times the first's area.
        let p = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z, Vec3::Z + Vec3::X * 3.0, Vec3::Z + Vec3::Y];
        let s = surface_samples(&p, &[0, 1, 2, 3, 4, 5]).unwrap();
        assert_eq!(s.len(), MAX_SURFACE_SAMPLES);
        let first = s.iter().filter(|s| s.point.z == 0.0).count();
        assert_eq!(first, MAX_SURFACE_SAMPLES / 4);
        assert!(s.iter().all(|s| s.normal == Vec3::Z));
        assert!(s[..first]
            .iter()
            .all(|s| s.point.x >= 0.0 && s.point.y >= 0.0 && s.point.x + s.point.y <= 1.0 + 1e-6));
        assert!(surface_samples(&p, &[0, 0, 1]).unwrap().is_empty());
    }

    #[test]
    fn hits_lie_on_the_environment_and_size_the_shells() {
        let (p, i) = uv_sphere(Vec3::ZERO, 1.0, 32, 16);
        let eyes = [Vec3::new(4.0, 1.0, 0.0), Vec3::new(0.0, 1.0, 4.0), Vec3::new(-3.0, 2.0, -2.0)];
        let hits = hit_points(&p, &i, &eyes, room(6.0)).unwrap();
        // Roughly half the sphere faces each eye.
        let n = hits.len() as f32 / (MAX_SURFACE_SAMPLES * eyes.len()) as f32;
        assert!(n > 0.3 && n < 0.6, "{n}");
        assert!(
            hits.iter().all(|h| (h.abs().max_element() - 6.0).abs() < 1e-3),
            "a hit is off the walls"
        );
        assert_eq!(hits, hit_points(&p, &i, &eyes, room(6.0)).unwrap());
        let b = distant_box(Vec3::ZERO, None, &hits).unwrap();
        assert!(
            b.min.distance(Vec3::splat(-6.0)) < 1e-2 && b.max.distance(Vec3::splat(6.0)) < 1e-2,
            "{b:?}"
        );
        let s = distant_sphere(Vec3::ZERO, &hits).unwrap();
        assert!(s.radius > 6.0 && s.radius < 6.0 * 3f32.sqrt(), "{s:?}");
    }

    #[test]
    fn mirror_reflects_and_back_faces_are_skipped() {
        // A square mirror in z = 0 facing +Z under a ceiling at z = 10.
        let p = [
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(-1.0, 1.0, 0.0),
        ];
        let i = [0, 1, 2, 0, 2, 3];
        let ceiling = |o: Vec3, d: Vec3| (d.z > 0.0).then(|| (10.0 - o.z) / d.z);
        let hits = hit_points(&p, &i, &[Vec3::new(0.0, 0.0, 5.0)], ceiling).unwrap();
        assert_eq!(hits.len(), MAX_SURFACE_SAMPLES);
        // Seen from the eye's mirror image (0, 0, −5), the hits are the mirror scaled by 3.
        assert!(hits.iter().all(|h| (h.z - 10.0).abs() < 1e-4
            && h.x.abs() <= 3.0 + 1e-4
            && h.y.abs() <= 3.0 + 1e-4));
        assert!(hit_points(&p, &i, &[Vec3::new(0.0, 0.0, -5.0)], ceiling).unwrap().is_empty());
        assert!(hit_points(&p, &i, &[Vec3::NAN], ceiling).is_err());
        assert!(hit_points(&p, &[0, 1, 7], &[Vec3::Z], ceiling).is_err());
    }
}
