//! Scene geometry in world space at one parameter point, with an obvhs CWBVH over it.
//!
//! Rays pass through the holes of materials with alpha mode MASK or BLEND
//! ([`crate::material::passes`]): every query — closest hit, shadow ray, all hits — tests
//! the coverage where it meets such a triangle. BLEND's stochastic choice is a hash of the
//! ray and the triangle, so a render stays a pure function of its inputs.

use crate::material::{alpha, has_holes, mapped_normal, passes};
use crate::sampling::hash_keys;
use crate::tangent::{attribute_frame, bend, triangle_frame};
use glam::{Mat3, Mat4, Vec2, Vec3, Vec3A};
use obvhs::cwbvh::builder::build_cwbvh_from_tris;
use obvhs::cwbvh::CwBvh;
use obvhs::ray::{Ray, RayHit};
use obvhs::triangle::Triangle;
use obvhs::BvhBuildParams;
/// The tracer's ray origin offset: one function for the tracer and the compiler.
pub use pis_scene::optics::offset_origin;
use pis_scene::{Frame, Material, Primitive, Scene, TextureRef};
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
    /// Whether its material has holes rays pass through ([`has_holes`]).
    holes: bool,
}

/// Per-object placement at this parameter point.
#[derive(Clone, Copy, Debug)]
struct Placement {
    object_from_world: Mat4,
    normal_matrix: Mat3,
    /// The linear part of object-to-world (what tangents transform by).
    tangent_matrix: Mat3,
    /// −1 where the placement mirrors (turning tangent frames' handedness), else 1.
    handedness: f32,
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
    /// Interpolated shading normal (unit, world), on the same side as `geometric_normal`;
    /// bent by the material's normal map once [`SurfacePoint::apply_normal_map`] has run.
    pub normal: Vec3,
    /// True when the ray hit the front side (the side the triangle winding faces).
    pub front_face: bool,
    /// TEXCOORD_0.
    pub uv: Vec2,
    /// TEXCOORD_1 (TEXCOORD_0 where the mesh has no second set).
    pub uv1: Vec2,
    /// Tangent and bitangent of the material's normal map (unit, world, turned with
    /// `normal` to the side the ray came from); zero without a normal map.
    pub tangent: Vec3,
    pub bitangent: Vec3,
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
            let linear = Mat3::from_mat4(m);
            placements.push(Placement {
                object_from_world: m.inverse(),
                normal_matrix: linear.inverse().transpose(),
                tangent_matrix: linear,
                handedness: if linear.determinant() < 0.0 { -1.0 } else { 1.0 },
            });
            for (p, prim) in object.primitives.iter().enumerate() {
                let holes = scene.materials.get(prim.material).is_some_and(has_holes);
                let world: Vec<Vec3> =
                    prim.positions.iter().map(|&v| m.transform_point3(v)).collect();
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
                        holes,
                    });
                }
            }
        }
        let bvh = if triangles.is_empty() {
            lo = Vec3::ZERO;
            hi = Vec3::ZERO;
            None
        } else {
            Some(build_cwbvh_from_tris(
                &triangles,
                BvhBuildParams::medium_build(),
                &mut Duration::default(),
            ))
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
            self.intersect(tri, r)
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
        !bvh.ray_traverse_miss(ray, |r, id| self.intersect(bvh.primitive_indices[id] as usize, r))
    }

    /// The distance at which ray `r` meets world triangle `tri`, infinite where it misses
    /// or passes through a hole of the triangle's material.
    #[inline]
    fn intersect(&self, tri: usize, r: &Ray) -> f32 {
        let t = self.triangles[tri].intersect(r);
        if t < r.tmax && self.sources[tri].holes && self.passes_through(tri, r, t) {
            f32::INFINITY
        } else {
            t
        }
    }

    /// Whether ray `r`, meeting triangle `tri` (of a material with holes) at distance `t`,
    /// passes through it.
    fn passes_through(&self, tri: usize, r: &Ray, t: f32) -> bool {
        let src = self.sources[tri];
        let prim = &self.scene.objects[src.object as usize].primitives[src.primitive as usize];
        let Some(material) = self.scene.materials.get(prim.material) else { return false };
        let tr = &self.triangles[tri];
        let p = Vec3::from(r.origin + r.direction * t);
        let w = barycentric([tr.v0, tr.v1, tr.v2].map(Vec3::from), p);
        let Some(corners) = corners(prim, src.first_index) else { return false };
        let uvs = interpolated_uvs(prim, corners, w);
        let bits = |v: Vec3A| v.to_array().map(|c| c.to_bits() as u64);
        let ([ox, oy, oz], [dx, dy, dz]) = (bits(r.origin), bits(r.direction));
        let h = hash_keys(&[ox | oy << 32, oz | dx << 32, dy | dz << 32, tri as u64]);
        let u = (h >> 40) as f32 * (1.0 / 16_777_216.0);
        passes(material, alpha(self.scene, material, uvs), u)
    }

    /// Every hit along the ray up to `tmax`, nearest first (ties broken by triangle index).
    pub fn all_hits(&self, origin: Vec3, dir: Vec3, tmax: f32) -> Vec<Hit> {
        let Some(bvh) = self.bvh.as_ref() else { return Vec::new() };
        let ray = Ray::new(Vec3A::from(origin), Vec3A::from(dir), 0.0, tmax);
        let mut hits = Vec::new();
        bvh.ray_traverse_anyhit(ray, |r, id| {
            let tri = bvh.primitive_indices[id];
            let t = self.intersect(tri as usize, r);
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
        let w = barycentric([a, b, c], p);
        let [i0, i1, i2] = corners(prim, src.first_index).unwrap_or([0; 3]);
        let place = &self.placements[src.object as usize];
        let ng = (b - a).cross(c - a).normalize();
        let front_face = ng.dot(dir) < 0.0;
        let geometric_normal = if front_face { ng } else { -ng };
        let mut normal = match (prim.normals.get(i0), prim.normals.get(i1), prim.normals.get(i2)) {
            (Some(&n0), Some(&n1), Some(&n2)) => {
                let ns = place.normal_matrix * (n0 * w[0] + n1 * w[1] + n2 * w[2]);
                let ns = ns.normalize_or_zero();
                if ns == Vec3::ZERO {
                    ng
                } else {
                    ns
                }
            }
            _ => ng,
        };
        let [uv, uv1] = interpolated_uvs(prim, [i0, i1, i2], w);
        let material = self.scene.materials.get(prim.material);
        let (mut tangent, mut bitangent) = match material.and_then(|m| m.normal_texture.as_ref()) {
            Some(map) => self.tangent_frame(prim, place, [i0, i1, i2], w, [a, b, c], normal, map),
            None => (Vec3::ZERO, Vec3::ZERO),
        };
        if normal.dot(geometric_normal) < 0.0 {
            (normal, tangent, bitangent) = (-normal, -tangent, -bitangent);
        }
        SurfacePoint {
            position: p,
            object_position: place.object_from_world.transform_point3(p),
            geometric_normal,
            normal,
            front_face,
            uv,
            uv1,
            tangent,
            bitangent,
            material: prim.material,
            object: src.object,
        }
    }

    /// The normal map's tangent frame at barycentrics `w` of the triangle with corners
    /// `idx` (world positions `p`) about the world shading normal `n`: the TANGENT
    /// attribute's where the primitive has one, else the triangle's own ([`crate::tangent`]).
    #[allow(
        clippy::too_many_arguments,
        reason = "the triangle's corners, weights, positions and normal map, each apart"
    )]
    fn tangent_frame(
        &self,
        prim: &Primitive,
        place: &Placement,
        idx: [usize; 3],
        w: [f32; 3],
        p: [Vec3; 3],
        n: Vec3,
        map: &TextureRef,
    ) -> (Vec3, Vec3) {
        let frame = match idx.map(|i| prim.tangents.get(i)) {
            [Some(t0), Some(t1), Some(t2)] => {
                let t = *t0 * w[0] + *t1 * w[1] + *t2 * w[2];
                attribute_frame(n, place.tangent_matrix * t.truncate(), t.w * place.handedness)
            }
            _ => {
                let uv = idx.map(|i| {
                    let set = if map.tex_coord == 1 && !prim.uvs1.is_empty() {
                        &prim.uvs1
                    } else {
                        &prim.uvs
                    };
                    map.transform.apply(set.get(i).copied().unwrap_or(Vec2::ZERO))
                });
                triangle_frame(p, uv, n)
            }
        };
        frame.unwrap_or((Vec3::ZERO, Vec3::ZERO))
    }
}

