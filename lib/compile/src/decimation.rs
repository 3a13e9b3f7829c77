//! The MIP chain the player builds (thesis 3.6): every level above 0 decimated from the one
//! below by the 2×2 box filter of `pis_format::mip::decimate` (ceil halving, the boundary
//! texel replicated on odd sizes). As a linear map of level 0, `x = D·x₀`.
//!
//! The player stores level 0 only and rebuilds the coarser levels by this decimation, so a
//! texture solved with free coarser levels is drawn with levels it was not solved with.
//! Solving for x₀ through `A·D` (the decimated parameterization, [`crate::MipSolve::Decimated`])
//! makes the texture the solver fits exactly the texture the player draws. D is applied level
//! by level (never assembled): one product costs O(n_t).

use crate::sparse::Csr;
use crate::TextureLayout;

/// D of a texture layout: one sparse step per level pair, level m → level m + 1, and its
/// transpose.
#[derive(Clone, Debug)]
pub struct Decimation {
    pub layout: TextureLayout,
    /// Per level m of 0..L−1: the (m+1)-level × m-level box filter and its transpose.
    steps: Vec<(Csr, Csr)>,
}

/// The 2×2 box filter from a `w × h` level to its `⌈w/2⌉ × ⌈h/2⌉` successor.
fn step(w: u32, h: u32) -> Csr {
    let (w, h) = (w as usize, h as usize);
    let (ow, oh) = (w.div_ceil(2), h.div_ceil(2));
    let mut m = Csr {
        rows: ow * oh,
        cols: w * h,
        row_start: Vec::with_capacity(ow * oh + 1),
        col: vec![],
        val: vec![],
    };
    m.row_start.push(0);
    for j in 0..oh {
        let (y0, y1) = (2 * j, (2 * j + 1).min(h - 1));
        for i in 0..ow {
            let (x0, x1) = (2 * i, (2 * i + 1).min(w - 1));
            // The four taps, a replicated boundary texel counted twice; columns ascending.
            let mut taps: Vec<(u32, f64)> = Vec::with_capacity(4);
            for (x, y) in [(x0, y0), (x1, y0), (x0, y1), (x1, y1)] {
                let c = (y * w + x) as u32;
                match taps.iter_mut().find(|t| t.0 == c) {
                    Some(t) => t.1 += 0.25,
                    None => taps.push((c, 0.25)),
                }
            }
            taps.sort_by_key(|t| t.0);
            for (c, v) in taps {
                m.col.push(c);
                m.val.push(v);
            }
            m.row_start.push(m.col.len());
        }
    }
    m
}

impl Decimation {
    pub fn new(layout: TextureLayout) -> Self {
        let steps = (0..layout.levels.saturating_sub(1))
            .map(|m| {
                let (w, h) = layout.level_size(m);
                let s = step(w, h);
                let t = s.transpose();
                (s, t)
            })
            .collect();
        Decimation { layout, steps }
    }

    /// Texels of level 0.
    pub fn base_len(&self) -> usize {
        self.layout.width as usize * self.layout.height as usize
    }

    /// D·x₀: the whole chain (n_t values, in the order of [`TextureLayout`]) from level 0.
    pub fn expand(&self, x0: &[f64], out: &mut [f64]) {
        self.expand_lanes::<1>(x0, out);
    }

    /// [`Decimation::expand`] of the L vectors of `x0`, interleaved (`x0[t·L + l]`), into
    /// `out` interleaved alike: each lane bit for bit what `expand` gives it.
    pub fn expand_lanes<const L: usize>(&self, x0: &[f64], out: &mut [f64]) {
        let n0 = self.base_len() * L;
        out[..n0].copy_from_slice(&x0[..n0]);
        let mut at = 0;
        for (m, (s, _)) in self.steps.iter().enumerate() {
            let next = self.layout.level_offset(m as u32 + 1) * L;
            let (src, dst) = out.split_at_mut(next);
            s.mul_lanes::<L>(&src[at..], &mut dst[..s.rows * L]);
            at = next;
        }
    }

    /// Dᵀ·g: a gradient over the whole chain carried back to level 0 (n₀ values).
    pub fn reduce(&self, g: &[f64], out: &mut [f64]) {
        self.reduce_lanes::<1>(g, out);
    }

