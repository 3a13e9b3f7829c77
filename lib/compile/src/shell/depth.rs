//! Depth shells (SPEC.md 8.5; seed 004's depth images, Szirmay-Kalos et al.'s distance
//! impostors): a star-shaped shell about the environment-map origin whose radius in every
//! direction is the distance from the origin to the rest of the scene. Its **depth cube**
//! holds that distance per texel; a reflection ray is marched against it — uniform steps in
//! the square root of the ray parameter up to the far sphere, then regula falsi between the
//! last step in front of the surface and the first behind it — and the point it reaches,
//! less the origin, looks up the radiance cube as a fixed shell's hit does. Where the
//! reflected geometry is off any simple shell (a pedestal under the object, a box beside
//! it), the lookup follows it and the reflection keeps its parallax off the sampled views.
//!
//! The depth cube is not stored: writer and reader compute it from the file's meshes with
//! [`DepthCube::cast`]. WGSL twins in `lib/play/src/shell.wgsl`: `depth_distance`,
//! `depth_hit`, same order of operations.

use std::time::Duration;

use glam::{DVec3, Vec3, Vec3A};
use obvhs::cwbvh::builder::build_cwbvh_from_tris;
use obvhs::ray::{Ray, RayHit};
use obvhs::triangle::Triangle;
use obvhs::BvhBuildParams;
use rayon::prelude::*;

use super::cube::{cube_bilinear, face_vector};
use crate::filter::Taps;
use crate::TextureLayout;

/// Regula-falsi iterations after the march finds a step behind the surface.
pub const REFINE: u32 = 4;

/// Largest face size of a depth cube (SPEC.md 7.3).
pub const MAX_SIZE: u32 = 256;

/// Largest number of march steps (SPEC.md 7.3).
pub const MAX_STEPS: u32 = 64;

/// The distance from a depth shell's origin to the scene, per texel of an `size × size`
/// cube (one MIP level; texel (face, i, j) at `face·size² + j·size + i`, SPEC.md 8.2's
/// faces), each at most `far`.
#[derive(Clone, Debug, PartialEq)]
pub struct DepthCube {
    pub size: u32,
    pub far: f32,
    pub distances: Vec<f32>,
}

impl DepthCube {
    /// The depth cube about `origin` of the world-space `triangles` (the scene less the
    /// object the shell belongs to): per texel, the distance along the unit direction of the
    /// texel's centre (`face_vector`, normalized, in `f32`) to the nearest triangle, either
    /// side, in (0, `far`), else `far`. Degenerate and non-finite triangles are skipped.
    pub fn cast(origin: Vec3, size: u32, far: f32, triangles: &[[Vec3; 3]]) -> DepthCube {
        let tris: Vec<Triangle> = triangles
            .iter()
            .filter(|[a, b, c]| {
                (*b - *a).cross(*c - *a).length_squared() > 0.0 && (*a + *b + *c).is_finite()
            })
            .map(|&[a, b, c]| Triangle { v0: a.into(), v1: b.into(), v2: c.into() })
            .collect();
        let bvh = (!tris.is_empty()).then(|| {
            build_cwbvh_from_tris(&tris, BvhBuildParams::medium_build(), &mut Duration::default())
        });
        let n = size as usize;
        let distances = (0..6 * n * n)
            .into_par_iter()
            .map(|k| {
                let (face, j, i) = ((k / (n * n)) as u32, (k / n) % n, k % n);
                let sc = 2.0 * (i as f64 + 0.5) / n as f64 - 1.0;
                let tc = 2.0 * (j as f64 + 0.5) / n as f64 - 1.0;
                let dir = face_vector(face, sc, tc).as_vec3().normalize();
                let Some(bvh) = &bvh else { return far };
                let ray = Ray::new(Vec3A::from(origin), Vec3A::from(dir), 0.0, far);
                let mut hit = RayHit::none();
                let found = bvh.ray_traverse(ray, &mut hit, |r, id| {
                    tris[bvh.primitive_indices[id] as usize].intersect(r)
                });
                if found && hit.t < far {
                    hit.t
                } else {
                    far
                }
            })
            .collect();
        DepthCube { size, far, distances }
    }

    /// The cube's one-level layout.
    pub fn layout(&self) -> TextureLayout {
        TextureLayout { levels: 1, ..TextureLayout::cube(self.size) }
    }

    /// The distance in direction `q` (not normalized): the bilinear, seamless lookup of the
    /// cube ([`cube_bilinear`] at level 0).
    pub fn distance(&self, q: DVec3, taps: &mut Taps) -> f64 {
        *taps = Taps::default();
        cube_bilinear(&self.layout(), q, 0, 1.0, taps);
        taps.sorted().map(|(c, w)| w as f64 * self.distances[c as usize] as f64).sum()
    }
}

/// The larger root of a·t² + 2b·t + c = 0, or −1 when there is none.
fn quadratic_far(a: f64, b: f64, c: f64) -> f64 {
    let disc = b * b - a * c;
    if a <= 0.0 || disc < 0.0 {
        return -1.0;
    }
    (-b + disc.sqrt()) / a
}

