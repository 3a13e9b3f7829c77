//! The sampler's filter weights (Vulkan "Texel Filtering"): which texels of which MIP levels
//! a texture lookup at (s, t) with level of detail λ blends, and with what weights. Level m
//! of a texture with used size w × h has `mip_size(w, h, m)` texels and texel coordinates
//! `u = s·w/2^m`, `v = t·h/2^m` (texel i covers [i, i+1)): the player allocates levels so
//! that this holds on the GPU (see `pis_play::textured`).
//!
//! - nearest: texel ⌊u⌋, ⌊v⌋ of level 0;
//! - bilinear: level 0, texels ⌊u − ½⌋ and ⌊u − ½⌋ + 1 weighted 1 − α and α, α = frac(u − ½);
//! - trilinear: bilinear on levels ⌊λ⌋ and min(⌊λ⌋ + 1, max level), blended by frac(λ).
//!
//! Addressing applies per texel index: clamp-to-edge clamps to [0, size − 1]; repeat wraps
//! modulo size.

use crate::{Address, Filter, Sampler, TextureLayout};

/// The most texels one lookup reads.
pub const MAX_TAPS: usize = 12;

/// At most [`MAX_TAPS`] (column, weight) pairs: the texels one lookup reads (8 for a
/// trilinear surface lookup; 12 for a trilinear cube-map lookup at a cube corner).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Taps {
    pub len: usize,
    pub cols: [u32; MAX_TAPS],
    pub weights: [f32; MAX_TAPS],
}

impl Taps {
    /// Adds a weight to a column, merging repeated columns (clamping reads a texel twice);
    /// zero weights are skipped.
    pub fn add(&mut self, col: u32, w: f64) {
        if w == 0.0 {
            return;
        }
        if let Some(k) = self.cols[..self.len].iter().position(|&c| c == col) {
            self.weights[k] += w as f32;
        } else if self.len < MAX_TAPS {
            self.cols[self.len] = col;
            self.weights[self.len] = w as f32;
            self.len += 1;
        }
    }

    /// The taps sorted by column.
    pub fn sorted(&self) -> impl Iterator<Item = (u32, f32)> {
        let mut v: [(u32, f32); MAX_TAPS] = [(0, 0.0); MAX_TAPS];
        for (k, e) in v.iter_mut().enumerate().take(self.len) {
            *e = (self.cols[k], self.weights[k]);
        }
        v[..self.len].sort_unstable_by_key(|p| p.0);
        v.into_iter().take(self.len)
    }
}

/// Texel index `i` of a level `size` texels wide under an addressing mode.
pub fn address(i: i64, size: u32, mode: Address) -> u32 {
    match mode {
        Address::ClampToEdge => i.clamp(0, size as i64 - 1) as u32,
        Address::Repeat => i.rem_euclid(size as i64) as u32,
    }
}

/// Adds the bilinear taps of level `m` at (s, t), scaled by `scale`.
pub fn bilinear(
    layout: &TextureLayout,
    sampler: &Sampler,
    m: u32,
    st: [f64; 2],
    scale: f64,
    taps: &mut Taps,
) {
    let (w, h) = layout.level_size(m);
    let k = (0.5f64).powi(m as i32);
    let u = st[0] * layout.width as f64 * k - 0.5;
    let v = st[1] * layout.height as f64 * k - 0.5;
    let (i0, j0) = (u.floor(), v.floor());
    let (a, b) = (u - i0, v - j0);
    let (i0, j0) = (i0 as i64, j0 as i64);
    let is = [address(i0, w, sampler.address[0]), address(i0 + 1, w, sampler.address[0])];
    let js = [address(j0, h, sampler.address[1]), address(j0 + 1, h, sampler.address[1])];
    let wi = [1.0 - a, a];
    let wj = [1.0 - b, b];
    for (dj, &j) in js.iter().enumerate() {
        for (di, &i) in is.iter().enumerate() {
            taps.add(layout.texel(m, i, j) as u32, scale * wi[di] * wj[dj]);
        }
    }
}