    /// [`Decimation::reduce`] of the L interleaved vectors of `g`, into `out` interleaved
    /// alike: each lane bit for bit what `reduce` gives it.
    pub fn reduce_lanes<const L: usize>(&self, g: &[f64], out: &mut [f64]) {
        let mut acc: Vec<f64> = match self.steps.last() {
            Some(_) => g[self.layout.level_offset(self.layout.levels - 1) * L..].to_vec(),
            None => g[..self.base_len() * L].to_vec(),
        };
        for m in (0..self.steps.len()).rev() {
            let (_, t) = &self.steps[m];
            let off = self.layout.level_offset(m as u32) * L;
            let mut lower = vec![0.0; t.rows * L];
            t.mul_lanes::<L>(&acc, &mut lower);
            lower.iter_mut().zip(&g[off..off + t.rows * L]).for_each(|(l, v)| *l += v);
            acc = lower;
        }
        out[..acc.len()].copy_from_slice(&acc);
    }

    /// An estimate of diag(Dᵀ·diag(d)·D) (the Jacobi preconditioner in level-0 unknowns):
    /// the squared step weights carried down level by level (exact where no boundary texel
    /// is replicated).
    pub fn reduce_diagonal(&self, d: &[f64]) -> Vec<f64> {
        let mut acc: Vec<f64> = d[self.layout.level_offset(self.layout.levels - 1)..].to_vec();
        for m in (0..self.steps.len()).rev() {
            let (_, t) = &self.steps[m];
            let off = self.layout.level_offset(m as u32);
            let mut lower = vec![0.0; t.rows];
            for (r, l) in lower.iter_mut().enumerate() {
                let (c, v) = t.row(r);
                *l = d[off + r]
                    + c.iter().zip(v).map(|(&c, &v)| v * v * acc[c as usize]).sum::<f64>();
            }
            acc = lower;
        }
        acc
    }
}

/// The whole chain of an interleaved `channels`-valued level 0, decimated exactly as the
/// player does (`pis_format::mip::decimate`, in f32).
pub fn chain_f32(layout: &TextureLayout, level0: &[f32], channels: u32) -> Vec<f32> {
    let mut out = level0.to_vec();
    let mut cur = level0.to_vec();
    for m in 1..layout.levels {
        let (w, h) = layout.level_size(m - 1);
        cur = pis_format::mip::decimate(&cur, w, h, channels);
        out.extend_from_slice(&cur);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lcg(seed: &mut u64) -> f64 {
        *seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((*seed >> 11) as f64 / (1u64 << 53) as f64) - 0.5
    }

    #[test]
    fn expand_is_the_players_decimation_and_reduce_its_transpose() {
        let mut seed = 7;
        for &(w, h) in &[(8, 8), (7, 5), (13, 1), (1, 1)] {
            let layout = TextureLayout::full(w, h);
            let d = Decimation::new(layout);
            let n0 = d.base_len();
            let x0: Vec<f64> = (0..n0).map(|_| lcg(&mut seed)).collect();
            let mut x = vec![0.0; layout.texel_count()];
            d.expand(&x0, &mut x);
            let x32: Vec<f32> = x0.iter().map(|&v| v as f32).collect();
            let want = chain_f32(&layout, &x32, 1);
            assert_eq!(want.len(), x.len());
            assert!(x.iter().zip(&want).all(|(a, b)| (a - *b as f64).abs() < 1e-6), "{w}×{h}");
            // ⟨D x₀, g⟩ = ⟨x₀, Dᵀ g⟩
            let g: Vec<f64> = (0..x.len()).map(|_| lcg(&mut seed)).collect();
            let mut dtg = vec![0.0; n0];
            d.reduce(&g, &mut dtg);
            let lhs: f64 = x.iter().zip(&g).map(|(a, b)| a * b).sum();
            let rhs: f64 = x0.iter().zip(&dtg).map(|(a, b)| a * b).sum();
            assert!((lhs - rhs).abs() < 1e-12 * lhs.abs().max(1.0), "{w}×{h}: {lhs} vs {rhs}");
        }
    }

    #[test]
    fn the_diagonal_estimate_is_exact_on_even_sizes() {
        let layout = TextureLayout::full(8, 4);
        let dec = Decimation::new(layout);
        let n0 = dec.base_len();
        let diag: Vec<f64> = (0..layout.texel_count()).map(|k| 1.0 + k as f64 * 0.1).collect();
        let est = dec.reduce_diagonal(&diag);
        for j in 0..n0 {
            let mut e = vec![0.0; n0];
            e[j] = 1.0;
            let mut col = vec![0.0; layout.texel_count()];
            dec.expand(&e, &mut col);
            let exact: f64 = col.iter().zip(&diag).map(|(c, d)| c * c * d).sum();
            assert!((exact - est[j]).abs() < 1e-12, "texel {j}: {exact} vs {}", est[j]);
        }
    }
}
