//! Charts whose texture coordinates overlap (before thesis 3.2's steps): a mesh may map
//! several of its visible parts onto the same (u, v) region — a room's walls each carrying
//! the whole [0, 1]² of a repeating wallpaper. One texture cannot hold two different
//! surfaces at the same texel, so such charts are laid out side by side first (an atlas),
//! each scaled to the texel density its most magnified pixel needs.
//!
//! A chart is a set of triangles connected through shared vertices. Only charts some view
//! sees take part; when no two of them overlap in (u, v), the coordinates are left alone.

use glam::{DMat2, DVec2, Vec2};

use super::visibility::{rasterize_ids, screen_triangle, uv_jacobian, ViewGeometry};

/// Texels of empty border around every chart of an atlas (at the density the chart is
/// scaled to): keeps bilinear taps of the finest levels inside their chart.
pub const GUTTER: f64 = 4.0;

/// Largest ratio between the texel densities the seen charts of one texture need before
/// they are laid out again, each at its own: above it, a texture sized for the most
/// magnified chart wastes most of its texels on the others, and the texel budget's
/// reduction blurs the magnified one.
pub const NONUNIFORM: f64 = 8.0;

/// Cells per side of the grid the overlap test rasterizes (u, v) triangles into.
const OVERLAP_GRID: usize = 128;

/// Per triangle, its chart (connected through shared vertices), and the chart count.
pub fn charts(indices: &[u32], vertices: usize) -> (Vec<u32>, usize) {
    let mut parent: Vec<u32> = (0..vertices as u32).collect();
    fn root(p: &mut [u32], mut i: u32) -> u32 {
        while p[i as usize] != i {
            p[i as usize] = p[p[i as usize] as usize];
            i = p[i as usize];
        }
        i
    }
    for tri in indices.chunks_exact(3) {
        let mut a = root(&mut parent, tri[0]);
        for &v in &tri[1..] {
            let b = root(&mut parent, v);
            if a != b {
                // Join under the lower root, which the next vertex then joins: linking the
                // triangle's first root again once it has a parent would undo the first join.
                let (lo, hi) = (a.min(b), a.max(b));
                parent[hi as usize] = lo;
                a = lo;
            }
        }
    }
    let mut id = vec![u32::MAX; vertices];
    let mut count = 0;
    let tri_chart = indices
        .chunks_exact(3)
        .map(|tri| {
            let r = root(&mut parent, tri[0]) as usize;
            if id[r] == u32::MAX {
                id[r] = count;
                count += 1;
            }
            id[r]
        })
        .collect();
    (tri_chart, count as usize)
}

/// A mesh with its folded charts cut apart: the new index list (same triangles, same order)
/// and, for every vertex added after the original ones, the vertex it copies.
#[derive(Clone, Debug, PartialEq)]
pub struct Unfolded {
    pub indices: Vec<u32>,
    pub copies: Vec<u32>,
}

/// Charts folded onto themselves in (u, v), cut where they turn over.
///
/// An artist's mirrored model gives its two halves one half's coordinates: the halves meet
/// at the mirror line through shared vertices, so they form one chart whose (u, v) map
/// overlaps itself, and one texture cannot hold both. With a consistent winding, a chart's
/// triangles all turn the same way in (u, v) unless it folds: two triangles that share an
/// edge and turn opposite ways lie on the same side of it and overlap. So the vertices used
/// by triangles of both turnings are duplicated, the triangles that turn clockwise taking
/// the copies: every chart then turns one way, and the halves become charts of their own
/// that [`separate_overlapping_charts`] lays apart where both are seen. Triangles of zero
/// (u, v) area (a mesh without coordinates) count as counter-clockwise. `None` when no chart
/// folds.
pub fn unfold_charts(uvs: &[Vec2], indices: &[u32]) -> Option<Unfolded> {
    let turn = |t: &[u32]| -> usize {
        let [a, b, c] = [t[0], t[1], t[2]]
            .map(|v| uvs.get(v as usize).copied().unwrap_or(Vec2::ZERO).as_dvec2());
        usize::from(super::visibility::edge(a, b, c) < 0.0)
    };
    // Which turnings use each vertex.
    let mut used = vec![[false; 2]; uvs.len()];
    for t in indices.chunks_exact(3) {
        let s = turn(t);
        for &v in t {
            if let Some(u) = used.get_mut(v as usize) {
                u[s] = true;
            }
        }
    }
    if !used.iter().any(|u| u[0] && u[1]) {
        return None;
    }
    // The clockwise users of a vertex both turnings use get one copy of it.
    let mut copy = vec![u32::MAX; uvs.len()];
    let mut copies = Vec::new();
    for (v, u) in used.iter().enumerate() {
        if u[0] && u[1] {
            copy[v] = (uvs.len() + copies.len()) as u32;
            copies.push(v as u32);
        }
    }
    let mut out = Vec::with_capacity(indices.len());
    for t in indices.chunks_exact(3) {
        let s = turn(t);
        out.extend(t.iter().map(|&v| {
            if s == 1 && copy.get(v as usize).is_some_and(|&c| c != u32::MAX) {
                copy[v as usize]
            } else {
                v
            }
        }));
    }
    Some(Unfolded { indices: out, copies })
}

