//! New charts where a mesh's texture coordinates cannot hold a texture (before thesis 3.2's
//! steps): a CAD export without `TEXCOORD_0` (every vertex at (0, 0)), or an artist's atlas
//! with triangles collapsed to a line or a point in (u, v). One texel would then stand for a
//! whole part (a flat silhouette), or the stretch limit would scale the map without bound
//! to reach a triangle of no (u, v) area (a placement reduced to nothing).
//!
//! A triangle is *degenerate* when its (u, v) area is under [`DEGENERATE`] times its
//! object-space area at the mesh's typical density (its total (u, v) area over its total
//! object-space area). Degenerate triangles are charted again by box projection: grouped by
//! the axis their face normal points along most (±X, ±Y, ±Z), each group projected
//! orthographically onto the plane across its axis, in object-space units. A vertex used by no
//! kept triangle keeps its index for the first group that uses it, and is copied for others. The
//! new charts overlap each other and the mesh's own in (u, v), so that
//! [`super::charts::separate_overlapping_charts`] lays every seen chart out apart, each at the
//! density its pixels need.

use glam::{DVec3, Vec2, Vec3};

/// A triangle's (u, v) area under this fraction of its object-space area at the mesh's
/// typical density makes it degenerate: its texels stretch over more than a hundred times
/// the length the rest of the mesh gives them.
pub const DEGENERATE: f64 = 1e-4;

/// The largest spread of a mesh's own texel density (the 90th over the 10th percentile of its
/// triangles' (u, v) length per object-space length, weighted by area) that its coordinates
/// are kept at: above it the whole mesh is charted again. A texture placed on such
/// coordinates gets the density the stretch limit asks for at its most compressed triangles
/// everywhere else too, and a texel budget then starves the rest: an exported duck whose
/// (u, v) density varies 30 times played 27 dB losslessly on its own coordinates and 36 dB
/// charted again, against a set 38 dB from converged.
pub const NONUNIFORM_DENSITY: f64 = 4.0;

/// The spread of texel density over triangles of (object-space area, (u, v) area): the
/// area-weighted 90th over 10th percentile of √((u, v) area / object-space area), over the
/// triangles that have both; 1 where fewer than two do.
pub fn density_spread(areas: &[(f64, f64)]) -> f64 {
    let mut d: Vec<(f64, f64)> = areas
        .iter()
        .filter(|&&(w, t)| w > 0.0 && t > 0.0)
        .map(|&(w, t)| ((t / w).sqrt(), w))
        .collect();
    if d.len() < 2 {
        return 1.0;
    }
    d.sort_by(|a, b| a.0.total_cmp(&b.0));
    let total: f64 = d.iter().map(|&(_, w)| w).sum();
    let at = |q: f64| {
        let mut sum = 0.0;
        d.iter()
            .find(|&&(_, w)| {
                sum += w;
                sum >= q * total
            })
            .map_or(d[d.len() - 1].0, |&(v, _)| v)
    };
    at(0.9) / at(0.1)
}

/// A mesh's triangles charted again: the new coordinates of every vertex (the original ones
/// first, then one per copy), the new index list (same triangles, same order), the vertex each
/// copy copies, and what was done.
#[derive(Clone, Debug, PartialEq)]
pub struct Recharted {
    pub uvs: Vec<Vec2>,
    pub indices: Vec<u32>,
    pub copies: Vec<u32>,
    /// Triangles charted again.
    pub triangles: usize,
    /// The spread of the mesh's own texel density ([`density_spread`]): above
    /// [`NONUNIFORM_DENSITY`] every triangle was charted again.
    pub spread: f64,
    /// Their share of the mesh's object-space area.
    pub area_share: f64,
    /// Projection groups (of ±X, ±Y, ±Z) that received triangles.
    pub groups: usize,
}

