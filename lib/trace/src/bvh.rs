//! Scene geometry in world space at one parameter point, with an obvhs CWBVH over it.

use glam::{Mat3, Mat4, Vec2, Vec3, Vec3A};
use obvhs::cwbvh::builder::build_cwbvh_from_tris;
use obvhs::cwbvh::CwBvh;
use obvhs::ray::{Ray, RayHit};
use obvhs::triangle::Triangle;
use obvhs::BvhBuildParams;
use pis_scene::{Frame, Scene};
use std::time::Duration;

/// Where a world triangle came from.
#[derive(Clone, Copy, Debug)]
struct TriangleSource {
    object: u32,
    /// [`Scene::reflector_of`] the object.
    reflector: u32,
    primitive: u32,
    /// Index of the triangle's first index in the primitive's index list.
    first_index: u32,
}

/// Per-object placement at this parameter point.
#[derive(Clone, Copy, Debug)]
struct Placement {
    object_from_world: Mat4,
    normal_matrix: Mat3,
}

/// A ray–triangle hit.
#[derive(Clone, Copy, Debug)]
pub struct Hit {
    /// Distance along the (unit) ray direction.
    pub t: f32,
    /// Index of the world triangle.
    pub triangle: u32,
    /// Index of the object (into [`Scene::objects`]).
    pub object: u32,
}

/// The geometry the tracer intersects: every object's triangles placed in the world.
pub struct SceneGeometry<'s> {
    scene: &'s Scene,
    triangles: Vec<Triangle>,
    sources: Vec<TriangleSource>,
    placements: Vec<Placement>,
    /// [`Scene::reflector_of`] every object.
    pub reflectors: Vec<u32>,
    bvh: Option<CwBvh>,
    /// Axis-aligned bounds of all triangles (min, max); zero when empty.
    pub bounds: (Vec3, Vec3),
}

/// The geometry of a hit, interpolated.
#[derive(Clone, Copy, Debug)]
pub struct SurfacePoint {
    pub position: Vec3,
    /// Position in object space (for coherent sampling).
    pub object_position: Vec3,
    /// Geometric normal (unit, world), facing against the incoming ray.
    pub geometric_normal: Vec3,
    /// Interpolated shading normal (unit, world), on the same side as `geometric_normal`.
    pub normal: Vec3,
    /// True when the ray hit the front side (the side the triangle winding faces).
    pub front_face: bool,
    pub uv: Vec2,
    /// Index into [`Scene::materials`].
    pub material: usize,
    pub object: u32,
}

