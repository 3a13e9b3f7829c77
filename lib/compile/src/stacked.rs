//! A view-independent solve's data term assembled view by view (thesis eq. 3.7 in the AᵀA
//! form of eq. 3.5). AᵀA, Aᵀb, ‖b‖² and the column norms of the stacked A are sums over its
//! rows, so each view's render matrix is read, added and dropped: the solve holds terms the
//! size of the texture whatever the number of views. Every sum runs over the stacked rows in
//! their order, as the stacked matrix's products run, so the terms are the stacked
//! matrix's bit for bit.

use rayon::prelude::*;

use crate::error::check_finite;
use crate::sparse::Csr;
use crate::view::{View, CHANNELS};
use crate::{CompileError, TextureLayout};

/// The views of a view-independent solve, served one at a time and as often as the solve
/// asks (twice: the data term, then the residual). A source that reads them from a scratch
/// file holds one view at a time.
pub trait ViewSource {
    /// How many views.
    fn count(&self) -> usize;
    /// Calls `f` with view `k` (`k < count()`).
    fn visit(
        &self,
        k: usize,
        f: &mut dyn FnMut(View<'_>) -> Result<(), CompileError>,
    ) -> Result<(), CompileError>;
}

impl ViewSource for [View<'_>] {
    fn count(&self) -> usize {
        self.len()
    }

    fn visit(
        &self,
        k: usize,
        f: &mut dyn FnMut(View<'_>) -> Result<(), CompileError>,
    ) -> Result<(), CompileError> {
        f(self[k])
    }
}

/// The stacked data term.
pub(crate) struct Assembled {
    /// AᵀA.
    pub h: Csr,
    /// Per channel, Aᵀb.
    pub atb: Vec<Vec<f64>>,
    /// Per channel, ‖b‖².
    pub bb: Vec<f64>,
    /// The diagonal of AᵀA.
    pub col_norms: Vec<f64>,
    /// Covered pixels over all views.
    pub n_s: usize,
    /// The largest pixel value.
    pub b_max: f32,
}

/// Checks view `k` against `layout` and converts its matrix.
pub(crate) fn view_matrix(
    k: usize,
    v: &View<'_>,
    layout: TextureLayout,
) -> Result<Csr, CompileError> {
    if v.a.layout != layout {
        return Err(CompileError::Setting(format!(
            "view {k}'s texture layout differs from view 0's"
        )));
    }
    if v.b.len() != v.a.rows() * CHANNELS {
        return Err(CompileError::Size {
            what: format!("b of view {k} (covered pixels × 3)"),
            expected: v.a.rows() * CHANNELS,
            found: v.b.len(),
        });
    }
    check_finite("b", v.b)?;
    Csr::from_render_matrix(v.a)
}

/// Adds the views of `source` one at a time; the layout is view 0's.
pub(crate) fn assemble<S: ViewSource + ?Sized>(
    source: &S,
) -> Result<(TextureLayout, Assembled), CompileError> {
    if source.count() == 0 {
        return Err(CompileError::Setting("no views to solve".into()));
    }
    let mut layout = None;
    let mut t = Assembled {
        h: Csr::zeros(0),
        atb: vec![],
        bb: vec![],
        col_norms: vec![],
        n_s: 0,
        b_max: 0.0,
    };
    for k in 0..source.count() {
        source.visit(k, &mut |v| {
            let layout = *layout.get_or_insert_with(|| {
                let n_t = v.a.layout.texel_count();
                // Sums start where the iterator sums of the stacked products start (-0.0).
                t = Assembled {
                    h: Csr::zeros(n_t),
                    atb: vec![vec![-0.0; n_t]; CHANNELS],
                    bb: vec![-0.0; CHANNELS],
                    col_norms: vec![0.0; n_t],
                    n_s: 0,
                    b_max: 0.0,
                };
                v.a.layout
            });
            let a = view_matrix(k, &v, layout)?;
            let at = a.transpose();
            for (&c, &w) in a.col.iter().zip(&a.val) {
                t.col_norms[c as usize] += w * w;
            }
            for ch in 0..CHANNELS {
                t.atb[ch].par_iter_mut().enumerate().with_min_len(256).for_each(|(i, s)| {
                    let (rs, ws) = at.row(i);
                    for (&r, &w) in rs.iter().zip(ws) {
                        *s += w * v.b[r as usize * CHANNELS + ch] as f64;
                    }
                });
                for px in v.b.chunks_exact(CHANNELS) {
                    let x = px[ch] as f64;
                    t.bb[ch] += x * x;
                }
            }
            t.b_max = v.b.iter().fold(t.b_max, |m, &x| m.max(x));
            t.h = t.h.add_gram(&a, &at);
            t.n_s += a.rows;
            Ok(())
        })?;
    }
    let layout = layout.ok_or_else(|| CompileError::Source("view 0 was not served".into()))?;
    Ok((layout, t))
}

/// Per channel, ‖Ax − b‖² over the views of `source`, `x[ch]` the channel's texels.
pub(crate) fn residual2<S: ViewSource + ?Sized>(
    source: &S,
    layout: TextureLayout,
    x: &[&[f64]],
) -> Result<Vec<f64>, CompileError> {
    let mut r2 = vec![-0.0; CHANNELS];
    for k in 0..source.count() {
        source.visit(k, &mut |v| {
            let at = view_matrix(k, &v, layout)?.transpose();
            for (ch, x) in x.iter().enumerate() {
                // Ax through the transpose's columns, as the held solve gathers it.
                let mut ax = vec![0.0; at.cols];
                for (c, &xc) in x.iter().enumerate().take(at.rows) {
                    let (rows, vals) = at.row(c);
                    for (&r, &w) in rows.iter().zip(vals) {
                        ax[r as usize] += w * xc;
                    }
                }
                for (a, px) in ax.iter().zip(v.b.chunks_exact(CHANNELS)) {
                    let d = a - px[ch] as f64;
                    r2[ch] += d * d;
                }
            }
            Ok(())
        })?;
    }
    Ok(r2)
}
