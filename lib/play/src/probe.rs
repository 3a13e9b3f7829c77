//! Probe mode (thesis 3.4.3, "parallel matrix inference with texel identifiers"): the render
//! matrix A measured through the player's own pipeline with test renderings, so texture
//! inference can target whatever the adapter does.
//!
//! Each rendering activates every S-th texel per axis (S = 6, or 8 along a repeat axis so
//! that the groups tile the power-of-two period) of every third MIP level: active texels hold
//! 1 in red, all others 0. Green and blue hold a texel identifier: the group (gx, gy) of the
//! active texel and its level m (blue = 16·gy + m), written into every texel of the active
//! texel's filtering neighbourhood — its bilinear neighbours on its own level and the texels
//! that a trilinear lookup reading it may blend from the next coarser and finer levels.
//! Neighbourhoods of texels solved in parallel never overlap, so a pixel that reads an active
//! texel reads exactly one, its red value is that texel's weight (float render target, no
//! quantization) and its green and blue are the identifier unchanged (a filtered constant).
//! 3 · S_x · S_y renderings (108 with clamping; S_x · S_y = 36 for nearest and bilinear, which
//! read level 0 only) give every column, independent of resolution.

use std::collections::BTreeMap;

use pis_compile::{Address, DrawMesh, RenderMatrix, TextureLayout, TexturedObject, Viewport};

use crate::error::PlayError;
use crate::gpu::Gpu;
use crate::textured::{ObjectScene, ObjectTexture, TexturedPipeline};

/// Texels between texels probed in parallel along an axis.
pub fn spacing(address: Address) -> u32 {
    match address {
        Address::ClampToEdge => 6,
        Address::Repeat => 8,
    }
}

/// The level-`level` texels of one axis that belong to the neighbourhood of active texel
/// `i_a` on level `active` (level differs by at most 1), as an inclusive range.
fn neighbourhood(i_a: i64, level: u32, active: u32, s: i64) -> (i64, i64) {
    if level == active {
        (i_a - s / 2, i_a + s / 2 - 1)
    } else if level == active + 1 {
        // Coarser: a lookup reading i_a has u_m ∈ (i_a − ½, i_a + 1½), so u_{m+1} − ½ ∈ (i_a/2 − ¾, i_a/2 + ¼).
        ((2 * i_a - 3).div_euclid(4), (2 * i_a + 1).div_euclid(4) + 1)
    } else {
        // Finer: u_{m−1} − ½ ∈ (2·i_a − 1½, 2·i_a + 2½).
        (2 * i_a - 2, 2 * i_a + 3)
    }
}

/// Per axis, per level: the group of each texel (−1: none) for active level `active` and
/// offset `o`.
fn axis_groups(sizes: &[u32], active: u32, o: u32, s: u32, address: Address, level: u32) -> Vec<i32> {
    let n = sizes[level as usize] as i64;
    let active_n = sizes[active as usize] as i64;
    let mut g = vec![-1i32; n as usize];
    let mut group = 0i64;
    loop {
        let i_a = o as i64 + s as i64 * group;
        if i_a >= active_n {
            break;
        }
        let (lo, hi) = neighbourhood(i_a, level, active, s as i64);
        for i in lo..=hi {
            let k = match address {
                Address::ClampToEdge if i < 0 || i >= n => continue,
                Address::ClampToEdge => i,
                Address::Repeat => i.rem_euclid(n),
            };
            if g[k as usize] < 0 {
                g[k as usize] = group as i32;
            }
        }
        group += 1;
    }
    g
}

/// The probe texture of one rendering: phase `p` (active levels m ≡ p mod 3), offsets (ox, oy).
fn probe_texture(layout: &TextureLayout, address: [Address; 2], p: u32, o: [u32; 2]) -> Vec<f32> {
    let s = [spacing(address[0]), spacing(address[1])];
    let widths: Vec<u32> = (0..layout.levels).map(|m| layout.level_size(m).0).collect();
    let heights: Vec<u32> = (0..layout.levels).map(|m| layout.level_size(m).1).collect();
    let mut rgba = vec![0.0f32; layout.texel_count() * 4];
    for level in 0..layout.levels {
        // The active level whose neighbourhood this level belongs to.
        let active = match (level + 3 - p % 3) % 3 {
            0 => Some(level),
            1 => level.checked_sub(1),
            _ => Some(level + 1).filter(|&a| a < layout.levels),
        };
        let Some(active) = active else { continue };
        let gx = axis_groups(&widths, active, o[0], s[0], address[0], level);
        let gy = axis_groups(&heights, active, o[1], s[1], address[1], level);
        let (w, h) = layout.level_size(level);
        for j in 0..h {
            for i in 0..w {
                let (x, y) = (gx[i as usize], gy[j as usize]);
                if x < 0 || y < 0 {
                    continue;
                }
                let t = layout.texel(level, i, j) * 4;
                let on = level == active && i % s[0] == o[0] && j % s[1] == o[1];
                rgba[t] = if on { 1.0 } else { 0.0 };
                rgba[t + 1] = x as f32;
                rgba[t + 2] = (16 * y + active as i32) as f32;
            }
        }
    }
    rgba
}