/// Where the ray `p + t·r` meets the depth shell about `origin` (`r` need not be
/// normalized): with q(t) = p + t·r − origin and f(t) = |q(t)| − D(q(t)), the first of
/// `steps` samples t_i = t_end·(i/steps)² (t_end where the ray leaves the sphere of radius
/// `far`) with f ≥ 0, then [`REFINE`] regula-falsi steps between it and the sample before,
/// and the secant's root of the last bracket. 0 where f(0) ≥ 0 (p lies behind the shell),
/// −1 where p lies outside the far sphere. f(t_end) ≥ 0 since no distance exceeds `far`.
pub fn depth_hit(cube: &DepthCube, steps: u32, origin: DVec3, p: DVec3, r: DVec3) -> f64 {
    let q0 = p - origin;
    let far = cube.far as f64;
    let t_end = quadratic_far(r.dot(r), q0.dot(r), q0.dot(q0) - far * far);
    if t_end < 0.0 {
        return -1.0;
    }
    let mut taps = Taps::default();
    let mut f = |t: f64| {
        let q = q0 + r * t;
        q.length() - cube.distance(q, &mut taps)
    };
    let (mut t0, mut f0) = (0.0, f(0.0));
    if f0 >= 0.0 {
        return 0.0;
    }
    let (mut t1, mut f1) = (t_end, 0.0);
    for i in 1..=steps {
        let s = i as f64 / steps as f64;
        let t = t_end * s * s;
        let ft = f(t);
        if ft >= 0.0 {
            (t1, f1) = (t, ft);
            break;
        }
        (t0, f0) = (t, ft);
    }
    for _ in 0..REFINE {
        let tm = t0 + (t1 - t0) * f0 / (f0 - f1);
        let fm = f(tm);
        if fm >= 0.0 {
            (t1, f1) = (tm, fm);
        } else {
            (t0, f0) = (tm, fm);
        }
    }
    t0 + (t1 - t0) * f0 / (f0 - f1)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The 12 triangles of the axis-aligned box between `lo` and `hi`.
    fn box_triangles(lo: Vec3, hi: Vec3) -> Vec<[Vec3; 3]> {
        let c = |k: u32| {
            Vec3::new(
                if k & 1 == 0 { lo.x } else { hi.x },
                if k & 2 == 0 { lo.y } else { hi.y },
                if k & 4 == 0 { lo.z } else { hi.z },
            )
        };
        let quads =
            [[0, 2, 6, 4], [1, 5, 7, 3], [0, 4, 5, 1], [2, 3, 7, 6], [0, 1, 3, 2], [4, 6, 7, 5]];
        quads
            .iter()
            .flat_map(|q| [[c(q[0]), c(q[1]), c(q[2])], [c(q[0]), c(q[2]), c(q[3])]])
            .collect()
    }

    #[test]
    fn a_room_s_depth_cube_holds_the_distance_to_its_walls() {
        let room = box_triangles(Vec3::new(-2.0, -1.0, -3.0), Vec3::new(4.0, 2.0, 3.0));
        let cube = DepthCube::cast(Vec3::ZERO, 8, 100.0, &room);
        let mut taps = Taps::default();
        // Texel centres along the axes see the walls straight on, up to the texel's tilt.
        for (dir, wall) in [(DVec3::X, 4.0), (DVec3::NEG_Y, 1.0), (DVec3::Z, 3.0)] {
            let d = cube.distance(dir, &mut taps);
            assert!(d >= wall && d < wall * 1.02, "{dir}: {d}");
        }
    }

    #[test]
    fn an_empty_scene_is_the_far_sphere() {
        let cube = DepthCube::cast(Vec3::ZERO, 4, 10.0, &[]);
        assert!(cube.distances.iter().all(|&d| d == 10.0));
        let p = DVec3::new(0.1, 0.2, 0.0);
        let r = DVec3::new(0.3, -1.0, 2.0);
        let t = depth_hit(&cube, 16, DVec3::ZERO, p, r);
        assert!(((p + r * t).length() - 10.0).abs() < 1e-9, "{t}");
    }

    #[test]
    fn a_marched_ray_lands_on_the_wall_it_points_at() {
        // A room whose walls are planes: the march lands within a hundredth of the exact hit
        // wherever the depth cube is flat (away from the room's edges).
        let room = box_triangles(Vec3::splat(-2.0), Vec3::splat(2.0));
        let cube = DepthCube::cast(Vec3::ZERO, 32, 50.0, &room);
        let p = DVec3::new(0.3, -0.2, 0.1);
        for r in
            [DVec3::new(1.0, 0.2, -0.1), DVec3::new(-0.2, -1.0, 0.3), DVec3::new(0.1, 0.3, 1.0)]
        {
            let t = depth_hit(&cube, 32, DVec3::ZERO, p, r);
            let hit = p + r * t;
            let exact = (0..3)
                .filter(|&k| r[k] != 0.0)
                .map(|k| (2.0f64.copysign(r[k]) - p[k]) / r[k])
                .fold(f64::INFINITY, f64::min);
            assert!((hit - (p + r * exact)).length() < 0.02, "{r}: {hit} vs {}", p + r * exact);
        }
    }

    #[test]
    fn a_near_box_hides_the_wall_behind_it() {
        // A crate between the point and the wall: the ray stops at the crate's face, where a
        // fixed shell at the wall's distance would look up the wall.
        let mut scene = box_triangles(Vec3::splat(-5.0), Vec3::splat(5.0));
        scene.extend(box_triangles(Vec3::new(1.0, -0.5, -0.5), Vec3::new(1.5, 0.5, 0.5)));
        let cube = DepthCube::cast(Vec3::ZERO, 64, 50.0, &scene);
        let p = DVec3::new(0.0, 0.05, 0.0);
        let t = depth_hit(&cube, 32, DVec3::ZERO, p, DVec3::X);
        assert!((t - 1.0).abs() < 0.03, "{t}");
    }

    #[test]
    fn a_point_outside_the_far_sphere_misses() {
        let cube = DepthCube::cast(Vec3::ZERO, 4, 1.0, &[]);
        assert_eq!(depth_hit(&cube, 8, DVec3::ZERO, DVec3::new(2.0, 0.0, 0.0), DVec3::X), -1.0);
    }
}
