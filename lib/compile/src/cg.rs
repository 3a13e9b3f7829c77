//! Preconditioned nonlinear conjugate gradient (Polak–Ribière+, thesis 3.5) with an exact
//! line search.
//!
//! The objective is a convex quadratic `f_q(x) = xᵀHx − 2cᵀx + const` (the data term of
//! eq. 3.4/3.5 plus the pyramidal term of eq. 3.9) plus, optionally, the separable range
//! barrier of eq. 3.8. Along a search direction p the quadratic part is known in closed
//! form, `f_q(x + αp) = f_q(x) + α ∇f_q·p + α² pᵀHp`, so one product with H per iteration
//! gives the exact line minimum; with the barrier on, the line function stays convex and its
//! minimum is found by safeguarded Newton steps on φ'(α) inside the barrier's domain, at
//! O(n_t) per step. Without the barrier, exact line search makes Polak–Ribière identical to
//! linear (preconditioned) CG on the normal equations, so one routine serves both cases.
//!
//! Every accepted step lowers the objective; a step that would not is refused and the
//! iteration stops, so the recorded objective never increases.

// `!(a < b)` is meant: it is also true when a value is NaN, which must stop the iteration.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use crate::regularize::{barrier, barrier_d1, barrier_d2, RangeRegularization};

/// The quadratic part of the objective.
pub trait Quadratic: Sync {
    /// out = H·p.
    fn hess_mul(&self, p: &[f64], out: &mut [f64]);
    /// f_q(x), and its gradient 2(Hx − c) written to `grad`, computed from scratch.
    fn value_gradient(&self, x: &[f64], grad: &mut [f64]) -> f64;
}

/// Stopping rules.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CgSettings {
    /// Stop after this many iterations.
    pub max_iterations: u32,
    /// Stop when gᵀM⁻¹g has fallen below `tolerance²` times its value at x = 0 (the cold
    /// start), so a warm start from a good guess stops as soon as it is as good.
    pub tolerance: f64,
    /// Recompute the gradient from scratch every this many iterations (limits drift).
    pub refresh_every: u32,
}

impl Default for CgSettings {
    fn default() -> Self {
        CgSettings { max_iterations: 400, tolerance: 1e-4, refresh_every: 50 }
    }
}

/// What a minimization did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CgReport {
    pub iterations: u32,
    /// The objective before the first and after every iteration.
    pub objective: Vec<f64>,
    /// Whether the tolerance was met (else the iteration limit or a refused step ended it).
    pub converged: bool,
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// Minimizes `f_q(x) + range(x)` from the given x, in place. `inv_diag` is the Jacobi
/// preconditioner M⁻¹ (positive).
pub fn minimize(
    q: &dyn Quadratic,
    range: Option<&RangeRegularization>,
    inv_diag: &[f64],
    x: &mut [f64],
    settings: &CgSettings,
) -> CgReport {
    let n = x.len();
    let mut gq = vec![0.0; n];
    let fq = q.value_gradient(x, &mut gq);
    let full_grad = |gq: &[f64], x: &[f64]| {
        let mut g = gq.to_vec();
        if let Some(r) = range {
            r.add_gradient(x, &mut g);
        }
        g
    };
    let mut f = fq + range.map_or(0.0, |r| r.value(x));
    let mut report = CgReport { objective: vec![f], ..Default::default() };
    let g = full_grad(&gq, x);
    let mut z: Vec<f64> = g.iter().zip(inv_diag).map(|(g, m)| g * m).collect();
    let mut gz = dot(&g, &z);
    let gz0 = {
        let mut g0 = vec![0.0; n];
        q.value_gradient(&vec![0.0; n], &mut g0);
        let cold = dot(&g0, &g0.iter().zip(inv_diag).map(|(g, m)| g * m).collect::<Vec<_>>());
        if cold > 0.0 {
            cold
        } else {
            gz
        }
    };
    if !(gz > 0.0) || !gz.is_finite() {
        report.converged = gz == 0.0;
        return report;
    }
    let mut d: Vec<f64> = z.iter().map(|v| -v).collect();
    let mut hd = vec![0.0; n];
    while report.iterations < settings.max_iterations {
        if gz <= settings.tolerance * settings.tolerance * gz0 {
            report.converged = true;
            break;
        }
        q.hess_mul(&d, &mut hd);
        let curv = dot(&d, &hd);
        let slope_q = dot(&gq, &d);
        let Some((alpha, delta)) = line_minimum(slope_q, curv, range, x, &d) else {
            break;
        };
        if !(delta < 0.0) {
            break;
        }
        for i in 0..n {
            x[i] += alpha * d[i];
            gq[i] += 2.0 * alpha * hd[i];
        }
        f += delta;
        report.iterations += 1;
        report.objective.push(f);
        if settings.refresh_every > 0 && report.iterations.is_multiple_of(settings.refresh_every) {
            q.value_gradient(x, &mut gq);
        }
        let g_new = full_grad(&gq, x);
        let z_new: Vec<f64> = g_new.iter().zip(inv_diag).map(|(g, m)| g * m).collect();
        let gz_new = dot(&g_new, &z_new);
        // Polak–Ribière+: β = max(0, g₊ᵀ(z₊ − z) / gᵀz).
        let beta = ((gz_new - dot(&g_new, &z)) / gz).max(0.0);
        for i in 0..n {
            d[i] = -z_new[i] + beta * d[i];
        }
        if dot(&d, &g_new) >= 0.0 {
            d.iter_mut().zip(&z_new).for_each(|(d, z)| *d = -z);
        }
        z = z_new;
        gz = gz_new;
    }
    report
}

