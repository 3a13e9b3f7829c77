//! A lens object on its own (thesis 6.4): its world-space triangles, shading normals and
//! material constants, with a BVH of its triangles alone, which the runtime's vertex rays
//! traverse instead of the whole scene's.

use std::time::Duration;

use glam::{Vec3, Vec3A};
use obvhs::cwbvh::builder::build_cwbvh_from_tris;
use obvhs::cwbvh::CwBvh;
use obvhs::ray::{Ray, RayHit};
use obvhs::triangle::Triangle;
use obvhs::BvhBuildParams;
/// The tracer's ray origin offset: one function for the tracer and the compiler.
pub use pis_scene::optics::offset_origin;

/// What the greedy paths need of a lens object's material (glTF transmission, IOR and
/// volume; pis-trace's `ShadingMaterial` for the same object).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LensMaterial {
    /// Index of refraction (≥ 1).
    pub ior: f32,
    /// Base colour, multiplied into a path where it enters the object.
    pub base: Vec3,
    /// Absorption coefficient σ per unit of world distance inside the object: a segment of
    /// length d inside multiplies the path by exp(−σ·d).
    pub sigma_a: Vec3,
}

/// A lens object's triangles in world space.
pub struct LensObject {
    pub material: LensMaterial,
    /// World positions and shading normals, per vertex.
    pub positions: Vec<Vec3>,
    pub normals: Vec<Vec3>,
    /// Three vertex indices per triangle (degenerate triangles dropped).
    pub triangles: Vec<[u32; 3]>,
    bvh_triangles: Vec<Triangle>,
    bvh: Option<CwBvh>,
}

/// A ray's hit on the lens object.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LensHit {
    pub t: f32,
    pub triangle: u32,
}

/// A point of the lens object's surface as a ray meets it, oriented against the ray: the
/// shading normal and the geometric normal face the side the ray comes from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LensSurface {
    pub position: Vec3,
    pub normal: Vec3,
    pub geometric_normal: Vec3,
    /// Whether the ray arrives from outside (against the triangle's winding normal).
    pub front_face: bool,
}

impl LensObject {
    /// A lens object from world positions, per-vertex normals (zero or missing: the face
    /// normal) and triangle indices; triangles with an index out of range, a zero area or a
    /// non-finite corner are dropped.
    pub fn new(
        material: LensMaterial,
        positions: Vec<Vec3>,
        normals: Vec<Vec3>,
        indices: &[u32],
    ) -> LensObject {
        let mut triangles = Vec::with_capacity(indices.len() / 3);
        let mut bvh_triangles = Vec::with_capacity(indices.len() / 3);
        for t in indices.chunks_exact(3) {
            let v = |i: u32| positions.get(i as usize).copied();
            let (Some(a), Some(b), Some(c)) = (v(t[0]), v(t[1]), v(t[2])) else { continue };
            if (b - a).cross(c - a).length_squared() <= 0.0 || !(a + b + c).is_finite() {
                continue;
            }
            triangles.push([t[0], t[1], t[2]]);
            bvh_triangles.push(Triangle { v0: a.into(), v1: b.into(), v2: c.into() });
        }
        let bvh = (!bvh_triangles.is_empty()).then(|| {
            build_cwbvh_from_tris(
                &bvh_triangles,
                BvhBuildParams::medium_build(),
                &mut Duration::default(),
            )
        });
        LensObject { material, positions, normals, triangles, bvh_triangles, bvh }
    }

    /// The closest hit along `origin + t·dir`, t in (0, `tmax`).
    pub fn closest(&self, origin: Vec3, dir: Vec3, tmax: f32) -> Option<LensHit> {
        let bvh = self.bvh.as_ref()?;
        let ray = Ray::new(Vec3A::from(origin), Vec3A::from(dir), 0.0, tmax);
        let mut hit = RayHit::none();
        if !bvh.ray_traverse(ray, &mut hit, |r, id| {
            self.bvh_triangles[bvh.primitive_indices[id] as usize].intersect(r)
        }) {
            return None;
        }
        Some(LensHit { t: hit.t, triangle: bvh.primitive_indices[hit.primitive_id as usize] })
    }

    /// The surface at `hit` on the ray `origin + t·dir` (pis-trace's surface point: the
    /// barycentric blend of the corners' normals, the face normal where they cancel).
    pub fn surface(&self, hit: &LensHit, origin: Vec3, dir: Vec3) -> LensSurface {
        let [i0, i1, i2] = self.triangles[hit.triangle as usize];
        let (a, b, c) =
            (self.positions[i0 as usize], self.positions[i1 as usize], self.positions[i2 as usize]);
        let p = origin + dir * hit.t;
        let w = barycentric([a, b, c], p);
        let ng = (b - a).cross(c - a).normalize();
        let front_face = ng.dot(dir) < 0.0;
        let geometric_normal = if front_face { ng } else { -ng };
        let n = |i: u32| self.normals.get(i as usize).copied();
        let mut normal = match (n(i0), n(i1), n(i2)) {
            (Some(n0), Some(n1), Some(n2)) => {
                let ns = (n0 * w[0] + n1 * w[1] + n2 * w[2]).normalize_or_zero();
                if ns == Vec3::ZERO {
                    ng
                } else {
                    ns
                }
            }
            _ => ng,
        };
        if normal.dot(geometric_normal) < 0.0 {
            normal = -normal;
        }
        LensSurface { position: p, normal, geometric_normal, front_face }
    }

    /// The area-weighted centroid of the surface: the layered environment map's origin
    /// (thesis 5.7, 6.3.2).
    pub fn centroid(&self) -> Vec3 {
        let (mut sum, mut area) = (glam::DVec3::ZERO, 0.0f64);
        for t in &self.triangles {
            let [a, b, c] = t.map(|i| self.positions[i as usize].as_dvec3());
            let w = 0.5 * (b - a).cross(c - a).length();
            sum += (a + b + c) * (w / 3.0);
            area += w;
        }
        if area > 0.0 {
            (sum / area).as_vec3()
        } else {
            Vec3::ZERO
        }
    }

    /// The winding normal of triangle `t` (unit).
    pub fn face_normal(&self, t: usize) -> Vec3 {
        let [a, b, c] = self.triangles[t].map(|i| self.positions[i as usize]);
        (b - a).cross(c - a).normalize()
    }
}

/// Barycentric coordinates of `p` in triangle `v`.
pub fn barycentric(v: [Vec3; 3], p: Vec3) -> [f32; 3] {
    let [a, b, c] = v;
    let n = (b - a).cross(c - a);
    let inv = 1.0 / n.length_squared();
    let w1 = (p - a).cross(c - a).dot(n) * inv;
    let w2 = (b - a).cross(p - a).dot(n) * inv;
    [1.0 - w1 - w2, w1, w2]
}
