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

use rayon::prelude::*;

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
    let mut hess = |p: &[&[f64]], out: &mut [&mut [f64]]| q.hess_mul(p[0], out[0]);
    let mut reports = minimize_lanes(&[q], &mut hess, range, inv_diag, vec![x], settings);
    reports.pop().expect("one lane")
}

/// The products `out_l = H·p_l` of the lanes still running, taken together.
pub type LanesProduct<'a> = dyn FnMut(&[&[f64]], &mut [&mut [f64]]) + 'a;

/// [`minimize`] for several problems that share H (the colour channels of one texture),
/// iterated in lockstep: each iteration takes the products with H of every lane still
/// running in one call of `hess` (e.g. one pass over H's entries). Each lane's arithmetic
/// is that of [`minimize`] on its own problem, so where `hess` gives each lane what
/// [`Quadratic::hess_mul`] would, its result is the same bit for bit.
pub fn minimize_lanes(
    qs: &[&dyn Quadratic],
    hess: &mut LanesProduct<'_>,
    range: Option<&RangeRegularization>,
    inv_diag: &[f64],
    xs: Vec<&mut [f64]>,
    settings: &CgSettings,
) -> Vec<CgReport> {
    let mut lanes: Vec<Lane> =
        qs.iter().zip(xs).map(|(&q, x)| Lane::new(q, range, inv_diag, x)).collect();
    loop {
        for lane in lanes.iter_mut().filter(|l| l.running) {
            lane.check(settings);
        }
        let (d, mut hd): (Vec<&[f64]>, Vec<&mut [f64]>) =
            lanes.iter_mut().filter(|l| l.running).map(|l| (&l.d[..], &mut l.hd[..])).unzip();
        if d.is_empty() {
            break;
        }
        hess(&d, &mut hd);
        lanes.par_iter_mut().filter(|l| l.running).for_each(|l| l.step(range, inv_diag, settings));
    }
    lanes.into_iter().map(|l| l.report).collect()
}

/// One problem's iteration state in [`minimize_lanes`].
struct Lane<'a> {
    q: &'a dyn Quadratic,
    x: &'a mut [f64],
    /// The quadratic part's gradient.
    gq: Vec<f64>,
    /// M⁻¹g, and the scratch its successor is computed in.
    z: Vec<f64>,
    z_next: Vec<f64>,
    gz: f64,
    /// gᵀM⁻¹g at the cold start, the tolerance's reference.
    gz0: f64,
    /// The search direction and H·d.
    d: Vec<f64>,
    hd: Vec<f64>,
    f: f64,
    report: CgReport,
    running: bool,
}

/// The full gradient: the quadratic part's, plus the range term's when there is one.
fn full_gradient<'g>(
    gq: &'g [f64],
    range: Option<&RangeRegularization>,
    x: &[f64],
) -> std::borrow::Cow<'g, [f64]> {
    match range {
        None => std::borrow::Cow::Borrowed(gq),
        Some(r) => {
            let mut g = gq.to_vec();
            r.add_gradient(x, &mut g);
            std::borrow::Cow::Owned(g)
        }
    }
}

impl<'a> Lane<'a> {
    fn new(
        q: &'a dyn Quadratic,
        range: Option<&RangeRegularization>,
        inv_diag: &[f64],
        x: &'a mut [f64],
    ) -> Lane<'a> {
        let n = x.len();
        let mut gq = vec![0.0; n];
        let fq = q.value_gradient(x, &mut gq);
        let f = fq + range.map_or(0.0, |r| r.value(x));
        let report = CgReport { objective: vec![f], ..Default::default() };
        let g = full_gradient(&gq, range, x);
        let z: Vec<f64> = g.iter().zip(inv_diag).map(|(g, m)| g * m).collect();
        let gz = dot(&g, &z);
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
        let d: Vec<f64> = z.iter().map(|v| -v).collect();
        let mut lane = Lane {
            q,
            x,
            gq,
            z,
            z_next: vec![0.0; n],
            gz,
            gz0,
            d,
            hd: vec![0.0; n],
            f,
            report,
            running: true,
        };
        if !(gz > 0.0) || !gz.is_finite() {
            lane.report.converged = gz == 0.0;
            lane.running = false;
        }
        lane
    }

    /// The stopping rules checked before an iteration.
    fn check(&mut self, settings: &CgSettings) {
        if self.report.iterations >= settings.max_iterations {
            self.running = false;
        } else if self.gz <= settings.tolerance * settings.tolerance * self.gz0 {
            self.report.converged = true;
            self.running = false;
        }
    }

    /// The rest of an iteration, once `hd` holds H·d: the line minimum, the step, and the
    /// next direction (Polak–Ribière+). A refused step stops the lane.
    fn step(
        &mut self,
        range: Option<&RangeRegularization>,
        inv_diag: &[f64],
        settings: &CgSettings,
    ) {
        // Each sum below runs over i in order from −0.0, as `dot` does: the loops are fused
        // to pass over the vectors fewer times, with the same arithmetic.
        let (mut curv, mut slope_q) = (-0.0, -0.0);
        for ((d, hd), gq) in self.d.iter().zip(&self.hd).zip(&self.gq) {
            curv += d * hd;
            slope_q += gq * d;
        }
        let accepted =
            line_minimum(slope_q, curv, range, self.x, &self.d).filter(|&(_, delta)| delta < 0.0);
        let Some((alpha, delta)) = accepted else {
            self.running = false;
            return;
        };
        for i in 0..self.x.len() {
            self.x[i] += alpha * self.d[i];
            self.gq[i] += 2.0 * alpha * self.hd[i];
        }
        self.f += delta;
        self.report.iterations += 1;
        self.report.objective.push(self.f);
        if settings.refresh_every > 0
            && self.report.iterations.is_multiple_of(settings.refresh_every)
        {
            self.q.value_gradient(self.x, &mut self.gq);
        }
        let g_new = full_gradient(&self.gq, range, self.x);
        // gᵀ₊z₊ and gᵀ₊z.
        let (mut gz_new, mut gz_old) = (-0.0, -0.0);
        for (((zn, g), m), z) in self.z_next.iter_mut().zip(g_new.iter()).zip(inv_diag).zip(&self.z)
        {
            *zn = g * m;
            gz_new += g * *zn;
            gz_old += g * z;
        }
        // Polak–Ribière+: β = max(0, g₊ᵀ(z₊ − z) / gᵀz).
        let beta = ((gz_new - gz_old) / self.gz).max(0.0);
        let mut dg = -0.0;
        for ((d, z), g) in self.d.iter_mut().zip(&self.z_next).zip(g_new.iter()) {
            *d = -z + beta * *d;
            dg += *d * g;
        }
        if dg >= 0.0 {
            self.d.iter_mut().zip(&self.z_next).for_each(|(d, z)| *d = -z);
        }
        std::mem::swap(&mut self.z, &mut self.z_next);
        self.gz = gz_new;
    }
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