impl<'s> SceneGeometry<'s> {
    /// Places every object of `scene` with the instances of `frame` and builds the BVH.
    pub fn build(scene: &'s Scene, frame: &Frame) -> SceneGeometry<'s> {
        let mut triangles = Vec::new();
        let mut sources = Vec::new();
        let mut placements = Vec::with_capacity(scene.objects.len());
        let reflectors = scene.reflectors();
        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        for (o, object) in scene.objects.iter().enumerate() {
            let m = frame.instances.get(o).map(|i| i.world_from_object).unwrap_or(Mat4::IDENTITY);
            placements.push(Placement {
                object_from_world: m.inverse(),
                normal_matrix: Mat3::from_mat4(m).inverse().transpose(),
            });
            for (p, prim) in object.primitives.iter().enumerate() {
                let world: Vec<Vec3> = prim.positions.iter().map(|&v| m.transform_point3(v)).collect();
                for (k, tri) in prim.indices.chunks_exact(3).enumerate() {
                    let v = |i: u32| world.get(i as usize).copied();
                    let (Some(a), Some(b), Some(c)) = (v(tri[0]), v(tri[1]), v(tri[2])) else {
                        continue;
                    };
                    if (b - a).cross(c - a).length_squared() <= 0.0 || !(a + b + c).is_finite() {
                        continue;
                    }
                    for q in [a, b, c] {
                        lo = lo.min(q);
                        hi = hi.max(q);
                    }
                    triangles.push(Triangle { v0: a.into(), v1: b.into(), v2: c.into() });
                    sources.push(TriangleSource {
                        object: o as u32,
                        reflector: reflectors[o],
                        primitive: p as u32,
                        first_index: (k * 3) as u32,
                    });
                }
            }
        }
        let bvh = if triangles.is_empty() {
            lo = Vec3::ZERO;
            hi = Vec3::ZERO;
            None
        } else {
            Some(build_cwbvh_from_tris(&triangles, BvhBuildParams::medium_build(), &mut Duration::default()))
        };
        SceneGeometry { scene, triangles, sources, placements, reflectors, bvh, bounds: (lo, hi) }
    }

    /// Number of world triangles.
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// The closest hit along `origin + t·dir`, t in (0, `tmax`), ignoring the triangles of
    /// every part of reflector `skip` ([`Scene::reflector_of`]) when given.
    pub fn closest(&self, origin: Vec3, dir: Vec3, tmax: f32, skip: Option<u32>) -> Option<Hit> {
        let bvh = self.bvh.as_ref()?;
        let ray = Ray::new(Vec3A::from(origin), Vec3A::from(dir), 0.0, tmax);
        let mut hit = RayHit::none();
        let found = bvh.ray_traverse(ray, &mut hit, |r, id| {
            let tri = bvh.primitive_indices[id] as usize;
            if skip.is_some_and(|s| self.sources[tri].reflector == s) {
                return f32::INFINITY;
            }
            self.triangles[tri].intersect(r)
        });
        if !found {
            return None;
        }
        let tri = bvh.primitive_indices[hit.primitive_id as usize];
        Some(Hit { t: hit.t, triangle: tri, object: self.sources[tri as usize].object })
    }

    /// True when anything blocks the segment `origin + t·dir`, t in (0, `tmax`).
    pub fn occluded(&self, origin: Vec3, dir: Vec3, tmax: f32) -> bool {
        let Some(bvh) = self.bvh.as_ref() else { return false };
        let ray = Ray::new(Vec3A::from(origin), Vec3A::from(dir), 0.0, tmax);
        !bvh.ray_traverse_miss(ray, |r, id| self.triangles[bvh.primitive_indices[id] as usize].intersect(r))
    }

    /// Every hit along the ray up to `tmax`, nearest first (ties broken by triangle index).
    pub fn all_hits(&self, origin: Vec3, dir: Vec3, tmax: f32) -> Vec<Hit> {
        let Some(bvh) = self.bvh.as_ref() else { return Vec::new() };
        let ray = Ray::new(Vec3A::from(origin), Vec3A::from(dir), 0.0, tmax);
        let mut hits = Vec::new();
        bvh.ray_traverse_anyhit(ray, |r, id| {
            let tri = bvh.primitive_indices[id];
            let t = self.triangles[tri as usize].intersect(r);
            if t < tmax {
                hits.push(Hit { t, triangle: tri, object: self.sources[tri as usize].object });
            }
        });
        hits.sort_by(|a, b| a.t.total_cmp(&b.t).then(a.triangle.cmp(&b.triangle)));
        hits.dedup_by(|a, b| a.triangle == b.triangle);
        hits
    }

    /// Interpolated surface attributes of `hit` on the ray with direction `dir`.
    pub fn surface(&self, hit: &Hit, origin: Vec3, dir: Vec3) -> SurfacePoint {
        let tri = &self.triangles[hit.triangle as usize];
        let src = self.sources[hit.triangle as usize];
        let prim = &self.scene.objects[src.object as usize].primitives[src.primitive as usize];
        let (a, b, c) = (Vec3::from(tri.v0), Vec3::from(tri.v1), Vec3::from(tri.v2));
        let p = origin + dir * hit.t;
        // Barycentrics from sub-triangle areas.
        let n = (b - a).cross(c - a);
        let inv = 1.0 / n.length_squared();
        let w1 = (p - a).cross(c - a).dot(n) * inv;
        let w2 = (b - a).cross(p - a).dot(n) * inv;
        let w0 = 1.0 - w1 - w2;
        let idx = |k: u32| prim.indices[(src.first_index + k) as usize] as usize;
        let (i0, i1, i2) = (idx(0), idx(1), idx(2));
        let place = &self.placements[src.object as usize];
        let ng = n.normalize();
        let front_face = ng.dot(dir) < 0.0;
        let geometric_normal = if front_face { ng } else { -ng };
        let mut normal = match (prim.normals.get(i0), prim.normals.get(i1), prim.normals.get(i2)) {
            (Some(&n0), Some(&n1), Some(&n2)) => {
                let ns = place.normal_matrix * (n0 * w0 + n1 * w1 + n2 * w2);
                let ns = ns.normalize_or_zero();
                if ns == Vec3::ZERO { ng } else { ns }
            }
            _ => ng,
        };
        if normal.dot(geometric_normal) < 0.0 {
            normal = -normal;
        }
        let uv = match (prim.uvs.get(i0), prim.uvs.get(i1), prim.uvs.get(i2)) {
            (Some(&u0), Some(&u1), Some(&u2)) => u0 * w0 + u1 * w1 + u2 * w2,
            _ => Vec2::ZERO,
        };
        SurfacePoint {
            position: p,
            object_position: place.object_from_world.transform_point3(p),
            geometric_normal,
            normal,
            front_face,
            uv,
            material: prim.material,
            object: src.object,
        }
    }
}

/// Origin offset for a ray leaving surface point `p` with geometric normal `ng` towards `dir`.
pub fn offset_origin(p: Vec3, ng: Vec3, dir: Vec3) -> Vec3 {
    let eps = 1e-4 * (1.0 + p.abs().max_element());
    if dir.dot(ng) >= 0.0 { p + ng * eps } else { p - ng * eps }
}
