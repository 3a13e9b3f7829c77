//! Least squares under the box constraint of thesis eq. 3.4 (`lo ≤ x ≤ hi`), enforced
//! exactly rather than through the range barrier of eq. 3.8: gradient projection and
//! conjugate gradients on the face it finds (Moré and Toraldo's GPCG).
//!
//! The objective is [`Quadratic`]'s `f(x) = xᵀHx − 2cᵀx + const` (gradient `2(Hx − c)`,
//! Hessian 2H). Each outer iteration
//! 1. takes projected-gradient steps `x(t) = P(x − t·M⁻¹g)` with Armijo backtracking from the
//!    unconstrained Cauchy step, which frees and fixes many bounds at once, while they change
//!    the face and lower f by a useful amount;
//! 2. runs preconditioned CG on the variables strictly inside their bounds (the face),
//!    stopping when a CG step would leave the box (it then steps to the first bound hit).
//!
//! Every step lowers f, so the recorded objective never increases (as in [`crate::cg`]).
//! Convergence: the projected gradient (zero where a bound holds and the gradient pushes
//! into it) measured as in `cg`, relative to the cold start's preconditioned gradient.

// `!(a < b)` is meant: it is also true when a value is NaN, which must stop the iteration.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use crate::cg::{CgReport, CgSettings, Quadratic};

/// Projected-gradient steps per outer iteration at most.
const PROJECTION_STEPS: usize = 5;
/// Armijo's sufficient-decrease factor.
const ARMIJO: f64 = 1e-4;
/// Backtracking halvings at most.
const BACKTRACKS: usize = 30;
/// CG on a face stops when its preconditioned residual has fallen by this factor.
const FACE_REDUCTION: f64 = 1e-2;

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// Whether coordinate i is held by a bound that the gradient pushes against.
#[inline]
fn held(x: f64, g: f64, lo: f64, hi: f64) -> bool {
    (x <= lo && g > 0.0) || (x >= hi && g < 0.0)
}

/// Σ M⁻¹·pg² of the projected gradient.
fn projected_measure(x: &[f64], g: &[f64], inv_diag: &[f64], lo: f64, hi: f64) -> f64 {
    x.iter()
        .zip(g)
        .zip(inv_diag)
        .filter(|((&x, &g), _)| !held(x, g, lo, hi))
        .map(|((_, &g), &m)| g * g * m)
        .sum()
}

/// Minimizes the quadratic `q` over the box `[lo, hi]ⁿ` from `x` (projected into the box
/// first), in place. `inv_diag` is the Jacobi preconditioner M⁻¹ (positive).
pub fn minimize_bounded(
    q: &dyn Quadratic,
    lo: f64,
    hi: f64,
    inv_diag: &[f64],
    x: &mut [f64],
    settings: &CgSettings,
) -> CgReport {
    x.iter_mut().for_each(|v| *v = v.clamp(lo, hi));
    let mut s = Gpcg::new(q, lo, hi, inv_diag, x, settings.max_iterations);
    // The convergence reference: the preconditioned gradient at the cold start x = 0.
    let goal = settings.tolerance * settings.tolerance * s.cold_start_measure();
    while s.report.iterations < settings.max_iterations {
        let measure = projected_measure(s.x, &s.g, inv_diag, lo, hi);
        if !(measure > goal) {
            s.report.converged = measure.is_finite();
            break;
        }
        let before = s.report.iterations;
        // 1. Gradient projection.
        if s.project() {
            break; // the iterations are spent
        }
        // 2. CG on the face: the coordinates strictly inside the box.
        if !s.cg_on_face(goal) {
            if s.report.iterations == before {
                break; // nothing free and no projected step lowers f: stalled
            }
            continue;
        }
        s.refresh();
        if s.report.iterations == before {
            break; // no step lowered f: stalled short of the tolerance
        }
    }
    s.report
}

/// [`minimize_bounded`]'s iterate, objective, gradient and work vectors.
struct Gpcg<'a> {
    q: &'a dyn Quadratic,
    lo: f64,
    hi: f64,
    inv_diag: &'a [f64],
    max_iterations: u32,
    x: &'a mut [f64],
    f: f64,
    g: Vec<f64>,
    trial: Vec<f64>,
    g_trial: Vec<f64>,
    d: Vec<f64>,
    hd: Vec<f64>,
    report: CgReport,
}