/// The render matrix of `object` measured through wgpu with 3·S_x·S_y renderings. Rows are
/// the pixels the object covers (alpha 1), coverage 1, columns sorted.
pub fn probe_render_matrix(gpu: &Gpu, pipeline: &TexturedPipeline, viewport: Viewport, occluders: &[DrawMesh], object: &TexturedObject) -> Result<RenderMatrix, PlayError> {
    let layout = object.layout;
    if gpu.texture_format != wgpu::TextureFormat::Rgba32Float {
        return Err(PlayError::ProbeNeedsFloat32(gpu.info.name.clone()));
    }
    pis_compile::model::render_matrix_inputs_ok(viewport, object)?;
    let scene = ObjectScene::new(gpu, pipeline, viewport, occluders, object)?;
    let texture = ObjectTexture::new(gpu, layout);
    let address = object.sampler.address;
    let s = [spacing(address[0]), spacing(address[1])];
    let mut rows: BTreeMap<u32, BTreeMap<u32, f32>> = BTreeMap::new();
    let mut covered: Option<Vec<u32>> = None;
    // Nearest and bilinear read level 0 only: one phase suffices.
    let phases = if object.sampler.filter == pis_compile::Filter::Trilinear { 3.min(layout.levels) } else { 1 };
    for p in 0..phases {
        for oy in 0..s[1] {
            for ox in 0..s[0] {
                texture.upload(gpu, &probe_texture(&layout, address, p, [ox, oy]))?;
                let img = scene.render(gpu, pipeline, &texture)?;
                if covered.is_none() {
                    let c: Vec<u32> = (0..img.width * img.height).filter(|&q| img.pixel(q as usize)[3] > 0.5).collect();
                    for &q in &c {
                        rows.insert(q, BTreeMap::new());
                    }
                    covered = Some(c);
                }
                for (&q, row) in rows.iter_mut() {
                    let [r, g, b, _] = img.pixel(q as usize);
                    if r == 0.0 || !r.is_finite() {
                        continue;
                    }
                    let (gx, id) = (g.round() as i64, b.round() as i64);
                    let (m, gy) = (id.rem_euclid(16) as u32, id.div_euclid(16));
                    let i = ox as i64 + s[0] as i64 * gx;
                    let j = oy as i64 + s[1] as i64 * gy;
                    if m >= layout.levels || gx < 0 || gy < 0 {
                        continue;
                    }
                    let (w, h) = layout.level_size(m);
                    if i >= w as i64 || j >= h as i64 {
                        continue;
                    }
                    row.insert(layout.texel(m, i as u32, j as u32) as u32, r);
                }
            }
        }
    }
    let mut a = RenderMatrix { width: viewport.width, height: viewport.height, layout, ..Default::default() };
    a.row_start.push(0);
    for (q, row) in rows {
        a.pixels.push(q);
        a.coverage.push(1.0);
        for (c, v) in row {
            a.cols.push(c);
            a.vals.push(v);
        }
        a.row_start.push(a.cols.len() as u32);
    }
    Ok(a)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn neighbourhoods_of_parallel_texels_do_not_overlap() {
        for o in 0..6 {
            for (level, active) in [(3, 3), (4, 3), (2, 3)] {
                let sizes = [200, 100, 50, 25, 13];
                let g = axis_groups(&sizes, active, o, 6, Address::ClampToEdge, level);
                // Every group's range is contiguous: group ids never decrease along the axis.
                let ids: Vec<i32> = g.iter().copied().filter(|&x| x >= 0).collect();
                assert!(ids.windows(2).all(|w| w[0] <= w[1]), "o {o} level {level}: {g:?}");
            }
        }
    }

    #[test]
    fn coarse_neighbourhood_covers_every_bilinear_read() {
        // Any u_m whose bilinear footprint holds i_a: u_{m+1} = u_m/2 reads texels in range.
        for i_a in 0..40i64 {
            let (lo, hi) = neighbourhood(i_a, 4, 3, 6);
            for k in 0..200 {
                let u = i_a as f64 - 0.5 + (k as f64 + 0.5) / 100.0;
                let v = u / 2.0 - 0.5;
                let (a, b) = (v.floor() as i64, v.floor() as i64 + 1);
                assert!(a >= lo && b <= hi, "i_a {i_a} u {u}: {a},{b} not in {lo}..={hi}");
                let f = 2.0 * u - 0.5;
                let (flo, fhi) = neighbourhood(i_a, 2, 3, 6);
                assert!(f.floor() as i64 >= flo && (f.floor() as i64) < fhi);
            }
        }
    }
}
