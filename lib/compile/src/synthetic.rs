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
                // Isotropic: the synthetic matrix has no anisotropic footprint.
                Filter::Trilinear | Filter::Anisotropic(_) => {
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
fn bilinear(
    layout: &TextureLayout,
    m: u32,
    s: f64,
    t: f64,
    weight: f64,
    out: &mut Vec<(u32, f64)>,
) {
    let (w, h) = layout.level_size(m);
    // Texel coordinates of level m: u = s·w₀/2^m (crate::filter; on odd sizes the level's
    // last texel, the replicated boundary, is only partly inside the used area).
    let k = (1u64 << m) as f64;
    let (u, v) = (s * layout.width as f64 / k - 0.5, t * layout.height as f64 / k - 0.5);
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::filter::{self, Taps};
    use crate::{Address, Sampler};

    /// On odd sizes the synthetic matrices place coarse levels as the hardware model does
    /// (u = s·w₀/2^m), so solver tests see the pyramid the player samples.
    #[test]
    fn synthetic_taps_match_the_hardware_model_on_odd_sizes() {
        let layout = TextureLayout::full(5, 3);
        let sampler = Sampler { filter: Filter::Bilinear, address: [Address::ClampToEdge; 2] };
        for m in 0..layout.levels {
            for k in 0..40 {
                let st = [(k as f64 * 0.618) % 1.0, (k as f64 * 0.382) % 1.0];
                let mut ours = Vec::new();
                bilinear(&layout, m, st[0], st[1], 1.0, &mut ours);
                let mut merged: std::collections::BTreeMap<u32, f64> = Default::default();
                for (c, w) in ours {
                    *merged.entry(c).or_default() += w;
                }
                let mut taps = Taps::default();
                filter::bilinear(&layout, &sampler, m, st, 1.0, &mut taps);
                let model: Vec<(u32, f32)> = taps.sorted().collect();
                let ours: Vec<(u32, f64)> = merged.into_iter().filter(|(_, w)| *w != 0.0).collect();
                assert_eq!(ours.len(), model.len(), "level {m} at {st:?}: {ours:?} vs {model:?}");
                for ((c0, w0), (c1, w1)) in ours.iter().zip(&model) {
                    assert_eq!(c0, c1);
                    assert!(
                        (w0 - *w1 as f64).abs() < 1e-5,
                        "level {m} at {st:?}: {ours:?} vs {model:?}"
                    );
                }
            }
        }
    }
}