/// Largest stretch of J⁻¹ (pixels per unit of (u, v) in the worst direction): 1/σ_min(J).
fn density(j: DMat2) -> Option<f64> {
    let m = j.transpose() * j;
    let (p, q, s) = (m.x_axis.x, m.y_axis.x, m.y_axis.y);
    let mu = 0.5 * (p + s - ((p - s) * (p - s) + 4.0 * q * q).sqrt());
    (mu.is_finite() && mu > 1e-300).then(|| 1.0 / mu.sqrt())
}

/// Whether two of the given charts cover a common cell of a grid over their (u, v) bounds.
fn overlapping(uvs: &[Vec2], indices: &[u32], tri_chart: &[u32], take: &[bool]) -> bool {
    let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
    for (t, tri) in indices.chunks_exact(3).enumerate() {
        if take[tri_chart[t] as usize] {
            for &v in tri {
                lo = lo.min(uvs[v as usize].as_dvec2());
                hi = hi.max(uvs[v as usize].as_dvec2());
            }
        }
    }
    let ext = (hi - lo).max(DVec2::splat(1e-12));
    let n = OVERLAP_GRID;
    let mut owner = vec![u32::MAX; n * n];
    for (t, tri) in indices.chunks_exact(3).enumerate() {
        let c = tri_chart[t];
        if !take[c as usize] {
            continue;
        }
        let p: Vec<DVec2> =
            tri.iter().map(|&v| (uvs[v as usize].as_dvec2() - lo) / ext * n as f64).collect();
        let area = super::visibility::edge(p[0], p[1], p[2]);
        if area.abs() < 1e-12 {
            continue;
        }
        let (a, b) = (p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2]));
        let (x0, x1) = (
            (a.x - 0.5).ceil().max(0.0) as usize,
            ((b.x - 0.5).floor().max(-1.0) as i64).min(n as i64 - 1),
        );
        let (y0, y1) = (
            (a.y - 0.5).ceil().max(0.0) as usize,
            ((b.y - 0.5).floor().max(-1.0) as i64).min(n as i64 - 1),
        );
        for y in y0 as i64..=y1 {
            for x in x0 as i64..=x1 {
                let q = DVec2::new(x as f64 + 0.5, y as f64 + 0.5);
                let l = [
                    super::visibility::edge(p[1], p[2], q),
                    super::visibility::edge(p[2], p[0], q),
                    super::visibility::edge(p[0], p[1], q),
                ];
                let inside = l.iter().all(|&l| l * area.signum() > 0.0);
                if !inside {
                    continue;
                }
                let k = y as usize * n + x as usize;
                if owner[k] == u32::MAX {
                    owner[k] = c;
                } else if owner[k] != c {
                    return true;
                }
            }
        }
    }
    false
}