impl<'a> Gpcg<'a> {
    fn new(
        q: &'a dyn Quadratic,
        lo: f64,
        hi: f64,
        inv_diag: &'a [f64],
        x: &'a mut [f64],
        max_iterations: u32,
    ) -> Self {
        let n = x.len();
        let mut g = vec![0.0; n];
        let f = q.value_gradient(x, &mut g);
        let report = CgReport { objective: vec![f], ..Default::default() };
        let work = vec![0.0; n];
        Gpcg {
            q,
            lo,
            hi,
            inv_diag,
            max_iterations,
            x,
            f,
            g,
            trial: work.clone(),
            g_trial: work.clone(),
            d: work.clone(),
            hd: work,
            report,
        }
    }

    /// Σ M⁻¹·g² at x = 0, or where that is 0 the projected measure at the start.
    fn cold_start_measure(&self) -> f64 {
        let n = self.x.len();
        let mut g0 = vec![0.0; n];
        self.q.value_gradient(&vec![0.0; n], &mut g0);
        let cold: f64 = g0.iter().zip(self.inv_diag).map(|(g, m)| g * g * m).sum();
        if cold > 0.0 {
            cold
        } else {
            projected_measure(self.x, &self.g, self.inv_diag, self.lo, self.hi)
        }
    }

    /// Moves to `trial` (objective `ft`, gradient `g_trial`) and counts the iteration.
    fn accept_trial(&mut self, ft: f64) {
        self.x.copy_from_slice(&self.trial);
        std::mem::swap(&mut self.g, &mut self.g_trial);
        self.f = ft;
        self.report.iterations += 1;
        self.report.objective.push(self.f);
    }

    /// Up to [`PROJECTION_STEPS`] projected-gradient steps with Armijo backtracking; true
    /// when they spent the iterations.
    fn project(&mut self) -> bool {
        let (lo, hi, n) = (self.lo, self.hi, self.x.len());
        for _ in 0..PROJECTION_STEPS {
            for i in 0..n {
                self.d[i] = if held(self.x[i], self.g[i], lo, hi) {
                    0.0
                } else {
                    -self.g[i] * self.inv_diag[i]
                };
            }
            self.q.hess_mul(&self.d, &mut self.hd);
            let (slope, curv) = (dot(&self.g, &self.d), dot(&self.d, &self.hd));
            if !(slope < 0.0) {
                break;
            }
            let t = if curv > 0.0 { -slope / (2.0 * curv) } else { 1.0 };
            let Some(ft) = self.backtrack(t) else { break };
            let x = &*self.x;
            let face_changed = (0..n)
                .any(|i| (x[i] > lo && x[i] < hi) != (self.trial[i] > lo && self.trial[i] < hi));
            let decrease = self.f - ft;
            self.accept_trial(ft);
            if self.report.iterations >= self.max_iterations {
                return true;
            }
            // Moré–Toraldo: leave projection once the face settles or progress is small.
            if !face_changed || decrease <= 0.25 * ARMIJO * self.f.abs().max(1e-300) {
                break;
            }
        }
        false
    }

    /// Armijo backtracking along the projected path P(x + t·d) from step `t`, halving it:
    /// the first trial's objective that decreases enough (the trial left in `trial`).
    fn backtrack(&mut self, mut t: f64) -> Option<f64> {
        let (lo, hi) = (self.lo, self.hi);
        for _ in 0..BACKTRACKS {
            for i in 0..self.x.len() {
                self.trial[i] = (self.x[i] + t * self.d[i]).clamp(lo, hi);
            }
            let ft = self.q.value_gradient(&self.trial, &mut self.g_trial);
            let moved: f64 = (self.g.iter().zip(&self.trial).zip(self.x.iter()))
                .map(|((g, t), x)| g * (t - x))
                .sum();
            if ft.is_finite() && ft <= self.f + ARMIJO * moved && ft < self.f {
                return Some(ft);
            }
            t *= 0.5;
        }
        None
    }

