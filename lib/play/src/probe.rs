//! Probe mode (thesis 3.4.3, "parallel matrix inference with texel identifiers"): the render
//! matrix A measured through the player's own pipeline with test renderings, so texture
//! inference can target whatever the adapter does — anisotropic filtering included, which no
//! specification pins down and the hardware model does not describe.
//!
//! Each rendering activates every S-th texel per axis of every third MIP level: active
//! texels hold 1 in red, all others 0. Green and blue hold a texel identifier: the group
//! (gx, gy) of the active texel and its level m (blue = 16·gy + m), written into every texel
//! of the active texel's filtering neighbourhood — the texels on its own level and on the
//! next coarser and finer levels that a lookup reading it may also read. Neighbourhoods of
//! texels solved in parallel never overlap, so a pixel that reads an active texel reads
//! exactly one, its red value is that texel's weight (float render target, no quantization)
//! and its green and blue are the identifier unchanged (a filtered constant).
//!
//! A lookup's reach R is how far (in texels of the active level) its other reads may lie
//! beyond the bilinear footprint of the read that touches the active texel: 0 for nearest,
//! bilinear and trilinear; for anisotropic filtering, whose taps spread along the
//! footprint's major axis by an amount the adapter chooses, as far as the footprint is long.
//! The spacing along an axis is S = 6 + 2R for that axis's reach (the next power of two, at
//! least 8, along a repeat axis, so that the groups tile the power-of-two period):
//! 3·S_x·S_y renderings at most (108 at R = 0 with clamping; S_x·S_y for nearest and
//! bilinear, which read level 0 only; fewer where a phase's finest active level is narrower
//! than the spacing) give every column, independent of resolution.
//!
//! The reach of an anisotropic lookup is estimated first, per axis, with two renderings of
//! textures holding each texel's centre (level-0 texel units), its square and its level's
//! scale 2^m: the filtered values are the footprint's mean, second moment and mean level
//! scale, so its spread σ per axis follows (less the ¼ texel² of one bilinear lookup); the
//! first reach is 2σ + 1 texels of that scale, the largest over the covered pixels. It is a
//! guess (the footprint's shape is the adapter's), which the check below corrects upward.
//!
//! The measured A is checked against the pipeline itself: a pseudo-random texture rendered
//! through the pipeline must equal A times that texture at every covered pixel. A failed
//! check (footprints wider than the neighbourhoods) probes again with 1.5 times the reach,
//! up to [`max_reach`]; so the adapter's real footprint decides the cost.

use std::collections::BTreeMap;

use pis_compile::{
    Address, DrawMesh, Filter, RenderMatrix, TextureLayout, TexturedObject, Viewport,
};

use crate::error::PlayError;
use crate::gpu::Gpu;
use crate::image::FloatImage;
use crate::textured::{ObjectScene, ObjectTexture, TexturedPipeline};

/// Texels between texels probed in parallel along an axis, for lookups of reach `reach`.
pub fn spacing(address: Address, reach: u32) -> u32 {
    let s = 6 + 2 * reach;
    match address {
        Address::ClampToEdge => s,
        Address::Repeat => s.next_power_of_two().max(8),
    }
}

/// The largest reach worth probing for a filter: 0 for isotropic filters; 64 for
/// anisotropic filtering, whatever its clamp (an adapter may take more taps than the clamp:
/// Mesa 22.3's lavapipe spreads the same footprint for clamps 4 and 16).
pub fn max_reach(filter: Filter) -> u32 {
    match filter {
        Filter::Anisotropic(_) => 64,
        _ => 0,
    }
}

/// The level-`level` texels of one axis that belong to the neighbourhood of active texel
/// `i_a` on level `active` (level differs by at most 1), as an inclusive range, for lookups
/// of reach `r`.
fn neighbourhood(i_a: i64, level: u32, active: u32, s: i64, r: i64) -> (i64, i64) {
    if level == active {
        (i_a - s / 2, i_a + s / 2 - 1)
    } else if level == active + 1 {
        // Coarser: a lookup reading i_a reads positions u_m ∈ (i_a − ½ − r, i_a + 1½ + r), so
        // u_{m+1} − ½ ∈ ((2·i_a − 3 − 2r)/4, (2·i_a + 1 + 2r)/4).
        ((2 * i_a - 3 - 2 * r).div_euclid(4), (2 * i_a + 1 + 2 * r).div_euclid(4) + 1)
    } else {
        // Finer: u_{m−1} − ½ ∈ (2·i_a − 1½ − 2r, 2·i_a + 2½ + 2r).
        (2 * i_a - 2 - 2 * r, 2 * i_a + 3 + 2 * r)
    }
}

