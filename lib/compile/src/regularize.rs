//! The two regularizing terms of thesis 3.5.3, with analytic gradients.
//!
//! - **Range regularization** (eq. 3.8): a barrier `g(y) = 1 / ((y + δ)(1 + δ − y))` per
//!   texel, δ = 1/512. The thesis's textures are 8-bit values in [0, 1]; ours are float
//!   radiance, so y = x / R with R = 1.1 · max(b) (the range [0, R]) and the calibration
//!   constant gains a factor R², which keeps the term's magnitude equal to f's (f is in
//!   units of b²). The term is optional (ε_b = 0 switches it off, the default): the thesis
//!   found it unnecessary when the pyramidal term is on.
//! - **Pyramidal regularization** (eq. 3.9): Γ(x) = ‖P x‖², P taking the difference between
//!   each texel of MIP level m and the bilinear interpolation of level m + 1 at its centre.
//!   Level m + 1 is placed as `pis_format::mip::decimate` builds it (coarse texel i covers
//!   fine texels 2i and 2i + 1), so a pyramid made by decimation nearly satisfies Γ = 0 and
//!   the decoder's on-the-fly decimation (thesis 3.6) stays close to the solved levels.

use crate::sparse::Csr;
use crate::TextureLayout;

/// δ of eq. 3.8.
pub const RANGE_DELTA: f64 = 1.0 / 512.0;

/// The range term `scale · Σ g(x_i / range)` of eq. 3.8.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RangeRegularization {
    /// R: texels are pushed into [0, R].
    pub range: f64,
    /// ε_b · (n_s / n_t) · R² / (g(0) − g(½)).
    pub scale: f64,
}

/// g(y) of eq. 3.8 (+∞ outside (−δ, 1 + δ)).
pub fn barrier(y: f64) -> f64 {
    let (p, q) = (y + RANGE_DELTA, 1.0 + RANGE_DELTA - y);
    if p <= 0.0 || q <= 0.0 {
        f64::INFINITY
    } else {
        1.0 / (p * q)
    }
}

/// g'(y).
pub fn barrier_d1(y: f64) -> f64 {
    let (p, q) = (y + RANGE_DELTA, 1.0 + RANGE_DELTA - y);
    (p - q) / (p * p * q * q)
}

/// g''(y).
pub fn barrier_d2(y: f64) -> f64 {
    let (p, q) = (y + RANGE_DELTA, 1.0 + RANGE_DELTA - y);
    // g = (pq)⁻¹, p' = 1, q' = −1: g' = (p − q)(pq)⁻², g'' = 2(p² − pq + q²)(pq)⁻³
    2.0 * (p * p - p * q + q * q) / (p * p * p * q * q * q)
}

impl RangeRegularization {
    /// The term for weight ε_b, n_s covered pixels, n_t texels and range R.
    pub fn new(epsilon_b: f64, n_s: usize, n_t: usize, range: f64) -> Self {
        let calib = 1.0 / (barrier(0.0) - barrier(0.5));
        let scale = epsilon_b * (n_s as f64 / n_t.max(1) as f64) * range * range * calib;
        RangeRegularization { range, scale }
    }

    /// The term's value at x.
    pub fn value(&self, x: &[f64]) -> f64 {
        self.scale * x.iter().map(|&v| barrier(v / self.range)).sum::<f64>()
    }

    /// Adds the term's gradient at x to `grad`.
    pub fn add_gradient(&self, x: &[f64], grad: &mut [f64]) {
        let k = self.scale / self.range;
        for (g, &v) in grad.iter_mut().zip(x) {
            *g += k * barrier_d1(v / self.range);
        }
    }

    /// The open interval of steps α for which x + α·p stays inside the barrier's domain.
    pub fn step_limit(&self, x: &[f64], p: &[f64]) -> f64 {
        let (lo, hi) = (-RANGE_DELTA * self.range, (1.0 + RANGE_DELTA) * self.range);
        let mut limit = f64::INFINITY;
        for (&xi, &pi) in x.iter().zip(p) {
            if pi > 0.0 {
                limit = limit.min((hi - xi) / pi);
            } else if pi < 0.0 {
                limit = limit.min((lo - xi) / pi);
            }
        }
        limit
    }

