//! Least-squares texture inference (thesis 3.5): the texture x minimizing
//! `‖Ax − b‖² + range term (eq. 3.8) + pyramidal term (eq. 3.9)` per colour channel, the
//! three channels sharing A.
//!
//! The vectors are f64 inside the solver (sums over ~10⁵ texels), the texture f32 outside.

use std::time::Instant;

use rayon::prelude::*;

use crate::bounded::minimize_bounded;
use crate::cg::{self, CgReport, CgSettings, Quadratic};
use crate::decimation::{chain_f32, Decimation};
use crate::error::check_finite;
use crate::normal_equations::{
    ChannelProblem, ChannelRhs, DataOperator, Form, PyramidTerm, DEFAULT_K,
};
use crate::regularize::{barrier_d2, pyramid_operator, RangeRegularization};
use crate::sparse::Csr;
use crate::stacked::{assemble, residual2 as residual2_of, view_matrix, ViewSource};
pub use crate::view::{View, CHANNELS};
use crate::{CompileError, RenderMatrix, TextureLayout};

/// Which form of the normal equations to iterate on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum FormChoice {
    /// The rule of thesis 3.5 with K = [`SolveSettings::k`].
    #[default]
    Auto,
    /// Always this form.
    Fixed(Form),
}

/// What the solver's unknowns are.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum MipSolve {
    /// Every texel of every MIP level (thesis 3.5: n_t counts the whole pyramid).
    #[default]
    Free,
    /// Level 0 only; the coarser levels are its decimations as the player rebuilds them
    /// (thesis 3.6), so A acts through D ([`crate::decimation`]). The solved texture is then
    /// exactly the one drawn, and a box-bounded level 0 bounds every level.
    Decimated,
}

/// Solver settings; [`SolveSettings::default`] is plain least squares,
/// [`SolveSettings::pyramidal`] the thesis's regularized setting,
/// [`SolveSettings::decimated`] the same for the player's decimated MIP chain.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolveSettings {
    /// ε_b of eq. 3.8 (0: no range term). The thesis used 1/32.
    pub epsilon_b: f64,
    /// ε_f of eq. 3.9 (0: no pyramidal term). The thesis used 0.1.
    pub epsilon_f: f64,
    /// The range [0, range_factor · max(b)] the range term keeps texels in, and the box of
    /// `bounded`.
    pub range_factor: f64,
    /// Enforce eq. 3.4's constraint exactly: every unknown in [0, range_factor · max(b)]
    /// ([`crate::bounded`]: gradient projection and CG on the free face), instead of (not
    /// together with) the range barrier of eq. 3.8.
    pub bounded: bool,
    pub form: FormChoice,
    pub mip: MipSolve,
    /// K of the form rule.
    pub k: f64,
    pub cg: CgSettings,
}

impl Default for SolveSettings {
    fn default() -> Self {
        SolveSettings {
            epsilon_b: 0.0,
            epsilon_f: 0.0,
            range_factor: 1.1,
            bounded: false,
            form: FormChoice::Auto,
            mip: MipSolve::Free,
            k: DEFAULT_K,
            cg: CgSettings::default(),
        }
    }
}

impl SolveSettings {
    /// Pyramidal regularization with ε_f = 0.1 (thesis 3.6): every texel defined.
    pub fn pyramidal() -> Self {
        SolveSettings { epsilon_f: 0.1, ..Default::default() }
    }

    /// Pyramidal regularization (ε_f = 0.1) in the decimated parameterization: level 0
    /// solved through the MIP chain the player decimates from it.
    pub fn decimated() -> Self {
        SolveSettings { mip: MipSolve::Decimated, ..Self::pyramidal() }
    }

    /// Plain least squares under eq. 3.4's box constraint 0 ≤ x ≤ 1.1 · max(b).
    pub fn bounded() -> Self {
        SolveSettings { bounded: true, ..Default::default() }
    }