/// Per axis, per level: the group of each texel (−1: none) for active level `active` and
/// offset `o`.
fn axis_groups(
    sizes: &[u32],
    active: u32,
    o: u32,
    s: u32,
    r: u32,
    address: Address,
    level: u32,
) -> Vec<i32> {
    let n = sizes[level as usize] as i64;
    let active_n = sizes[active as usize] as i64;
    let mut g = vec![-1i32; n as usize];
    let mut group = 0i64;
    loop {
        let i_a = o as i64 + s as i64 * group;
        if i_a >= active_n {
            break;
        }
        let (lo, hi) = neighbourhood(i_a, level, active, s as i64, r as i64);
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

/// The probe texture of one rendering: phase `p` (active levels m ≡ p mod 3), offsets (ox,
/// oy), spacing `s` per axis for reach `r`.
fn probe_texture(
    layout: &TextureLayout,
    address: [Address; 2],
    s: [u32; 2],
    r: [u32; 2],
    p: u32,
    o: [u32; 2],
) -> Vec<f32> {
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
        let gx = axis_groups(&widths, active, o[0], s[0], r[0], address[0], level);
        let gy = axis_groups(&heights, active, o[1], s[1], r[1], address[1], level);
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

/// A render matrix measured through the GPU, with what it cost and how well it predicts the
/// pipeline.
#[derive(Clone, Debug)]
pub struct Probe {
    pub matrix: RenderMatrix,
    /// The lookup reach per axis the neighbourhoods allowed for (see the module docs).
    pub reach: [u32; 2],
    /// Test renderings made, those of failed reaches and the checks included.
    pub renderings: u32,
    /// Largest |A·x − rendering of x| over the covered pixels and colour channels, for the
    /// check texture x (values in [0, 1)).
    pub check_error: f32,
}

/// Largest |A·x − rendering of x| the check accepts: the measured weights and the filtered
/// values are both f32, so a correct A predicts the rendering to rounding.
pub const CHECK_TOLERANCE: f32 = 1e-3;

/// The render matrix of `object` measured through wgpu with 3·S_x·S_y renderings. Rows are
/// the pixels the object covers (alpha 1), coverage 1, columns sorted.
pub fn probe_render_matrix(
    gpu: &Gpu,
    pipeline: &TexturedPipeline,
    viewport: Viewport,
    occluders: &[DrawMesh],
    object: &TexturedObject,
) -> Result<RenderMatrix, PlayError> {
    probe(gpu, pipeline, viewport, occluders, object).map(|p| p.matrix)
}

/// Probe mode with its check: measures A at the reach the footprint renderings give (0 for
/// isotropic filters), then at 1.5 times that up to [`max_reach`] of the sampler's filter,
/// until A predicts a pseudo-random texture's rendering within [`CHECK_TOLERANCE`]; an
/// error when no reach does.
pub fn probe(
    gpu: &Gpu,
    pipeline: &TexturedPipeline,
    viewport: Viewport,
    occluders: &[DrawMesh],
    object: &TexturedObject,
) -> Result<Probe, PlayError> {
    let layout = object.layout;
    if gpu.texture_format != wgpu::TextureFormat::Rgba32Float {
        return Err(PlayError::ProbeNeedsFloat32(gpu.info.name.clone()));
    }
    pis_compile::model::render_matrix_inputs_ok(viewport, object)?;
    let scene = ObjectScene::new(gpu, pipeline, viewport, occluders, object)?;
    let texture = ObjectTexture::new(gpu, layout);
    let check = check_texture(&layout);
    texture.upload(gpu, &check)?;
    let rendered = scene.render(gpu, pipeline, &texture)?;
    let mut renderings = 1;
    let top = max_reach(object.sampler.filter);
    let mut reach = [0, 0];
    if top > 0 {
        reach = footprint_reach(gpu, pipeline, &scene, &texture, &layout)?.map(|r| r.min(top));
        renderings += 2;
    }
    loop {
        let (matrix, n) = measure(gpu, pipeline, &scene, &texture, object, reach)?;
        renderings += n;
        let check_error = prediction_error(&matrix, &check, &rendered);
        if check_error <= CHECK_TOLERANCE {
            return Ok(Probe { matrix, reach, renderings, check_error });
        }
        if reach.iter().all(|&r| r >= top) {
            return Err(PlayError::ProbeCheck {
                filter: format!("{:?}", object.sampler.filter),
                reach: reach[0].max(reach[1]),
                error: check_error,
                tolerance: CHECK_TOLERANCE,
            });
        }
        reach = reach.map(|r| (r + 1).max(r * 3 / 2).min(top));
    }
}

/// The reach per axis of the widest footprint over the covered pixels, from the footprint's
/// mean, second moment and level scale (see the module docs).
fn footprint_reach(
    gpu: &Gpu,
    pipeline: &TexturedPipeline,
    scene: &ObjectScene,
    texture: &ObjectTexture,
    layout: &TextureLayout,
) -> Result<[u32; 2], PlayError> {
    // Texel centres in level-0 texel units, relative to the texture's centre (smaller
    // squares, less rounding).
    let (cx, cy) = (layout.width as f32 / 2.0, layout.height as f32 / 2.0);
    let texels = |f: &dyn Fn(f32, f32, f32) -> [f32; 3]| {
        let mut rgba = vec![1.0f32; layout.texel_count() * 4];
        for m in 0..layout.levels {
            let (w, h) = layout.level_size(m);
            let scale = (1u64 << m) as f32;
            for j in 0..h {
                for i in 0..w {
                    let t = layout.texel(m, i, j) * 4;
                    let c = f((i as f32 + 0.5) * scale - cx, (j as f32 + 0.5) * scale - cy, scale);
                    rgba[t..t + 3].copy_from_slice(&c);
                }
            }
        }
        rgba
    };
    texture.upload(gpu, &texels(&|x, y, scale| [x, y, scale]))?;
    let first = scene.render(gpu, pipeline, texture)?;
    texture.upload(gpu, &texels(&|x, y, _| [x * x, y * y, 0.0]))?;
    let second = scene.render(gpu, pipeline, texture)?;
    let mut reach = [0u32; 2];
    for q in 0..(first.width * first.height) as usize {
        let (a, b) = (first.pixel(q), second.pixel(q));
        if a[3] <= 0.5 || a[2].is_nan() || a[2] < 1.0 {
            continue;
        }
        // Texels of the mean level read (the check corrects a footprint that reads finer).
        let level_scale = a[2];
        for k in 0..2 {
            // Less the spread of one bilinear lookup (at most ¼ texel² of its level).
            let var = (b[k] - a[k] * a[k] - 0.25 * level_scale * level_scale).max(0.0);
            let r = 2.0 * var.sqrt() / level_scale + 1.0;
            if r.is_finite() {
                reach[k] = reach[k].max(r.ceil() as u32);
            }
        }
    }
    Ok(reach)
}

/// The check texture: pseudo-random RGB in [0, 1), alpha 1, on every level.
fn check_texture(layout: &TextureLayout) -> Vec<f32> {
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 40) as f32 / (1u64 << 24) as f32
    };
    let mut rgba = vec![1.0f32; layout.texel_count() * 4];
    for t in rgba.chunks_exact_mut(4) {
        t[0] = next();
        t[1] = next();
        t[2] = next();
    }
    rgba
}

/// Largest |A·x − rendered| over the pixels either covers (a pixel only one covers counts
/// as an error of 1).
fn prediction_error(a: &RenderMatrix, x: &[f32], rendered: &FloatImage) -> f32 {
    let mut worst = 0.0f32;
    let mut in_a = vec![false; rendered.width as usize * rendered.height as usize];
    for r in 0..a.rows() {
        let q = a.pixels[r] as usize;
        let Some(seen) = in_a.get_mut(q) else { return 1.0 };
        *seen = true;
        let px = rendered.pixel(q);
        if px[3] <= 0.5 {
            worst = worst.max(1.0);
            continue;
        }
        let (cols, vals) = a.row(r);
        for ch in 0..3 {
            let want: f32 = cols.iter().zip(vals).map(|(&c, &v)| v * x[c as usize * 4 + ch]).sum();
            worst = worst.max((want - px[ch]).abs());
        }
    }
    if in_a.iter().enumerate().any(|(q, &seen)| !seen && rendered.pixel(q)[3] > 0.5) {
        worst = worst.max(1.0);
    }
    worst
}

/// One measurement of A at reach `reach` per axis; also the number of renderings it made.
fn measure(
    gpu: &Gpu,
    pipeline: &TexturedPipeline,
    scene: &ObjectScene,
    texture: &ObjectTexture,
    object: &TexturedObject,
    reach: [u32; 2],
) -> Result<(RenderMatrix, u32), PlayError> {
    let layout = object.layout;
    let address = object.sampler.address;
    let s = [spacing(address[0], reach[0]), spacing(address[1], reach[1])];
    let mut rows: BTreeMap<u32, BTreeMap<u32, f32>> = BTreeMap::new();
    let mut covered: Option<Vec<u32>> = None;
    let mut renderings = 0;
    // Nearest and bilinear read level 0 only: one phase suffices.
    let phases = if object.sampler.filter.uses_mips() { 3.min(layout.levels) } else { 1 };
    for p in 0..phases {
        // The finest active level of the phase; an offset beyond its size (spacing wider than
        // the level) activates no texel on any level of the phase: no rendering.
        let (w, h) = layout.level_size(p);
        for oy in 0..s[1].min(h) {
            for ox in 0..s[0].min(w) {
                texture.upload(gpu, &probe_texture(&layout, address, s, reach, p, [ox, oy]))?;
                let img = scene.render(gpu, pipeline, texture)?;
                renderings += 1;
                if covered.is_none() {
                    let c: Vec<u32> = (0..img.width * img.height)
                        .filter(|&q| img.pixel(q as usize)[3] > 0.5)
                        .collect();
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
                    *row.entry(layout.texel(m, i as u32, j as u32) as u32).or_insert(0.0) += r;
                }
            }
        }
    }
    let mut a = RenderMatrix {
        width: scene.viewport().width,
        height: scene.viewport().height,
        layout,
        ..Default::default()
    };
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
    Ok((a, renderings))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn neighbourhoods_of_parallel_texels_do_not_overlap() {
        for o in 0..6 {
            for (level, active) in [(3, 3), (4, 3), (2, 3)] {
                let sizes = [200, 100, 50, 25, 13];
                let g = axis_groups(&sizes, active, o, 6, 0, Address::ClampToEdge, level);
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
            let (lo, hi) = neighbourhood(i_a, 4, 3, 6, 0);
            for k in 0..200 {
                let u = i_a as f64 - 0.5 + (k as f64 + 0.5) / 100.0;
                let v = u / 2.0 - 0.5;
                let (a, b) = (v.floor() as i64, v.floor() as i64 + 1);
                assert!(a >= lo && b <= hi, "i_a {i_a} u {u}: {a},{b} not in {lo}..={hi}");
                let f = 2.0 * u - 0.5;
                let (flo, fhi) = neighbourhood(i_a, 2, 3, 6, 0);
                assert!(f.floor() as i64 >= flo && (f.floor() as i64) < fhi);
            }
        }
    }

    #[test]
    fn neighbourhoods_of_any_reach_are_disjoint_and_cover_the_reach() {
        for r in 0..40i64 {
            let s = spacing(Address::ClampToEdge, r as u32) as i64;
            for i_a in 0..30i64 {
                for level in [2, 3, 4] {
                    let (_, hi) = neighbourhood(i_a, level, 3, s, r);
                    let (lo, _) = neighbourhood(i_a + s, level, 3, s, r);
                    assert!(
                        hi < lo,
                        "reach {r} spacing {s} level {level} texel {i_a}: {hi} ≥ {lo}"
                    );
                }
                // Every read within the reach: level 3 texels i_a − r − 1 ..= i_a + r + 1, and
                // the coarser texels a lookup at those positions reads.
                let (lo, hi) = neighbourhood(i_a, 3, 3, s, r);
                assert!(lo < i_a - r && hi > i_a + r);
                let (clo, chi) = neighbourhood(i_a, 4, 3, s, r);
                for k in 0..=100 {
                    let u = i_a as f64 - 0.5 - r as f64 + (2.0 + 2.0 * r as f64) * k as f64 / 100.0;
                    let v = u / 2.0 - 0.5;
                    assert!(
                        v.floor() as i64 >= clo && (v.floor() as i64) < chi,
                        "reach {r}: u {u}"
                    );
                }
            }
        }
        assert_eq!(spacing(Address::Repeat, 0), 8);
        assert_eq!(spacing(Address::Repeat, 2), 16);
    }

    #[test]
    fn only_anisotropic_lookups_reach_beyond_bilinear() {
        assert_eq!(max_reach(Filter::Trilinear), 0);
        assert_eq!(max_reach(Filter::Bilinear), 0);
        assert!(max_reach(Filter::Anisotropic(1)) > 0);
    }
}