    /// Preconditioned CG on the coordinates strictly inside the box, until a step reaches a
    /// bound or the face's residual has fallen by [`FACE_REDUCTION`]; false when nothing on
    /// the face is left to lower (no step taken).
    fn cg_on_face(&mut self, goal: f64) -> bool {
        let (lo, hi, n) = (self.lo, self.hi, self.x.len());
        let free: Vec<bool> = self.x.iter().map(|&v| v > lo && v < hi).collect();
        let mut r: Vec<f64> =
            self.g.iter().zip(&free).map(|(&g, &f)| if f { -g } else { 0.0 }).collect();
        let mut z: Vec<f64> = r.iter().zip(self.inv_diag).map(|(r, m)| r * m).collect();
        let mut rz = dot(&r, &z);
        if !(rz > 0.0) {
            return false;
        }
        let rz_face = rz;
        self.d.copy_from_slice(&z);
        while self.report.iterations < self.max_iterations {
            self.q.hess_mul(&self.d, &mut self.hd);
            let curv = dot(&self.d, &self.hd);
            if !(curv > 0.0) {
                break;
            }
            // Along d: f(x + αd) = f − α·rᵀd + α²·dᵀHd (r = −g on the face), so
            // α* = rᵀd / (2·dᵀHd).
            let rd = dot(&r, &self.d);
            let alpha_star = rd / (2.0 * curv);
            let alpha_max = self.step_to_bound();
            let hit = alpha_star >= alpha_max;
            let alpha = if hit { alpha_max.max(0.0) } else { alpha_star };
            let change = -alpha * rd + alpha * alpha * curv;
            if !(change < 0.0) {
                break;
            }
            if hit && self.full_step_projected(alpha_star, change) {
                break;
            }
            for i in 0..n {
                self.x[i] = (self.x[i] + alpha * self.d[i]).clamp(lo, hi);
                self.g[i] += 2.0 * alpha * self.hd[i];
            }
            self.f += change;
            self.report.iterations += 1;
            self.report.objective.push(self.f);
            if hit {
                break;
            }
            for i in 0..n {
                r[i] = if free[i] { -self.g[i] } else { 0.0 };
                z[i] = r[i] * self.inv_diag[i];
            }
            let rz_new = dot(&r, &z);
            if rz_new <= FACE_REDUCTION * FACE_REDUCTION * rz_face || rz_new <= goal {
                break;
            }
            let beta = rz_new / rz;
            for (d, z) in self.d.iter_mut().zip(&z) {
                *d = z + beta * *d;
            }
            rz = rz_new;
        }
        true
    }

    /// The largest α with x + α·d inside the box.
    fn step_to_bound(&self) -> f64 {
        let mut alpha_max = f64::INFINITY;
        for (x, d) in self.x.iter().zip(&self.d) {
            if *d > 0.0 {
                alpha_max = alpha_max.min((self.hi - x) / d);
            } else if *d < 0.0 {
                alpha_max = alpha_max.min((self.lo - x) / d);
            }
        }
        alpha_max
    }

    /// The projected full step P(x + α*·d) fixes every bound it crosses at once; taken (and
    /// true returned) when it lowers f below the step to the first bound, f + `change`.
    fn full_step_projected(&mut self, alpha_star: f64, change: f64) -> bool {
        for i in 0..self.x.len() {
            self.trial[i] = (self.x[i] + alpha_star * self.d[i]).clamp(self.lo, self.hi);
        }
        let ft = self.q.value_gradient(&self.trial, &mut self.g_trial);
        if ft.is_finite() && ft < self.f + change {
            self.accept_trial(ft);
            return true;
        }
        false
    }