impl Recharted {
    /// One line for a report: what was charted again and why.
    pub fn describe(&self, total_triangles: usize) -> String {
        if self.spread > NONUNIFORM_DENSITY {
            return format!(
                "its texture coordinates' texel density varies {:.0} times over its surface \
                 (90th over 10th percentile): all {} triangles charted again by box projection \
                 onto {} planes",
                self.spread, total_triangles, self.groups
            );
        }
        format!(
            "{} of {} triangles ({:.1} % of the surface) had texture coordinates of no area \
             (missing or collapsed): charted again by box projection onto {} planes",
            self.triangles,
            total_triangles,
            100.0 * self.area_share,
            self.groups
        )
    }
}

fn corners<T: Copy>(values: &[T], tri: &[u32]) -> Option<[T; 3]> {
    Some([
        *values.get(tri[0] as usize)?,
        *values.get(tri[1] as usize)?,
        *values.get(tri[2] as usize)?,
    ])
}

/// Per triangle, (object-space area, (u, v) area); zero for a triangle with an index out of
/// range.
fn areas(positions: &[Vec3], uvs: &[Vec2], indices: &[u32]) -> Vec<(f64, f64)> {
    indices
        .chunks_exact(3)
        .map(|t| {
            let (Some(p), Some(w)) = (corners(positions, t), corners(uvs, t)) else {
                return (0.0, 0.0);
            };
            let [a, b, c] = p.map(|v| v.as_dvec3());
            let [x, y, z] = w.map(|v| v.as_dvec2());
            (0.5 * (b - a).cross(c - a).length(), 0.5 * (y - x).perp_dot(z - x).abs())
        })
        .collect()
}

/// Per triangle, whether its texture coordinates are degenerate (see the module's text).
/// Triangles of no object-space area are not: nothing of them is seen.
pub fn degenerate_triangles(positions: &[Vec3], uvs: &[Vec2], indices: &[u32]) -> Vec<bool> {
    degenerate(&areas(positions, uvs, indices))
}

/// [`degenerate_triangles`] of the triangles' (object-space area, (u, v) area).
fn degenerate(a: &[(f64, f64)]) -> Vec<bool> {
    let (world, texture) = a.iter().fold((0.0, 0.0), |s, &(w, t)| (s.0 + w, s.1 + t));
    let density = if world > 0.0 { texture / world } else { 0.0 };
    a.iter().map(|&(w, t)| w > 0.0 && !(t > DEGENERATE * density * w && t > 0.0)).collect()
}

/// The projection group of a face normal: 0–5 for +X, −X, +Y, −Y, +Z, −Z.
fn group(n: DVec3) -> usize {
    let m = n.abs();
    let axis = if m.x >= m.y && m.x >= m.z {
        0
    } else if m.y >= m.z {
        1
    } else {
        2
    };
    2 * axis + usize::from(n[axis] < 0.0)
}

/// Object-space point `p` projected for group `g`, with a basis (b1, b2) such that
/// b1 × b2 points along the group's axis: every projected triangle turns as seen from outside.
fn project(p: Vec3, g: usize) -> Vec2 {
    match g {
        0 => Vec2::new(-p.z, p.y),
        1 => Vec2::new(p.z, p.y),
        2 => Vec2::new(p.x, -p.z),
        3 => Vec2::new(p.x, p.z),
        4 => Vec2::new(p.x, p.y),
        _ => Vec2::new(-p.x, p.y),
    }
}

