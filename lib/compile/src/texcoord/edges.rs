//! Visible triangle edges (thesis 3.2): edges of the triangles the z-buffer shows, clipped
//! to the screen, with their screen length, their texture-coordinate endpoints and the
//! weight W_i of eq. 3.1 (the screen areas of the visible triangles on either side).

use std::collections::BTreeMap;

use glam::{DVec2, Vec2};

use super::visibility::{
    edge, rasterize_ids, screen_triangle, IdBuffer, ScreenVertex, ViewGeometry,
};

/// One visible edge in one view, after clipping to the screen.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VisibleEdge {
    /// Length on the screen in pixels (s_i).
    pub screen_length: f64,
    /// Texture coordinates of the clipped endpoints.
    pub uv: [DVec2; 2],
    /// W_i: the screen areas of the visible triangles sharing the edge.
    pub weight: f64,
}

/// The visible edges of `indices` in `view`, and the z-buffer that selected them.
pub fn visible_edges(
    view: &ViewGeometry,
    uvs: &[Vec2],
    indices: &[u32],
) -> (Vec<VisibleEdge>, IdBuffer) {
    let ids = rasterize_ids(view, indices);
    let mut visible: Vec<u32> = ids.ids.iter().flatten().copied().collect();
    visible.sort_unstable();
    visible.dedup();
    // edge (lo, hi) → summed weight
    let mut weights: BTreeMap<(u32, u32), f64> = BTreeMap::new();
    for &t in &visible {
        let tri = &indices[3 * t as usize..3 * t as usize + 3];
        let Some(v) = screen_triangle(view, tri) else { continue };
        let area = 0.5 * edge(v[0].p, v[1].p, v[2].p).abs();
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            *weights.entry((a.min(b), a.max(b))).or_insert(0.0) += area;
        }
    }
    let mut out = Vec::with_capacity(weights.len());
    for ((a, b), weight) in weights {
        let (Some(va), Some(vb)) = (
            screen_triangle(view, &[a, a, a]).map(|v| v[0]),
            screen_triangle(view, &[b, b, b]).map(|v| v[0]),
        ) else {
            continue;
        };
        let (Some(&ua), Some(&ub)) = (uvs.get(a as usize), uvs.get(b as usize)) else { continue };
        if let Some(e) =
            clip_edge(va, vb, ua.as_dvec2(), ub.as_dvec2(), view.width, view.height, weight)
        {
            out.push(e);
        }
    }
    (out, ids)
}

/// Clips the screen segment to the screen rectangle (Liang–Barsky) and interpolates the
/// texture coordinates perspective-correctly at the new endpoints.
fn clip_edge(
    a: ScreenVertex,
    b: ScreenVertex,
    ua: DVec2,
    ub: DVec2,
    w: u32,
    h: u32,
    weight: f64,
) -> Option<VisibleEdge> {
    let d = b.p - a.p;
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for (p, q) in [(-d.x, a.p.x), (d.x, w as f64 - a.p.x), (-d.y, a.p.y), (d.y, h as f64 - a.p.y)] {
        if p == 0.0 {
            if q < 0.0 {
                return None;
            }
        } else {
            let r = q / p;
            if p < 0.0 {
                t0 = t0.max(r)
            } else {
                t1 = t1.min(r)
            }
        }
    }
    if t0 >= t1 {
        return None;
    }
    let uv_at = |t: f64| {
        let (wa, wb) = ((1.0 - t) * a.inv_w, t * b.inv_w);
        (ua * wa + ub * wb) / (wa + wb)
    };
    Some(VisibleEdge { screen_length: d.length() * (t1 - t0), uv: [uv_at(t0), uv_at(t1)], weight })
}