    /// The running gradient drifts; each outer iteration starts from an exact one.
    fn refresh(&mut self) {
        let fresh = self.q.value_gradient(self.x, &mut self.g);
        if fresh.is_finite() && fresh <= self.f * (1.0 + 1e-12) + 1e-300 {
            self.f = fresh;
            if let Some(last) = self.report.objective.last_mut() {
                *last = last.min(self.f);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// f(x) = ‖Ax − b‖² for a dense A.
    struct Dense {
        a: Vec<Vec<f64>>,
        b: Vec<f64>,
    }

    impl Quadratic for Dense {
        fn hess_mul(&self, p: &[f64], out: &mut [f64]) {
            let ap: Vec<f64> = self.a.iter().map(|row| dot(row, p)).collect();
            for (j, o) in out.iter_mut().enumerate() {
                *o = self.a.iter().zip(&ap).map(|(row, v)| row[j] * v).sum();
            }
        }
        fn value_gradient(&self, x: &[f64], grad: &mut [f64]) -> f64 {
            let r: Vec<f64> = self.a.iter().zip(&self.b).map(|(row, b)| dot(row, x) - b).collect();
            for (j, g) in grad.iter_mut().enumerate() {
                *g = 2.0 * self.a.iter().zip(&r).map(|(row, v)| row[j] * v).sum::<f64>();
            }
            dot(&r, &r)
        }
    }

    fn lcg(seed: &mut u64) -> f64 {
        *seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((*seed >> 11) as f64) / (1u64 << 53) as f64
    }

    /// Karush–Kuhn–Tucker conditions: inside the box the gradient vanishes, at a bound it
    /// pushes outwards.
    fn kkt_violation(q: &Dense, x: &[f64], lo: f64, hi: f64) -> f64 {
        let mut g = vec![0.0; x.len()];
        q.value_gradient(x, &mut g);
        x.iter()
            .zip(&g)
            .map(|(&x, &g)| if held(x, g, lo, hi) { 0.0 } else { g.abs() })
            .fold(0.0, f64::max)
    }

    #[test]
    fn identity_problem_is_the_clipped_target() {
        let n = 6;
        let a: Vec<Vec<f64>> =
            (0..n).map(|i| (0..n).map(|j| if i == j { 1.0 } else { 0.0 }).collect()).collect();
        let b = vec![-2.0, 0.3, 1.7, 0.9, 5.0, 0.0];
        let q = Dense { a, b: b.clone() };
        let mut x = vec![0.5; n];
        let r = minimize_bounded(
            &q,
            0.0,
            1.0,
            &vec![1.0; n],
            &mut x,
            &CgSettings { max_iterations: 100, tolerance: 1e-10, refresh_every: 0 },
        );
        assert!(r.converged);
        for (x, b) in x.iter().zip(&b) {
            assert!((x - b.clamp(0.0, 1.0)).abs() < 1e-9, "{x} vs {b}");
        }
    }

    #[test]
    fn underdetermined_fit_stays_in_the_box_and_meets_kkt() {
        // More unknowns than equations with a target beyond the box: the unconstrained
        // minimizer is far outside, the bounded one must stop at the box's optimum.
        let mut seed = 7;
        let (rows, cols) = (12, 30);
        let a: Vec<Vec<f64>> = (0..rows)
            .map(|_| {
                (0..cols).map(|_| if lcg(&mut seed) < 0.3 { lcg(&mut seed) } else { 0.0 }).collect()
            })
            .collect();
        let b: Vec<f64> = (0..rows).map(|_| 3.0 * lcg(&mut seed) - 1.0).collect();
        let q = Dense { a, b };
        let mut x = vec![0.0; cols];
        let s = CgSettings { max_iterations: 5000, tolerance: 1e-9, refresh_every: 0 };
        let r = minimize_bounded(&q, 0.0, 1.0, &vec![1.0; cols], &mut x, &s);
        assert!(x.iter().all(|&v| (0.0..=1.0).contains(&v)));
        assert!(
            r.objective.windows(2).all(|w| w[1] <= w[0] + 1e-12 * w[0].abs()),
            "objective rose: {:?}",
            r.objective
        );
        let v = kkt_violation(&q, &x, 0.0, 1.0);
        assert!(r.converged && v < 1e-5, "converged {}, KKT violation {v}", r.converged);
    }

    #[test]
    fn unconstrained_optimum_inside_the_box_is_found() {
        let mut seed = 3;
        let n = 10;
        let a: Vec<Vec<f64>> =
            (0..2 * n).map(|_| (0..n).map(|_| lcg(&mut seed) - 0.5).collect()).collect();
        let x_true: Vec<f64> = (0..n).map(|_| 0.2 + 0.6 * lcg(&mut seed)).collect();
        let b: Vec<f64> = a.iter().map(|row| dot(row, &x_true)).collect();
        let q = Dense { a, b };
        let mut x = vec![0.0; n];
        let r = minimize_bounded(
            &q,
            0.0,
            1.0,
            &vec![1.0; n],
            &mut x,
            &CgSettings { max_iterations: 1000, tolerance: 1e-10, refresh_every: 0 },
        );
        assert!(r.converged);
        for (x, t) in x.iter().zip(&x_true) {
            assert!((x - t).abs() < 1e-6, "{x} vs {t}");
        }
    }
}