/// The mesh charted again where its coordinates are degenerate; `None` when no triangle is.
pub fn rechart(positions: &[Vec3], uvs: &[Vec2], indices: &[u32]) -> Option<Recharted> {
    let a = areas(positions, uvs, indices);
    let mut bad = degenerate(&a);
    // The spread of the triangles kept: degenerate ones are charted again either way.
    let kept: Vec<(f64, f64)> =
        a.iter().zip(&bad).map(|(&a, &b)| if b { (0.0, 0.0) } else { a }).collect();
    let spread = density_spread(&kept);
    if spread > NONUNIFORM_DENSITY {
        bad = a.iter().map(|&(w, _)| w > 0.0).collect();
    }
    if !bad.contains(&true) {
        return None;
    }
    let total: f64 = a.iter().map(|&(w, _)| w).sum();
    let groups: Vec<Option<usize>> = indices
        .chunks_exact(3)
        .zip(&bad)
        .map(|(t, &b)| {
            let p = corners(positions, t)?.map(|v| v.as_dvec3());
            b.then(|| group((p[1] - p[0]).cross(p[2] - p[0])))
        })
        .collect();
    // Who uses each vertex: a kept triangle (bit 6) or degenerate ones of groups 0–5.
    let mut users = vec![0u8; uvs.len().max(positions.len())];
    for (t, g) in indices.chunks_exact(3).zip(&groups) {
        let bit = g.map_or(1 << 6, |g| 1 << g);
        for &v in t {
            if let Some(u) = users.get_mut(v as usize) {
                *u |= bit;
            }
        }
    }
    let mut out_uvs: Vec<Vec2> = uvs.to_vec();
    out_uvs.resize(users.len(), Vec2::ZERO);
    let mut copy_of: std::collections::HashMap<(u32, usize), u32> = Default::default();
    let mut copies = Vec::new();
    let mut new_indices = Vec::with_capacity(indices.len());
    for (t, g) in indices.chunks_exact(3).zip(&groups) {
        let Some(g) = *g else {
            new_indices.extend_from_slice(t);
            continue;
        };
        for &v in t {
            let p = positions[v as usize];
            // The vertex's lowest group keeps it, unless a kept triangle uses it.
            let u = users[v as usize];
            let index = if u & (1 << 6) == 0 && u.trailing_zeros() as usize == g {
                out_uvs[v as usize] = project(p, g);
                v
            } else {
                *copy_of.entry((v, g)).or_insert_with(|| {
                    copies.push(v);
                    out_uvs.push(project(p, g));
                    (out_uvs.len() - 1) as u32
                })
            };
            new_indices.push(index);
        }
    }
    let used: std::collections::BTreeSet<usize> = groups.iter().flatten().copied().collect();
    let moved: f64 = a.iter().zip(&bad).filter(|(_, &b)| b).map(|(&(w, _), _)| w).sum();
    Some(Recharted {
        uvs: out_uvs,
        indices: new_indices,
        copies,
        triangles: bad.iter().filter(|&&b| b).count(),
        spread,
        area_share: if total > 0.0 { moved / total } else { 0.0 },
        groups: used.len(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit cube of 8 shared vertices and 12 triangles, all at `uv`.
    fn cube(uv: Vec2) -> (Vec<Vec3>, Vec<Vec2>, Vec<u32>) {
        let p: Vec<Vec3> = (0..8)
            .map(|i| Vec3::new((i & 1) as f32, ((i >> 1) & 1) as f32, ((i >> 2) & 1) as f32))
            .collect();
        #[rustfmt::skip]
        let idx = vec![
            0, 2, 3, 0, 3, 1, // −Z
            4, 5, 7, 4, 7, 6, // +Z
            0, 4, 6, 0, 6, 2, // −X
            1, 3, 7, 1, 7, 5, // +X
            0, 1, 5, 0, 5, 4, // −Y
            2, 6, 7, 2, 7, 3, // +Y
        ];
        (p, vec![uv; 8], idx)
    }

    #[test]
    fn a_mesh_without_coordinates_gets_six_planar_charts() {
        let (p, uv, idx) = cube(Vec2::ZERO);
        assert!(degenerate_triangles(&p, &uv, &idx).iter().all(|&b| b));
        let r = rechart(&p, &uv, &idx).expect("every triangle is degenerate");
        assert_eq!((r.triangles, r.groups), (12, 6));
        assert!((r.area_share - 1.0).abs() < 1e-12);
        // Every triangle now has the (u, v) area of its object-space area, turning one way.
        for t in r.indices.chunks_exact(3) {
            let [a, b, c] = [t[0], t[1], t[2]].map(|v| r.uvs[v as usize].as_dvec2());
            let turn = (b - a).perp_dot(c - a);
            assert!((turn - 1.0).abs() < 1e-9, "{turn}");
        }
        // Each corner is used by three faces: kept for one, copied for the two others.
        assert_eq!(r.copies.len(), 16);
        assert_eq!(r.uvs.len(), 8 + 16);
        let p2: Vec<Vec3> =
            p.iter().copied().chain(r.copies.iter().map(|&v| p[v as usize])).collect();
        assert!(degenerate_triangles(&p2, &r.uvs, &r.indices).iter().all(|&b| !b));
    }

    #[test]
    fn a_few_collapsed_triangles_in_a_good_chart_are_charted_again_alone() {
        // A strip of two quads in the plane z = 0 with coordinates = positions, then the
        // right quad's far edge collapsed onto its near edge in (u, v).
        let p: Vec<Vec3> = [(0., 0.), (1., 0.), (2., 0.), (0., 1.), (1., 1.), (2., 1.)]
            .iter()
            .map(|&(x, y)| Vec3::new(x, y, 0.0))
            .collect();
        let mut uv: Vec<Vec2> = p.iter().map(|v| v.truncate()).collect();
        let idx = vec![0, 1, 4, 0, 4, 3, 1, 2, 5, 1, 5, 4];
        assert_eq!(rechart(&p, &uv, &idx), None);
        uv[2] = uv[1] + Vec2::new(1e-7, 0.0);
        uv[5] = uv[4];
        assert_eq!(degenerate_triangles(&p, &uv, &idx), vec![false, false, true, true]);
        let r = rechart(&p, &uv, &idx).expect("two triangles collapsed");
        assert_eq!((r.triangles, r.groups), (2, 1));
        assert!((r.area_share - 0.5).abs() < 1e-6);
        // Vertices 1 and 4 are shared with the good quad: copied; 2 and 5 moved in place.
        assert_eq!(r.copies, vec![1, 4]);
        assert_eq!(&r.indices[..6], &idx[..6]);
        assert_eq!(r.uvs[2], Vec2::new(2.0, 0.0));
        assert_eq!(r.uvs[0..2], uv[0..2]);
    }

    #[test]
    fn coordinates_of_very_uneven_density_are_charted_again_whole() {
        // Two unit quads side by side on vertices of their own; the left one's coordinates
        // span 1 × 1, the right one's 0.1 × 0.1: the density varies 10 times.
        let corners = [(0., 0.), (1., 0.), (1., 1.), (0., 1.)];
        let mut p = Vec::new();
        let mut uv = Vec::new();
        for (q, scale) in [(0.0, 1.0), (1.0, 0.1)] {
            for &(x, y) in &corners {
                p.push(Vec3::new(q + x, y, 0.0));
                uv.push(Vec2::new(2.0 * q + x * scale, y * scale));
            }
        }
        let idx = vec![0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7];
        let spread = density_spread(&areas(&p, &uv, &idx));
        assert!((spread - 10.0).abs() < 1e-4, "{spread}");
        let r = rechart(&p, &uv, &idx).expect("the density varies 10 times");
        assert_eq!((r.triangles, r.groups, r.copies.len()), (4, 1, 0));
        assert!(r.describe(4).contains("varies 10 times"), "{}", r.describe(4));
        // Every triangle now has its object-space area in (u, v).
        for (w, t) in areas(&p, &r.uvs, &r.indices) {
            assert!((w - t).abs() < 1e-6, "{w} {t}");
        }
        // 2.5 times as dense on the left only: kept.
        uv[4..]
            .iter_mut()
            .for_each(|v| *v = Vec2::new(2.0, 0.0) + (*v - Vec2::new(2.0, 0.0)) * 4.0);
        assert!(density_spread(&areas(&p, &uv, &idx)) < NONUNIFORM_DENSITY);
        assert_eq!(rechart(&p, &uv, &idx), None);
    }
}
