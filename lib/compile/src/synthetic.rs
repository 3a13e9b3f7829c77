//! Render matrices for a known screen→texture map, built without geometry: what the unit
//! tests and benchmarks of the solver use in place of the hardware model. The filter
//! weights follow the Vulkan rules (texel centres at half-integers, clamp-to-edge, LOD =
//! log2 of the larger screen-space derivative length in level-0 texels, trilinear blending
//! between ⌊λ⌋ and ⌊λ⌋ + 1).

use crate::{Filter, RenderMatrix, TextureLayout};

/// Builds A for a `width × height` screen where `map(x, y)` gives the texture coordinate
/// (s, t) ∈ [0, 1]² seen at pixel centre (x, y), or `None` where the object does not
/// cover the pixel. Derivatives come from central differences of `map` over one pixel.
pub fn warp_matrix(
    width: u32,
    height: u32,
    layout: TextureLayout,
    filter: Filter,
    map: impl Fn(f64, f64) -> Option<(f64, f64)>,
) -> RenderMatrix {
    let mut a = RenderMatrix { width, height, layout, row_start: vec![0], ..Default::default() };
    let (w0, h0) = (layout.width as f64, layout.height as f64);
    for py in 0..height {
        for px in 0..width {
            let (x, y) = (px as f64 + 0.5, py as f64 + 0.5);
            let Some((s, t)) = map(x, y) else { continue };
            let mut entries: Vec<(u32, f64)> = Vec::with_capacity(8);
            match filter {
                Filter::Nearest => {
                    let i = ((s * w0).floor().clamp(0.0, w0 - 1.0)) as u32;
                    let j = ((t * h0).floor().clamp(0.0, h0 - 1.0)) as u32;
                    entries.push((layout.texel(0, i, j) as u32, 1.0));
                }
                Filter::Bilinear => bilinear(&layout, 0, s, t, 1.0, &mut entries),
                Filter::Trilinear => {
                    let d = |dx: f64, dy: f64| {
                        let p = map(x + dx, y + dy).unwrap_or((s, t));
                        let m = map(x - dx, y - dy).unwrap_or((s, t));
                        ((p.0 - m.0) * w0 / (2.0 * (dx + dy)), (p.1 - m.1) * h0 / (2.0 * (dx + dy)))
                    };
                    let (ux, vx) = d(0.5, 0.0);
                    let (uy, vy) = d(0.0, 0.5);
                    let rho = (ux * ux + vx * vx).sqrt().max((uy * uy + vy * vy).sqrt());
                    let lambda = rho.max(1e-30).log2().clamp(0.0, (layout.levels - 1) as f64);
                    let m0 = lambda.floor() as u32;
                    let f = lambda - m0 as f64;
                    bilinear(&layout, m0, s, t, 1.0 - f, &mut entries);
                    if f > 0.0 && m0 + 1 < layout.levels {
                        bilinear(&layout, m0 + 1, s, t, f, &mut entries);
                    }
                }
            }
            a.pixels.push(py * width + px);
            a.coverage.push(1.0);
            for (c, v) in entries {
                if v != 0.0 {
                    a.cols.push(c);
                    a.vals.push(v as f32);
                }
            }
            a.row_start.push(a.cols.len() as u32);
        }
    }
    a
}

/// Bilinear taps of level m at (s, t), clamp-to-edge, scaled by `weight`.
fn bilinear(layout: &TextureLayout, m: u32, s: f64, t: f64, weight: f64, out: &mut Vec<(u32, f64)>) {
    let (w, h) = layout.level_size(m);
    let (u, v) = (s * w as f64 - 0.5, t * h as f64 - 0.5);
    let (i0, j0) = (u.floor(), v.floor());
    let (fu, fv) = (u - i0, v - j0);
    let ci = |i: f64| i.clamp(0.0, (w - 1) as f64) as u32;
    let cj = |j: f64| j.clamp(0.0, (h - 1) as f64) as u32;
    for (dj, wv) in [(0.0, 1.0 - fv), (1.0, fv)] {
        for (di, wu) in [(0.0, 1.0 - fu), (1.0, fu)] {
            out.push((layout.texel(m, ci(i0 + di), cj(j0 + dj)) as u32, weight * wu * wv));
        }
    }
}
