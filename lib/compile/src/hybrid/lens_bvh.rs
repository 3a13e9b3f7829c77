//! A lens object's triangles as a flat binary BVH: the layout the player's compute shader
//! walks when it traces vertex rays on the GPU (`lens_rays.wgsl` in pis-play), built once
//! per placed lens object and uploaded as two storage buffers.
//!
//! - **Nodes**, 8 words each: the box's min x, y, z (f32 bits), the primitive count (0 for an
//!   inner node), the box's max x, y, z, then the first primitive (a leaf) or the left child
//!   (an inner node; the right child follows it). Node 0 is the root.
//! - **Triangles**, in the order the leaves index them, 24 floats each: corner 0 and the
//!   triangle's index in [`LensObject::triangles`] (as bits), corner 1 and 1.0 where the
//!   three corners have shading normals (else 0.0), corner 2 and 0, then the three normals,
//!   each padded to four.
//!
//! [`FlatBvh::closest`] walks the same layout on the CPU, as the shader does; a test holds it
//! to [`LensObject::closest`] (the same Möller–Trumbore test, so the same `t`).

use std::time::Duration;

use glam::{Vec3, Vec3A};
use obvhs::bvh2::builder::build_bvh2_from_tris;
use obvhs::ray::Ray;
use obvhs::triangle::Triangle;
use obvhs::BvhBuildParams;

use super::lens::{LensHit, LensObject};

/// Words per node and floats per triangle.
pub const NODE_WORDS: usize = 8;
pub const TRIANGLE_FLOATS: usize = 24;

/// The deepest node stack a walk needs: the tree's depth plus one.
pub const MAX_STACK: usize = 64;

/// A lens object's BVH in the shader's layout.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FlatBvh {
    pub nodes: Vec<[u32; NODE_WORDS]>,
    pub triangles: Vec<[f32; TRIANGLE_FLOATS]>,
    /// The longest root-to-leaf path, in nodes.
    pub depth: usize,
}

impl FlatBvh {
    /// The BVH of `lens`'s triangles (empty for an object without triangles).
    pub fn new(lens: &LensObject) -> FlatBvh {
        let corners = |t: &[u32; 3]| t.map(|i| lens.positions[i as usize]);
        let tris: Vec<Triangle> = lens
            .triangles
            .iter()
            .map(|t| {
                let [a, b, c] = corners(t);
                Triangle { v0: a.into(), v1: b.into(), v2: c.into() }
            })
            .collect();
        if tris.is_empty() {
            return FlatBvh::default();
        }
        let bvh =
            build_bvh2_from_tris(&tris, BvhBuildParams::medium_build(), &mut Duration::default());
        let nodes = bvh
            .nodes
            .iter()
            .map(|n| {
                let (lo, hi) = (n.aabb.min, n.aabb.max);
                [
                    lo.x.to_bits(),
                    lo.y.to_bits(),
                    lo.z.to_bits(),
                    n.prim_count,
                    hi.x.to_bits(),
                    hi.y.to_bits(),
                    hi.z.to_bits(),
                    n.first_index,
                ]
            })
            .collect::<Vec<_>>();
        let triangles = bvh.primitive_indices.iter().map(|&t| triangle_words(lens, t)).collect();
        let depth = depth_of(&nodes);
        FlatBvh { nodes, triangles, depth }
    }

    /// The closest hit along `origin + t·dir`, t in (0, `tmax`), found as the shader finds it:
    /// a stack of nodes, the nearer child walked first, each leaf's triangles tested with
    /// Möller–Trumbore (obvhs's test, bit for bit). A ray that starts in a triangle's plane
    /// does not hit it at t = 0, as [`LensObject::closest`] does not.
    pub fn closest(&self, origin: Vec3, dir: Vec3, tmax: f32) -> Option<LensHit> {
        if self.nodes.is_empty() {
            return None;
        }
        let mut ray = Ray::new(Vec3A::from(origin), Vec3A::from(dir), 0.0, tmax);
        let mut best: Option<LensHit> = None;
        let mut stack = [0u32; MAX_STACK];
        let mut len = 0;
        if box_distance(&self.nodes[0], &ray) < ray.tmax {
            stack[0] = 0;
            len = 1;
        }
        while len > 0 {
            len -= 1;
            let node = &self.nodes[stack[len] as usize];
            if node[3] > 0 {
                for k in node[7]..node[7] + node[3] {
                    let w = &self.triangles[k as usize];
                    let tri = Triangle {
                        v0: Vec3A::new(w[0], w[1], w[2]),
                        v1: Vec3A::new(w[4], w[5], w[6]),
                        v2: Vec3A::new(w[8], w[9], w[10]),
                    };
                    // t = 0 (the origin in the triangle's plane) is no hit: t in (0, tmax).
                    let t = tri.intersect(&ray);
                    if t > 0.0 && t < ray.tmax {
                        ray.tmax = t;
                        best = Some(LensHit { t, triangle: w[3].to_bits() });
                    }
                }
                continue;
            }
            let (l, r) = (node[7], node[7] + 1);
            let (tl, tr) = (
                box_distance(&self.nodes[l as usize], &ray),
                box_distance(&self.nodes[r as usize], &ray),
            );
            let (near, far, tn, tf) = if tl <= tr { (l, r, tl, tr) } else { (r, l, tr, tl) };
            if tf < ray.tmax && len < MAX_STACK {
                stack[len] = far;
                len += 1;
            }
            if tn < ray.tmax && len < MAX_STACK {
                stack[len] = near;
                len += 1;
            }
        }
        best
    }
}