    /// Moves x strictly inside [0, R] (a warm start may lie outside).
    pub fn clamp_inside(&self, x: &mut [f64]) {
        for v in x {
            *v = v.clamp(0.0, self.range);
        }
    }
}

/// The pyramid constraint operator P of eq. 3.9: one row per texel of levels 0..L−2, the
/// texel minus the bilinear interpolation of the next coarser level at its centre; each face
/// of a cube map on its own.
pub fn pyramid_operator(layout: &TextureLayout) -> Csr {
    let n = layout.texel_count();
    let mut p = Csr { rows: 0, cols: n, row_start: vec![0], col: vec![], val: vec![] };
    for (face, m) in (0..layout.faces.max(1))
        .flat_map(|f| (0..layout.levels.saturating_sub(1)).map(move |m| (f, m)))
    {
        let (w, h) = layout.level_size(m);
        let (cw, ch) = layout.level_size(m + 1);
        let taps = |i: u32, cn: u32| -> [(u32, f64); 2] {
            // Fine texel centre i + ½ lies at (i + ½)/2 in coarse texel units; the coarse
            // texel k has its centre at k + ½.
            let u = (i as f64 + 0.5) / 2.0 - 0.5;
            let k0 = u.floor();
            let f = u - k0;
            let clamp = |k: f64| (k.max(0.0) as u32).min(cn - 1);
            [(clamp(k0), 1.0 - f), (clamp(k0 + 1.0), f)]
        };
        for j in 0..h {
            let ty = taps(j, ch);
            for i in 0..w {
                let tx = taps(i, cw);
                let mut entries: Vec<(u32, f64)> =
                    vec![(layout.face_texel(face, m, i, j) as u32, 1.0)];
                for &(y, wy) in &ty {
                    for &(x, wx) in &tx {
                        let wgt = wx * wy;
                        if wgt != 0.0 {
                            entries.push((layout.face_texel(face, m + 1, x, y) as u32, -wgt));
                        }
                    }
                }
                entries.sort_by_key(|e| e.0);
                for (c, v) in entries {
                    if p.col.last() == Some(&c) && p.row_start.last() != Some(&p.col.len()) {
                        *p.val.last_mut().expect("an entry was just pushed") += v;
                    } else {
                        p.col.push(c);
                        p.val.push(v);
                    }
                }
                p.row_start.push(p.col.len());
                p.rows += 1;
            }
        }
    }
    p
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn barrier_derivatives_match_finite_differences() {
        for &y in &[0.0, 0.1, 0.5, 0.93, 1.0] {
            let h = 1e-6;
            let d1 = (barrier(y + h) - barrier(y - h)) / (2.0 * h);
            let d2 = (barrier_d1(y + h) - barrier_d1(y - h)) / (2.0 * h);
            assert!(
                (d1 - barrier_d1(y)).abs() <= 1e-5 * d1.abs().max(1.0),
                "{y}: {d1} vs {}",
                barrier_d1(y)
            );
            assert!(
                (d2 - barrier_d2(y)).abs() <= 1e-4 * d2.abs().max(1.0),
                "{y}: {d2} vs {}",
                barrier_d2(y)
            );
        }
        assert!(barrier(-1.0).is_infinite() && barrier(2.0).is_infinite());
    }

    #[test]
    fn a_constant_pyramid_satisfies_the_constraint() {
        for &(w, h) in &[(8, 8), (5, 3), (7, 1)] {
            let layout = TextureLayout::full(w, h);
            let p = pyramid_operator(&layout);
            let x = vec![0.7; layout.texel_count()];
            let mut y = vec![0.0; p.rows];
            p.mul(&x, &mut y);
            assert!(y.iter().all(|v| v.abs() < 1e-12), "{w}×{h}");
            // every row sums to zero and has at most 5 entries
            for r in 0..p.rows {
                assert!(p.row(r).0.len() <= 5);
            }
        }
    }
}