/// New texture coordinates that lay the visible charts out side by side when two of them
/// overlap in (u, v), or when the texel densities they need differ by more than
/// [`NONUNIFORM`] (an artist's atlas with one part at a fraction of the others' scale);
/// `None` when the mesh's coordinates already give every visible surface point its own
/// texel at a density close to the others'. Charts no view sees collapse to the atlas
/// origin.
pub fn separate_overlapping_charts(
    uvs: &[Vec2],
    indices: &[u32],
    views: &[ViewGeometry],
) -> Option<Vec<Vec2>> {
    let (tri_chart, n) = charts(indices, uvs.len());
    if n < 2 {
        return None;
    }
    // Per chart: the largest density any covered pixel of any view asks for.
    let mut need = vec![0.0f64; n];
    let mut seen = vec![false; n];
    for view in views {
        let ids = rasterize_ids(view, indices);
        for (k, id) in ids.ids.iter().enumerate() {
            let Some(t) = id else { continue };
            let c = tri_chart[*t as usize] as usize;
            seen[c] = true;
            let tri = &indices[3 * *t as usize..3 * *t as usize + 3];
            let Some(sv) = screen_triangle(view, tri) else { continue };
            let p = DVec2::new(
                (k % view.width as usize) as f64 + 0.5,
                (k / view.width as usize) as f64 + 0.5,
            );
            let tuv = [uvs[tri[0] as usize], uvs[tri[1] as usize], uvs[tri[2] as usize]];
            if let Some(d) = uv_jacobian(&sv, tuv, p).and_then(density) {
                need[c] = need[c].max(d);
            }
        }
    }
    if seen.iter().filter(|&&s| s).count() < 2 {
        return None;
    }
    let dense = |f: fn(f64, f64) -> f64, init: f64| {
        need.iter().zip(&seen).filter(|(d, s)| **s && **d > 0.0).map(|(d, _)| *d).fold(init, f)
    };
    let uneven = dense(f64::max, 0.0) > NONUNIFORM * dense(f64::min, f64::INFINITY);
    if !uneven && !overlapping(uvs, indices, &tri_chart, &seen) {
        return None;
    }
    // Chart bounds in (u, v), then scaled to texel units.
    let mut lo = vec![DVec2::splat(f64::INFINITY); n];
    let mut hi = vec![DVec2::splat(f64::NEG_INFINITY); n];
    for (t, tri) in indices.chunks_exact(3).enumerate() {
        let c = tri_chart[t] as usize;
        for &v in tri {
            lo[c] = lo[c].min(uvs[v as usize].as_dvec2());
            hi[c] = hi[c].max(uvs[v as usize].as_dvec2());
        }
    }
    let scale: Vec<f64> = need.iter().map(|&d| if d > 0.0 { d } else { 1.0 }).collect();
    let size = |c: usize| (hi[c] - lo[c]) * scale[c] + DVec2::splat(2.0 * GUTTER);
    // Shelf packing, tallest first, rows about as wide as the atlas is tall.
    let mut order: Vec<usize> = (0..n).filter(|&c| seen[c]).collect();
    order.sort_by(|&a, &b| size(b).y.total_cmp(&size(a).y).then(a.cmp(&b)));
    let area: f64 = order.iter().map(|&c| size(c).x * size(c).y).sum();
    let row_width = area.sqrt().max(order.iter().map(|&c| size(c).x).fold(0.0, f64::max));
    let mut offset = vec![DVec2::ZERO; n];
    let (mut x, mut y, mut row_h) = (0.0f64, 0.0f64, 0.0f64);
    for &c in &order {
        let s = size(c);
        if x > 0.0 && x + s.x > row_width {
            x = 0.0;
            y += row_h;
            row_h = 0.0;
        }
        offset[c] = DVec2::new(x, y) + DVec2::splat(GUTTER);
        x += s.x;
        row_h = row_h.max(s.y);
    }
    let extent = row_width.max(y + row_h);
    let mut out = vec![Vec2::ZERO; uvs.len()];
    let mut chart_of_vertex = vec![u32::MAX; uvs.len()];
    for (t, tri) in indices.chunks_exact(3).enumerate() {
        for &v in tri {
            chart_of_vertex[v as usize] = tri_chart[t];
        }
    }
    for (v, uv) in uvs.iter().enumerate() {
        let c = chart_of_vertex[v];
        if c == u32::MAX || !seen[c as usize] {
            continue;
        }
        let c = c as usize;
        let p = offset[c] + (uv.as_dvec2() - lo[c]) * scale[c];
        out[v] = (p / extent).as_vec2();
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Mat4, Vec3, Vec4};

    /// Two unit quads side by side (x ∈ [−1, 0] and [0, 1], z = 0), each with the whole
    /// [0, 1]² of (u, v), seen from z = 2.5 on a 64×48 screen.
    fn two_quads(separate_vertices: bool) -> (Vec<Vec2>, Vec<u32>, ViewGeometry) {
        let mut pos = Vec::new();
        let mut uvs = Vec::new();
        let mut idx = Vec::new();
        for q in 0..2 {
            let x0 = q as f32 - 1.0;
            let base = pos.len() as u32;
            for (dx, dy) in [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)] {
                pos.push(Vec3::new(x0 + dx, dy - 0.5, 0.0));
                uvs.push(if separate_vertices {
                    Vec2::new(dx, dy)
                } else {
                    Vec2::new((x0 + dx + 1.0) / 2.0, dy)
                });
            }
            idx.extend([base, base + 1, base + 2, base, base + 2, base + 3]);
        }
        // Right-handed perspective (0.9 rad vertical field, depth in [0, 1]), eye at z = 2.5.
        let (g, aspect, near, far) = (1.0 / 0.45f32.tan(), 64.0 / 48.0, 0.1f32, 10.0f32);
        let proj = Mat4::from_cols(
            Vec4::new(g / aspect, 0.0, 0.0, 0.0),
            Vec4::new(0.0, g, 0.0, 0.0),
            Vec4::new(0.0, 0.0, far / (near - far), -1.0),
            Vec4::new(0.0, 0.0, near * far / (near - far), 0.0),
        );
        let view = Mat4::from_translation(Vec3::new(0.0, 0.0, -2.5));
        let clip: Vec<Vec4> = pos.iter().map(|p| proj * view * p.extend(1.0)).collect();
        (uvs, idx, ViewGeometry { clip, width: 64, height: 48 })
    }

    #[test]
    fn overlapping_visible_charts_are_laid_out_apart() {
        let (uvs, idx, view) = two_quads(true);
        let new = separate_overlapping_charts(&uvs, &idx, std::slice::from_ref(&view))
            .expect("the quads overlap in (u, v)");
        // The two quads' (u, v) bounds no longer intersect.
        let bounds = |q: usize| {
            let vs = &new[q * 4..q * 4 + 4];
            (
                vs.iter().fold(Vec2::splat(f32::INFINITY), |a, v| a.min(*v)),
                vs.iter().fold(Vec2::splat(f32::NEG_INFINITY), |a, v| a.max(*v)),
            )
        };
        let ((a0, a1), (b0, b1)) = (bounds(0), bounds(1));
        assert!(
            a1.x <= b0.x || b1.x <= a0.x || a1.y <= b0.y || b1.y <= a0.y,
            "{a0} {a1} / {b0} {b1}"
        );
        // Each chart keeps its shape (a square stays a square, same size: same density).
        assert!(
            ((a1 - a0).x - (a1 - a0).y).abs() < 1e-4 && ((a1 - a0) - (b1 - b0)).length() < 1e-3
        );
        assert!(new.iter().all(|v| v.is_finite()
            && v.x >= 0.0
            && v.y >= 0.0
            && v.x <= 1.0
            && v.y <= 1.0));
    }

    /// The two quads of [`two_quads`] sharing their middle edge, the right one mirroring the
    /// left one's coordinates (u = 1 − |x|): one chart folded onto itself.
    fn mirrored_quads() -> (Vec<Vec2>, Vec<u32>, ViewGeometry) {
        let (_, _, view) = two_quads(true);
        // Vertices: the left quad's four, then the right quad's two outer ones; the middle
        // edge's two vertices are shared.
        let pos_uv = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)];
        let mut uvs: Vec<Vec2> = pos_uv.iter().map(|&(u, v)| Vec2::new(u, v)).collect();
        uvs.extend([Vec2::new(0.0, 0.0), Vec2::new(0.0, 1.0)]);
        let idx = vec![0, 1, 2, 0, 2, 3, 1, 4, 5, 1, 5, 2];
        // Clip positions: left quad x ∈ [−1, 0], right quad's outer edge at x = 1.
        let clip = vec![
            view.clip[0],
            view.clip[1],
            view.clip[2],
            view.clip[3],
            view.clip[5],
            view.clip[6],
        ];
        (uvs, idx, ViewGeometry { clip, ..view })
    }

    #[test]
    fn a_mirrored_chart_is_cut_at_the_mirror_line_and_laid_apart() {
        let (uvs, idx, view) = mirrored_quads();
        // One chart, so the overlap between charts alone finds nothing.
        assert_eq!(charts(&idx, uvs.len()).1, 1);
        assert_eq!(separate_overlapping_charts(&uvs, &idx, std::slice::from_ref(&view)), None);
        let u = unfold_charts(&uvs, &idx).expect("the chart folds at the shared edge");
        // The shared edge's two vertices are copied for the mirrored quad, nothing else.
        assert_eq!(u.copies, vec![1, 2]);
        assert_eq!(u.indices, vec![0, 1, 2, 0, 2, 3, 6, 4, 5, 6, 5, 7]);
        let uvs2: Vec<Vec2> =
            uvs.iter().copied().chain(u.copies.iter().map(|&v| uvs[v as usize])).collect();
        let mut clip = view.clip.clone();
        clip.extend(u.copies.iter().map(|&v| view.clip[v as usize]));
        assert_eq!(charts(&u.indices, uvs2.len()).1, 2);
        let new = separate_overlapping_charts(&uvs2, &u.indices, &[ViewGeometry { clip, ..view }])
            .expect("the halves overlap");
        let bounds = |vs: &[u32]| {
            let p: Vec<Vec2> = vs.iter().map(|&v| new[v as usize]).collect();
            (
                p.iter().fold(Vec2::splat(f32::INFINITY), |a, v| a.min(*v)),
                p.iter().fold(Vec2::splat(f32::NEG_INFINITY), |a, v| a.max(*v)),
            )
        };
        let ((a0, a1), (b0, b1)) = (bounds(&[0, 1, 2, 3]), bounds(&[6, 4, 5, 7]));
        assert!(
            a1.x <= b0.x || b1.x <= a0.x || a1.y <= b0.y || b1.y <= a0.y,
            "{a0} {a1} / {b0} {b1}"
        );
    }

    #[test]
    fn a_chart_that_turns_one_way_is_not_cut() {
        let (uvs, idx, _) = two_quads(false);
        assert_eq!(unfold_charts(&uvs, &idx), None);
        // No coordinates at all: every triangle has zero area, nothing folds.
        assert_eq!(unfold_charts(&vec![Vec2::ZERO; uvs.len()], &idx), None);
    }

    #[test]
    fn charts_of_very_different_texel_density_are_laid_out_at_one() {
        // The right quad's coordinates a sixteenth of the left one's: it needs 16 times the
        // texels per unit of (u, v).
        let (mut uvs, idx, view) = two_quads(true);
        uvs[4..].iter_mut().for_each(|v| *v = Vec2::new(2.0, 0.0) + *v / 16.0);
        let new = separate_overlapping_charts(&uvs, &idx, std::slice::from_ref(&view))
            .expect("the densities differ 16 times");
        let side = |q: usize| new[q * 4 + 1].x - new[q * 4].x;
        // Same screen size, so the same size in the atlas.
        assert!((side(0) / side(1) - 1.0).abs() < 1e-3, "{} {}", side(0), side(1));
        // Four times as dense only: left alone.
        let (mut uvs, idx, view) = two_quads(true);
        uvs[4..].iter_mut().for_each(|v| *v = Vec2::new(2.0, 0.0) + *v / 4.0);
        assert_eq!(separate_overlapping_charts(&uvs, &idx, &[view]), None);
    }

    #[test]
    fn an_injective_mapping_is_left_alone() {
        let (uvs, idx, view) = two_quads(false);
        assert_eq!(separate_overlapping_charts(&uvs, &idx, &[view]), None);
        // One chart seen: nothing to separate either.
        let (uvs, idx, mut view) = two_quads(true);
        view.clip[4..].iter_mut().for_each(|c| *c = Vec4::new(0.0, 0.0, 0.0, -1.0));
        assert_eq!(separate_overlapping_charts(&uvs, &idx, &[view]), None);
    }

    #[test]
    fn a_triangle_that_joins_three_sets_makes_one_chart() {
        // The first triangle joins vertex 2 to 0, then to 1; the second uses vertex 0 again.
        // Joining 2's set to 1's must not undo its joining to 0's.
        assert_eq!(charts(&[2, 0, 1, 0, 3, 4], 5), (vec![0, 0], 1));
    }
}