/// Triangle `t` of `lens` in the shader's layout.
fn triangle_words(lens: &LensObject, t: u32) -> [f32; TRIANGLE_FLOATS] {
    let ids = lens.triangles[t as usize];
    let p = ids.map(|i| lens.positions[i as usize]);
    let n: Option<[Vec3; 3]> = match ids.map(|i| lens.normals.get(i as usize).copied()) {
        [Some(a), Some(b), Some(c)] => Some([a, b, c]),
        _ => None,
    };
    let mut w = [0.0f32; TRIANGLE_FLOATS];
    for (k, c) in p.iter().enumerate() {
        w[k * 4..k * 4 + 3].copy_from_slice(&c.to_array());
    }
    w[3] = f32::from_bits(t);
    w[7] = if n.is_some() { 1.0 } else { 0.0 };
    for (k, c) in n.unwrap_or([Vec3::ZERO; 3]).iter().enumerate() {
        w[12 + k * 4..12 + k * 4 + 3].copy_from_slice(&c.to_array());
    }
    w
}

/// The entry distance of `ray` into node `n`'s box (obvhs's slab test), ∞ where it misses.
fn box_distance(n: &[u32; NODE_WORDS], ray: &Ray) -> f32 {
    let f = |k: usize| f32::from_bits(n[k]);
    let aabb =
        obvhs::aabb::Aabb { min: Vec3A::new(f(0), f(1), f(2)), max: Vec3A::new(f(4), f(5), f(6)) };
    aabb.intersect_ray(ray)
}

/// The longest path from the root down to a leaf, in nodes.
fn depth_of(nodes: &[[u32; NODE_WORDS]]) -> usize {
    let mut deepest = 0;
    let mut stack = vec![(0, 1usize)];
    while let Some((k, d)) = stack.pop() {
        deepest = deepest.max(d);
        if nodes[k][3] == 0 {
            let l = nodes[k][7] as usize;
            stack.push((l, d + 1));
            stack.push((l + 1, d + 1));
        }
    }
    deepest
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hybrid::lens::LensMaterial;

    /// A UV sphere of radius 1 about the origin with its vertex normals.
    pub(crate) fn sphere(rings: u32, segments: u32) -> LensObject {
        let mut positions = Vec::new();
        for i in 0..=rings {
            let theta = std::f32::consts::PI * i as f32 / rings as f32;
            for j in 0..segments {
                let phi = std::f32::consts::TAU * j as f32 / segments as f32;
                positions.push(Vec3::new(
                    theta.sin() * phi.cos(),
                    theta.cos(),
                    theta.sin() * phi.sin(),
                ));
            }
        }
        let mut indices = Vec::new();
        for i in 0..rings {
            for j in 0..segments {
                let (a, b) = (i * segments + j, i * segments + (j + 1) % segments);
                let (c, d) = (a + segments, b + segments);
                indices.extend([a, c, b, b, c, d]);
            }
        }
        let normals = positions.clone();
        let material = LensMaterial { ior: 1.5, base: Vec3::ONE, sigma_a: Vec3::ZERO };
        LensObject::new(material, positions, normals, &indices)
    }

    #[test]
    fn the_flat_walk_finds_the_hits_the_lens_object_finds() {
        let lens = sphere(24, 48);
        let bvh = FlatBvh::new(&lens);
        assert!(bvh.depth > 1 && bvh.depth < MAX_STACK, "depth {}", bvh.depth);
        let mut hits = 0;
        for k in 0..2000u32 {
            // Rays from points around and inside the sphere, in spread directions.
            let a = k as f32 * 0.618_034;
            let origin = Vec3::new((a * 7.1).sin(), (a * 3.3).cos(), (a * 5.7).sin()) * 1.8;
            let origin = if k % 3 == 0 { origin * 0.3 } else { origin };
            let dir = Vec3::new((a * 2.9).cos(), (a * 1.7).sin(), (a * 4.3).cos()).normalize();
            let (want, got) =
                (lens.closest(origin, dir, f32::INFINITY), bvh.closest(origin, dir, f32::INFINITY));
            assert_eq!(want.map(|h| h.t), got.map(|h| h.t), "ray {k}");
            if let (Some(w), Some(g)) = (want, got) {
                hits += 1;
                let s = |h: &LensHit| lens.surface(h, origin, dir).position;
                assert!((s(&w) - s(&g)).length() < 1e-5, "ray {k}");
            }
        }
        assert!(hits > 500, "{hits} hits");
    }

    #[test]
    fn an_object_without_triangles_has_an_empty_tree() {
        let material = LensMaterial { ior: 1.5, base: Vec3::ONE, sigma_a: Vec3::ZERO };
        let lens = LensObject::new(material, vec![Vec3::ZERO; 3], vec![], &[0, 1, 2]);
        let bvh = FlatBvh::new(&lens);
        assert!(bvh.nodes.is_empty() && bvh.closest(Vec3::Z, -Vec3::Z, 10.0).is_none());
    }
}