/// The step α minimizing the objective along d and the objective's change; `None` when
/// d is not a descent direction.
fn line_minimum(
    slope_q: f64,
    curv: f64,
    range: Option<&RangeRegularization>,
    x: &[f64],
    d: &[f64],
) -> Option<(f64, f64)> {
    let quad = |a: f64| a * slope_q + a * a * curv;
    let Some(r) = range else {
        if !(curv > 0.0) || !(slope_q < 0.0) {
            return None;
        }
        let a = -slope_q / (2.0 * curv);
        return Some((a, quad(a)));
    };
    let inv_r = 1.0 / r.range;
    // φ'(α) and φ''(α) of the full line function.
    let derivs = |a: f64| {
        let (mut d1, mut d2) = (slope_q + 2.0 * a * curv, 2.0 * curv);
        let (mut b1, mut b2) = (0.0, 0.0);
        for (&xi, &di) in x.iter().zip(d) {
            if di != 0.0 {
                let y = (xi + a * di) * inv_r;
                let q = di * inv_r;
                b1 += barrier_d1(y) * q;
                b2 += barrier_d2(y) * q * q;
            }
        }
        d1 += r.scale * b1;
        d2 += r.scale * b2;
        (d1, d2)
    };
    let (s0, _) = derivs(0.0);
    if !(s0 < 0.0) {
        return None;
    }
    let limit = r.step_limit(x, d);
    let (mut lo, mut hi) =
        (0.0, if limit.is_finite() { limit * (1.0 - 1e-9) } else { f64::INFINITY });
    // Start from the quadratic part's minimum, kept inside the bracket.
    let mut a = if curv > 0.0 { (-slope_q / (2.0 * curv)).max(0.0) } else { 1.0 };
    if !hi.is_finite() {
        while derivs(a).0 < 0.0 && a < 1e30 {
            a *= 2.0;
        }
        hi = a;
    }
    a = a.clamp(0.0, hi);
    for _ in 0..60 {
        let (d1, d2) = derivs(a);
        if d1.abs() <= 1e-12 * s0.abs() {
            break;
        }
        if d1 < 0.0 {
            lo = a
        } else {
            hi = a
        }
        let newton = a - d1 / d2;
        a = if d2 > 0.0 && newton > lo && newton < hi { newton } else { 0.5 * (lo + hi) };
        if hi - lo <= 1e-15 * hi {
            break;
        }
    }
    // The objective's change, summed exactly over the texels the step moves.
    let mut db = 0.0;
    for (&xi, &di) in x.iter().zip(d) {
        if di != 0.0 {
            db += barrier((xi + a * di) * inv_r) - barrier(xi * inv_r);
        }
    }
    Some((a, quad(a) + r.scale * db))
}