    /// Range regularization with ε_b = 1/32 (thesis 3.6).
    pub fn range() -> Self {
        SolveSettings { epsilon_b: 1.0 / 32.0, ..Default::default() }
    }
}

/// A solved texture and how the solve went.
#[derive(Clone, Debug, PartialEq)]
pub struct Solution {
    pub layout: TextureLayout,
    /// n_t texels × [`CHANNELS`], in the order of [`TextureLayout`].
    pub texels: Vec<f32>,
    pub form: Form,
    /// Covered pixels (all views together for a view-independent solve).
    pub n_s: usize,
    pub n_t: usize,
    /// CG iterations over the three channels together.
    pub iterations: u32,
    /// Per channel: iterations, objective history, convergence.
    pub channels: Vec<CgReport>,
    /// √(‖Ax − b‖² / (n_s · channels)): the data term's residual per pixel value.
    pub residual_rms: f64,
    /// ‖Ax − b‖ / ‖b‖.
    pub residual_relative: f64,
    /// Texels no pixel sees and no regularization reaches; they keep the initial value.
    pub undefined: usize,
    pub converged: bool,
    pub solve_ms: f64,
}

/// Solves for one object's texture at one parameter point. `initial` (n_t × 3) is a warm
/// start, typically the solution at a neighbouring parameter sample of the same block
/// (same texture layout); without one the solve starts from zero.
pub fn solve(
    a: &RenderMatrix,
    b: &[f32],
    initial: Option<&[f32]>,
    settings: &SolveSettings,
) -> Result<Solution, CompileError> {
    solve_views(&[View { a, b }], initial, settings, false)
}

/// Solves one view-independent (diffuse) texture over all views at once (thesis eq. 3.7):
/// the views' A matrices stacked, in the AᵀA form.
pub fn solve_view_independent(
    views: &[View<'_>],
    initial: Option<&[f32]>,
    settings: &SolveSettings,
) -> Result<Solution, CompileError> {
    solve_view_source(views, initial, settings)
}

/// [`solve_view_independent`] with the views served one at a time by `source`: in the AᵀA
/// form (the rule's choice for stacked views) the data term is assembled view by view and
/// the solve holds one view's render matrix at a time, with the same result bit for bit
/// ([`crate::stacked`]). The A form multiplies by the stacked A, so it holds every view.
pub fn solve_view_source<S: ViewSource + ?Sized>(
    source: &S,
    initial: Option<&[f32]>,
    settings: &SolveSettings,
) -> Result<Solution, CompileError> {
    let start = Instant::now();
    check_settings(settings)?;
    if settings.form == FormChoice::Fixed(Form::A) {
        let mut held = Vec::with_capacity(source.count());
        for k in 0..source.count() {
            source.visit(k, &mut |v| {
                held.push((v.a.clone(), v.b.to_vec()));
                Ok(())
            })?;
        }
        let views: Vec<View> = held.iter().map(|(a, b)| View { a, b }).collect();
        return solve_views(&views, initial, settings, true);
    }
    let (layout, t) = assemble(source)?;
    check_layout(layout, settings, initial)?;
    let data = DataTerm {
        layout,
        op: DataOperator::Gram { h: t.h },
        form: Form::Normal,
        col_norms: t.col_norms,
        n_s: t.n_s,
        b_max: t.b_max as f64,
        rhs: t
            .atb
            .into_iter()
            .zip(t.bb)
            .map(|(atb, bb)| ChannelRhs { b: vec![], atb, bb })
            .collect(),
        pixels: Pixels::Read(&|xs: &[&[f64]]| residual2_of(source, layout, xs)),
    };
    finish(data, initial, settings, start)
}

/// Where the residual ‖Ax − b‖² finds the pixels b.
enum Pixels<'a> {
    /// Per channel, held with the operator.
    Held(Vec<Vec<f64>>),
    /// Read again from the views: per channel, the residual of the channels' texels.
    Read(&'a Residual2<'a>),
}

/// Per channel, ‖Ax − b‖² of the channels' texels x.
type Residual2<'a> = dyn Fn(&[&[f64]]) -> Result<Vec<f64>, CompileError> + 'a;