/// The taps of one lookup at (s, t) with level of detail λ (already clamped by `texture_lod`).
pub fn sample_taps(
    layout: &TextureLayout,
    sampler: &Sampler,
    st: [f64; 2],
    lambda: f64,
    taps: &mut Taps,
) {
    *taps = Taps::default();
    match sampler.filter {
        Filter::Nearest => {
            let (w, h) = layout.level_size(0);
            let i = address((st[0] * layout.width as f64).floor() as i64, w, sampler.address[0]);
            let j = address((st[1] * layout.height as f64).floor() as i64, h, sampler.address[1]);
            taps.add(layout.texel(0, i, j) as u32, 1.0);
        }
        Filter::Bilinear => bilinear(layout, sampler, 0, st, 1.0, taps),
        // The model's part of an anisotropic lookup is its isotropic trilinear lookup only:
        // `render_matrix` refuses anisotropic samplers (probe mode measures them).
        Filter::Trilinear | Filter::Anisotropic(_) => {
            let q = layout.levels.saturating_sub(1);
            let d = lambda.clamp(0.0, q as f64);
            let hi = (d.floor() as u32).min(q);
            let lo = (hi + 1).min(q);
            let delta = d - hi as f64;
            bilinear(layout, sampler, hi, st, 1.0 - delta, taps);
            if delta > 0.0 {
                bilinear(layout, sampler, lo, st, delta, taps);
            }
        }
    }
}

/// The largest LOD the sampler may use: 0 for nearest and bilinear (level 0 only).
pub fn max_level(layout: &TextureLayout, sampler: &Sampler) -> f64 {
    if sampler.filter.uses_mips() {
        layout.levels.saturating_sub(1) as f64
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn taps(layout: TextureLayout, sampler: Sampler, st: [f64; 2], lambda: f64) -> Vec<(u32, f32)> {
        let mut t = Taps::default();
        sample_taps(&layout, &sampler, st, lambda, &mut t);
        t.sorted().collect()
    }

    #[test]
    fn texel_centre_reads_one_texel() {
        let l = TextureLayout::full(5, 3);
        let s = Sampler { filter: Filter::Bilinear, address: [Address::ClampToEdge; 2] };
        assert_eq!(taps(l, s, [2.5 / 5.0, 1.5 / 3.0], 0.0), vec![(l.texel(0, 2, 1) as u32, 1.0)]);
    }

    #[test]
    fn clamp_and_repeat_differ_at_the_border() {
        let l = TextureLayout::full(4, 4);
        let clamp = Sampler { filter: Filter::Bilinear, address: [Address::ClampToEdge; 2] };
        let repeat = Sampler { filter: Filter::Bilinear, address: [Address::Repeat; 2] };
        // Half-way between texel 3 and texel 4 ≡ 0 along s, on texel row 1's centre.
        let st = [1.0, 1.5 / 4.0];
        assert_eq!(taps(l, clamp, st, 0.0), vec![(l.texel(0, 3, 1) as u32, 1.0)]);
        assert_eq!(
            taps(l, repeat, st, 0.0),
            vec![(l.texel(0, 0, 1) as u32, 0.5), (l.texel(0, 3, 1) as u32, 0.5)]
        );
    }

    #[test]
    fn non_power_of_two_levels_scale_by_exact_halves() {
        // 5×3: level 1 is 3×2 with texel coordinates u = s·5/2.
        let l = TextureLayout::full(5, 3);
        let s = Sampler { filter: Filter::Trilinear, address: [Address::ClampToEdge; 2] };
        // s = 0.7 → u1 = 1.75 → bilinear between 1 and 2 with α = 0.25; t = 0.5 → v1 = 0.75 → rows 0, 1.
        let t = taps(l, s, [0.7, 0.5], 1.0);
        let want =
            [(1, 0, 0.75 * 0.75), (2, 0, 0.25 * 0.75), (1, 1, 0.75 * 0.25), (2, 1, 0.25 * 0.25)];
        for (i, j, w) in want {
            let c = l.texel(1, i, j) as u32;
            let got = t.iter().find(|p| p.0 == c).map(|p| p.1).unwrap_or(0.0);
            assert!((got - w as f32).abs() < 1e-6, "texel {i},{j}: {got} vs {w}");
        }
        let sum: f32 = t.iter().map(|p| p.1).sum();
        assert!((sum - 1.0).abs() < 1e-6);
    }

    #[test]
    fn trilinear_blends_two_levels_with_eight_taps() {
        let l = TextureLayout::full(16, 16);
        let s = Sampler { filter: Filter::Trilinear, address: [Address::ClampToEdge; 2] };
        let t = taps(l, s, [0.3, 0.6], 1.25);
        assert_eq!(t.len(), 8);
        let level1: f32 =
            t.iter().filter(|p| (p.0 as usize) < l.level_offset(2)).map(|p| p.1).sum();
        assert!((level1 - 0.75).abs() < 1e-6);
    }
}
