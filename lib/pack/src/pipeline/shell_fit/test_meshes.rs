//! Closed meshes with outward, counter-clockwise triangles for the tests.

use glam::Vec3;
use std::f32::consts::{PI, TAU};

/// An axis-aligned box: 8 vertices, 12 triangles.
pub fn cuboid(centre: Vec3, half: Vec3) -> (Vec<Vec3>, Vec<u32>) {
    let p = (0..8)
        .map(|k| {
            centre
                + half
                    * Vec3::new(
                        if k & 1 == 0 { -1.0 } else { 1.0 },
                        if k & 2 == 0 { -1.0 } else { 1.0 },
                        if k & 4 == 0 { -1.0 } else { 1.0 },
                    )
        })
        .collect();
    #[rustfmt::skip]
    let i = vec![
        0, 2, 1, 1, 2, 3, // -z
        4, 5, 6, 5, 7, 6, // +z
        0, 1, 4, 1, 5, 4, // -y
        2, 6, 3, 3, 6, 7, // +y
        0, 4, 2, 2, 4, 6, // -x
        1, 3, 5, 3, 7, 5, // +x
    ];
    (p, i)
}

/// A latitude-longitude sphere with single-vertex poles: `2 · segments · (rings − 1)`
/// triangles.
pub fn uv_sphere(centre: Vec3, radius: f32, segments: u32, rings: u32) -> (Vec<Vec3>, Vec<u32>) {
    let mut p = vec![centre + radius * Vec3::Y];
    for r in 1..rings {
        let phi = PI * r as f32 / rings as f32;
        for s in 0..segments {
            let theta = TAU * s as f32 / segments as f32;
            p.push(
                centre
                    + radius
                        * Vec3::new(phi.sin() * theta.cos(), phi.cos(), -phi.sin() * theta.sin()),
            );
        }
    }
    p.push(centre - radius * Vec3::Y);
    let ring = |r: u32, s: u32| 1 + (r - 1) * segments + s % segments;
    let south = p.len() as u32 - 1;
    let mut i = Vec::new();
    for s in 0..segments {
        i.extend([0, ring(1, s), ring(1, s + 1)]);
        i.extend([south, ring(rings - 1, s + 1), ring(rings - 1, s)]);
        for r in 1..rings - 1 {
            let (a, b, c, d) = (ring(r, s), ring(r, s + 1), ring(r + 1, s), ring(r + 1, s + 1));
            i.extend([a, c, b, b, c, d]);
        }
    }
    (p, i)
}

/// A torus around +Y with major radius `major` and tube radius `minor`; vertex
/// `v · around + u` is at angle `2πu/around` about the axis and `2πv/tube` around the tube
/// (0 on the outer equator). `2 · around · tube` triangles.
pub fn torus(major: f32, minor: f32, around: u32, tube: u32) -> (Vec<Vec3>, Vec<u32>) {
    let mut p = Vec::new();
    for v in 0..tube {
        let phi = TAU * v as f32 / tube as f32;
        for u in 0..around {
            let theta = TAU * u as f32 / around as f32;
            let rho = major + minor * phi.cos();
            p.push(Vec3::new(rho * theta.cos(), minor * phi.sin(), -rho * theta.sin()));
        }
    }
    let at = |u: u32, v: u32| (v % tube) * around + u % around;
    let mut i = Vec::new();
    for v in 0..tube {
        for u in 0..around {
            let (a, b, c, d) = (at(u, v), at(u + 1, v), at(u, v + 1), at(u + 1, v + 1));
            i.extend([a, b, c, c, b, d]);
        }
    }
    (p, i)
}

/// `n` points spread evenly over the unit sphere (a Fibonacci lattice).
pub fn sphere_points(n: usize) -> Vec<Vec3> {
    let golden = PI * (3.0 - 5.0f32.sqrt());
    (0..n)
        .map(|k| {
            let y = 1.0 - 2.0 * (k as f32 + 0.5) / n as f32;
            let r = (1.0 - y * y).sqrt();
            let a = golden * k as f32;
            Vec3::new(r * a.cos(), y, r * a.sin())
        })
        .collect()
}

#[test]
fn meshes_face_outward() {
    use super::mesh::{area_normal, corners};
    let check = |(p, i): (Vec<Vec3>, Vec<u32>), centre: Vec3| {
        for t in 0..i.len() / 3 {
            let c = corners(&p, &i, t);
            let mid = (c[0] + c[1] + c[2]) / 3.0;
            assert!(area_normal(c).dot(mid - centre) > 0.0, "triangle {t} faces inward");
        }
    };
    check(cuboid(Vec3::ONE, Vec3::new(1.0, 2.0, 3.0)), Vec3::ONE);
    check(uv_sphere(Vec3::ZERO, 1.0, 12, 8), Vec3::ZERO);
    let (p, i) = torus(2.0, 0.5, 16, 8);
    for t in 0..i.len() / 3 {
        let c = corners(&p, &i, t);
        let mid = (c[0] + c[1] + c[2]) / 3.0;
        let axis = Vec3::new(mid.x, 0.0, mid.z).normalize() * 2.0;
        assert!(area_normal(c).dot(mid - axis) > 0.0, "torus triangle {t} faces inward");
    }
}