/// A solve's data term: the operator, its right-hand side per channel, and what the
/// preconditioner and the regularization read of it.
struct DataTerm<'a> {
    layout: TextureLayout,
    op: DataOperator,
    form: Form,
    col_norms: Vec<f64>,
    n_s: usize,
    b_max: f64,
    rhs: Vec<ChannelRhs>,
    pixels: Pixels<'a>,
}

/// The settings the layout allows, and the warm start's size and values.
fn check_layout(
    layout: TextureLayout,
    settings: &SolveSettings,
    initial: Option<&[f32]>,
) -> Result<(), CompileError> {
    if settings.mip == MipSolve::Decimated && layout.faces > 1 {
        return Err(CompileError::Setting(
            "a cube map's levels are solved together (mip solve `free`), not decimated".into(),
        ));
    }
    if let Some(x0) = initial {
        let n_t = layout.texel_count();
        if x0.len() != n_t * CHANNELS {
            return Err(CompileError::Size {
                what: "initial guess (texels × 3)".into(),
                expected: n_t * CHANNELS,
                found: x0.len(),
            });
        }
        check_finite("initial guess", x0)?;
    }
    Ok(())
}

/// The views held: one, or several stacked (eq. 3.7), in the form the settings choose.
pub(crate) fn solve_views(
    views: &[View<'_>],
    initial: Option<&[f32]>,
    settings: &SolveSettings,
    stacked: bool,
) -> Result<Solution, CompileError> {
    let start = Instant::now();
    let first = views.first().ok_or_else(|| CompileError::Setting("no views to solve".into()))?;
    let layout = first.a.layout;
    check_settings(settings)?;
    check_layout(layout, settings, initial)?;
    let mut parts = views
        .iter()
        .enumerate()
        .map(|(k, v)| view_matrix(k, v, layout))
        .collect::<Result<Vec<_>, _>>()?;
    let n_t = layout.texel_count();
    // The views' parts are dropped once stacked.
    let a = if parts.len() == 1 {
        parts.pop().expect("one part")
    } else {
        Csr::stack(&std::mem::take(&mut parts))?
    };
    let n_s = a.rows;
    let form = match settings.form {
        FormChoice::Fixed(f) => f,
        FormChoice::Auto if stacked => Form::Normal,
        FormChoice::Auto => Form::choose(n_s, n_t, settings.k),
    };
    let col_norms = a.column_norms_squared();
    let op = DataOperator::new(a, form);
    let b_max = views.iter().flat_map(|v| v.b.iter()).fold(0.0f32, |m, &v| m.max(v)) as f64;
    let b: Vec<Vec<f64>> = (0..CHANNELS)
        .map(|ch| {
            views
                .iter()
                .flat_map(|v| v.b.iter().skip(ch).step_by(CHANNELS))
                .map(|&v| v as f64)
                .collect()
        })
        .collect();
    let rhs = b.iter().map(|b| op.rhs(b.clone())).collect();
    let data = DataTerm { layout, op, form, col_norms, n_s, b_max, rhs, pixels: Pixels::Held(b) };
    finish(data, initial, settings, start)
}

/// Solves the three channels of `data`, and measures the residual where its pixels are.
fn finish(
    data: DataTerm<'_>,
    initial: Option<&[f32]>,
    settings: &SolveSettings,
    start: Instant,
) -> Result<Solution, CompileError> {
    let DataTerm { layout, op, form, col_norms, n_s, b_max, rhs, pixels } = data;
    let n_t = layout.texel_count();
    let chain = (settings.mip == MipSolve::Decimated).then(|| Decimation::new(layout));
    // Unknowns per channel: the whole chain, or level 0.
    let n_x = chain.as_ref().map_or(n_t, Decimation::base_len);
    let ratio = n_s as f64 / n_t.max(1) as f64;
    let pyramid = (settings.epsilon_f > 0.0 && layout.levels > 1).then(|| {
        let p = pyramid_operator(&layout);
        let pt = p.transpose();
        PyramidTerm { lambda: settings.epsilon_f * ratio, p, pt }
    });
    let range = (settings.epsilon_b > 0.0).then(|| {
        RangeRegularization::new(
            settings.epsilon_b,
            n_s,
            n_x,
            (settings.range_factor * b_max).max(1e-6),
        )
    });

    // Jacobi preconditioner: the diagonal of AᵀA + λPᵀP + the barrier's curvature at ½.
    let mut diag = col_norms.clone();
    if let Some(pt) = &pyramid {
        for (d, n) in diag.iter_mut().zip(pt.p.column_norms_squared()) {
            *d += pt.lambda * n;
        }
    }
    if let Some(r) = &range {
        let c = r.scale * barrier_d2(0.5) / (r.range * r.range) * 0.5;
        diag.iter_mut().for_each(|d| *d += c);
    }
    if let Some(d) = &chain {
        diag = d.reduce_diagonal(&diag);
    }
    let positive: Vec<f64> = diag.iter().copied().filter(|&d| d > 0.0).collect();
    let floor = if positive.is_empty() {
        1.0
    } else {
        positive.iter().sum::<f64>() / positive.len() as f64
    };
    let inv_diag: Vec<f64> = diag.iter().map(|&d| 1.0 / if d > 0.0 { d } else { floor }).collect();
    let undefined = match (&pyramid, &chain) {
        (Some(_), _) => 0,
        (None, None) => col_norms.iter().filter(|&&d| d == 0.0).count(),
        (None, Some(d)) => d.reduce_diagonal(&col_norms).iter().filter(|&&v| v == 0.0).count(),
    };

    let mut texels = vec![0.0f32; n_t * CHANNELS];
    let mut channels = Vec::with_capacity(CHANNELS);
    let mut residual2 = 0.0;
    let mut bb_total = 0.0;
    let mut xs: Vec<Vec<f64>> = (0..CHANNELS)
        .map(|ch| {
            let mut x: Vec<f64> = match initial {
                Some(x0) => {
                    x0.iter().skip(ch).step_by(CHANNELS).take(n_x).map(|&v| v as f64).collect()
                }
                None => vec![0.0; n_x],
            };
            if let Some(r) = &range {
                r.clamp_inside(&mut x);
            }
            x
        })
        .collect();
    let problems: Vec<ChannelProblem> = rhs
        .iter()
        .map(|rhs| ChannelProblem {
            op: &op,
            rhs,
            pyramid: pyramid.as_ref(),
            chain: chain.as_ref(),
        })
        .collect();
    // The channels are problems sharing A: iterated in lockstep, each pass over A serving
    // every channel still running (each channel's arithmetic is its own, so the outcome is
    // that of three separate solves). The box-bounded solver takes them one by one,
    // concurrently.
    let reports: Vec<CgReport> = if settings.bounded {
        let hi = (settings.range_factor * b_max).max(1e-6);
        problems
            .par_iter()
            .zip(xs.par_iter_mut())
            .map(|(p, x)| minimize_bounded(p, 0.0, hi, &inv_diag, x, &settings.cg))
            .collect()
    } else {
        let qs: Vec<&dyn Quadratic> = problems.iter().map(|p| p as &dyn Quadratic).collect();
        let lanes = xs.iter_mut().map(|x| x.as_mut_slice()).collect();
        let mut product = problems[0].lanes();
        let mut hess = |p: &[&[f64]], out: &mut [&mut [f64]]| product.mul(p, out);
        cg::minimize_lanes(&qs, &mut hess, range.as_ref(), &inv_diag, lanes, &settings.cg)
    };
    let results: Vec<(CgReport, Vec<f64>, f64)> = reports
        .into_iter()
        .zip(xs)
        .zip(&rhs)
        .map(|((report, x), rhs)| match &chain {
            Some(d) => {
                let mut full = vec![0.0; n_t];
                d.expand(&x, &mut full);
                (report, full, rhs.bb)
            }
            None => (report, x, rhs.bb),
        })
        .collect();
    let xs: Vec<&[f64]> = results.iter().map(|r| r.1.as_slice()).collect();
    let r2: Vec<f64> = match &pixels {
        Pixels::Held(b) => xs.par_iter().zip(b).map(|(x, b)| data_residual2(&op, x, b)).collect(),
        Pixels::Read(read) => read(&xs)?,
    };
    drop(op);
    for (ch, ((report, x, bb), r2)) in results.into_iter().zip(r2).enumerate() {
        residual2 += r2;
        bb_total += bb;
        for (t, &v) in x.iter().enumerate() {
            texels[t * CHANNELS + ch] = v as f32;
        }
        channels.push(report);
    }
    if chain.is_some() {
        // The coarser levels exactly as the player decimates the stored level 0.
        let n0 = layout.width as usize * layout.height as usize * CHANNELS;
        texels = chain_f32(&layout, &texels[..n0], CHANNELS as u32);
    }
    Ok(Solution {
        layout,
        texels,
        form,
        n_s,
        n_t,
        iterations: channels.iter().map(|c| c.iterations).sum(),
        converged: channels.iter().all(|c| c.converged),
        channels,
        residual_rms: (residual2 / (n_s.max(1) * CHANNELS) as f64).sqrt(),
        residual_relative: if bb_total > 0.0 {
            (residual2 / bb_total).sqrt()
        } else {
            residual2.sqrt()
        },
        undefined,
        solve_ms: start.elapsed().as_secs_f64() * 1e3,
    })
}

/// ‖Ax − b‖², from scratch.
fn data_residual2(op: &DataOperator, x: &[f64], b: &[f64]) -> f64 {
    let at = match op {
        DataOperator::A { at, .. } | DataOperator::Normal { at, .. } => at,
        DataOperator::Gram { .. } => {
            unreachable!("a Gram operator's residual reads the views again")
        }
    };
    // Ax through the transpose's columns: (Ax)_r = Σ_c A_rc x_c, gathered row by row.
    let mut ax = vec![0.0; b.len()];
    for (c, &xc) in x.iter().enumerate().take(at.rows) {
        let (rows, vals) = at.row(c);
        for (&r, &v) in rows.iter().zip(vals) {
            ax[r as usize] += v * xc;
        }
    }
    ax.iter().zip(b).map(|(a, b)| (a - b) * (a - b)).sum()
}

fn check_settings(s: &SolveSettings) -> Result<(), CompileError> {
    let ok = |v: f64| v.is_finite() && v >= 0.0;
    if !ok(s.epsilon_b) || !ok(s.epsilon_f) {
        return Err(CompileError::Setting(format!(
            "ε_b = {} and ε_f = {} must be finite and ≥ 0",
            s.epsilon_b, s.epsilon_f
        )));
    }
    if s.bounded && s.epsilon_b > 0.0 {
        return Err(CompileError::Setting(
            "the box constraint and the range term (ε_b) are alternatives: set one".into(),
        ));
    }
    if !(s.range_factor.is_finite() && s.range_factor > 0.0 && s.k.is_finite() && s.k > 0.0) {
        return Err(CompileError::Setting("range factor and K must be finite and > 0".into()));
    }
    Ok(())
}

/// Renders a texture through A: the n_s × 3 pixel values A·x (for PSNR against b).
/// `texels` holds n_t × 3 values in the order of [`TextureLayout`] (a shorter slice panics).
pub fn render(a: &RenderMatrix, texels: &[f32]) -> Vec<f32> {
    let mut out = vec![0.0f32; a.rows() * CHANNELS];
    for r in 0..a.rows() {
        let (c, v) = a.row(r);
        for (&c, &v) in c.iter().zip(v) {
            for ch in 0..CHANNELS {
                out[r * CHANNELS + ch] += v * texels[c as usize * CHANNELS + ch];
            }
        }
    }
    out
}