impl SurfacePoint {
    /// Bends the shading normal by the normal map of `material` (a no-op without one, or
    /// where the bent normal would face away from the geometric normal).
    pub fn apply_normal_map(&mut self, scene: &Scene, material: &Material) {
        if self.tangent == Vec3::ZERO {
            return;
        }
        let Some(m) = mapped_normal(scene, material, [self.uv, self.uv1]) else { return };
        let bent = bend(self.normal, self.tangent, self.bitangent, m);
        if bent.dot(self.geometric_normal) > 0.0 {
            self.normal = bent;
        }
    }
}

/// Barycentric weights of point `p` in triangle `v`, from sub-triangle areas.
fn barycentric(v: [Vec3; 3], p: Vec3) -> [f32; 3] {
    let [a, b, c] = v;
    let n = (b - a).cross(c - a);
    let inv = 1.0 / n.length_squared();
    let w1 = (p - a).cross(c - a).dot(n) * inv;
    let w2 = (b - a).cross(p - a).dot(n) * inv;
    [1.0 - w1 - w2, w1, w2]
}

/// The vertex indices of the triangle whose first index is `first` in `prim`.
fn corners(prim: &Primitive, first: u32) -> Option<[usize; 3]> {
    let f = first as usize;
    let t = prim.indices.get(f..f + 3)?;
    Some([t[0] as usize, t[1] as usize, t[2] as usize])
}

/// TEXCOORD_0 and TEXCOORD_1 (TEXCOORD_0 where the primitive has no second set) at
/// barycentrics `w` of the triangle with corners `idx`.
fn interpolated_uvs(prim: &Primitive, idx: [usize; 3], w: [f32; 3]) -> [Vec2; 2] {
    let at = |set: &[Vec2]| match idx.map(|i| set.get(i)) {
        [Some(&u0), Some(&u1), Some(&u2)] => Some(u0 * w[0] + u1 * w[1] + u2 * w[2]),
        _ => None,
    };
    let uv = at(&prim.uvs).unwrap_or(Vec2::ZERO);
    [uv, at(&prim.uvs1).unwrap_or(uv)]
}
