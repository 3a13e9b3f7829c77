//! The two forms of the least-squares data term (thesis 3.5): the A form (eq. 3.4), which
//! multiplies by A and Aᵀ every iteration, and the AᵀA form (eq. 3.5), which assembles the
//! sparse n_t × n_t matrix AᵀA once and multiplies by it alone. The rule of thesis 3.5
//! picks between them: AᵀA when `2·n_s ≥ K·n_t` (K = 4, the relative density of AᵀA).

use rayon::prelude::*;

use crate::cg::Quadratic;
use crate::decimation::Decimation;
use crate::sparse::Csr;

/// Which form of the normal equations the solver iterates on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Form {
    /// Products with A and Aᵀ (eq. 3.4); cost ∝ n_s.
    A,
    /// Products with the assembled AᵀA (eq. 3.5); cost ∝ n_t.
    Normal,
}

/// K of thesis 3.5: how much denser AᵀA's rows are than A's.
pub const DEFAULT_K: f64 = 4.0;

impl Form {
    /// The rule of thesis 3.5: the AᵀA form when `2·n_s ≥ K·n_t`.
    pub fn choose(n_s: usize, n_t: usize, k: f64) -> Form {
        if 2.0 * n_s as f64 >= k * n_t as f64 {
            Form::Normal
        } else {
            Form::A
        }
    }
}

/// The data operator shared by the three colour channels.
pub enum DataOperator {
    A {
        a: Csr,
        at: Csr,
    },
    Normal {
        h: Csr,
        at: Csr,
    },
    /// AᵀA alone, assembled view by view with its right-hand sides
    /// ([`crate::stacked`]): A itself is never held.
    Gram {
        h: Csr,
    },
}

impl DataOperator {
    /// Builds the operator for `a` in the given form.
    pub fn new(a: Csr, form: Form) -> DataOperator {
        let at = a.transpose();
        match form {
            Form::A => DataOperator::A { a, at },
            Form::Normal => {
                let h = a.gram(&at);
                DataOperator::Normal { h, at }
            }
        }
    }

    /// The right-hand side of one channel: Aᵀb (AᵀA form) or b itself, plus ‖b‖².
    pub fn rhs(&self, b: Vec<f64>) -> ChannelRhs {
        let bb = b.iter().map(|v| v * v).sum();
        match self {
            DataOperator::A { .. } => ChannelRhs { b, atb: vec![], bb },
            DataOperator::Normal { at, .. } => {
                let mut atb = vec![0.0; at.rows];
                at.mul(&b, &mut atb);
                ChannelRhs { b: vec![], atb, bb }
            }
            DataOperator::Gram { .. } => {
                unreachable!("a Gram operator's right-hand sides are assembled with it")
            }
        }
    }

    /// n_t.
    pub fn cols(&self) -> usize {
        match self {
            DataOperator::A { at, .. } | DataOperator::Normal { at, .. } => at.rows,
            DataOperator::Gram { h } => h.rows,
        }
    }
}

/// One channel's data: b (A form) or Aᵀb (AᵀA form), and ‖b‖².
pub struct ChannelRhs {
    pub b: Vec<f64>,
    pub atb: Vec<f64>,
    pub bb: f64,
}

/// The pyramidal term λ‖Px‖² (eq. 3.9) with λ = ε_f·n_s/n_t.
pub struct PyramidTerm {
    pub lambda: f64,
    pub p: Csr,
    pub pt: Csr,
}

/// One channel's quadratic objective `‖Ax − b‖² + λ‖Px‖²`; with `chain`, of the level-0
/// texels x₀ with `x = D·x₀` (the decimated parameterization: `‖ADx₀ − b‖² + λ‖PDx₀‖²`).
pub struct ChannelProblem<'a> {
    pub op: &'a DataOperator,
    pub rhs: &'a ChannelRhs,
    pub pyramid: Option<&'a PyramidTerm>,
    pub chain: Option<&'a Decimation>,
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

impl Quadratic for ChannelProblem<'_> {
    fn hess_mul(&self, p: &[f64], out: &mut [f64]) {
        self.lanes().mul(&[p], &mut [out]);
    }

    fn value_gradient(&self, x: &[f64], grad: &mut [f64]) -> f64 {
        match self.chain {
            None => self.value_gradient_chain(x, grad),
            Some(d) => {
                let n_t = d.layout.texel_count();
                let (mut xf, mut gf) = (vec![0.0; n_t], vec![0.0; n_t]);
                d.expand(x, &mut xf);
                let f = self.value_gradient_chain(&xf, &mut gf);
                d.reduce(&gf, grad);
                f
            }
        }
    }
}

impl<'a> ChannelProblem<'a> {
    /// The product with H for the channels of this problem's texture, which share it.
    pub fn lanes(&self) -> LaneProduct<'a> {
        LaneProduct {
            op: self.op,
            pyramid: self.pyramid,
            chain: self.chain,
            scratch: Default::default(),
        }
    }
}

/// H·p for several vectors at once (the channels of one texture): A, P and D are read once
/// for all of them, the vectors interleaved, and each lane's product is bit for bit the
/// one [`ChannelProblem::hess_mul`] gives it alone. The work vectors are kept from one
/// product to the next.
pub struct LaneProduct<'a> {
    op: &'a DataOperator,
    pyramid: Option<&'a PyramidTerm>,
    chain: Option<&'a Decimation>,
    /// The lanes' p and H·p at level 0 and over the whole chain, and the intermediate
    /// products, interleaved.
    scratch: [Vec<f64>; 6],
}

impl LaneProduct<'_> {
    /// out_l = H·p_l for every lane (at most [`crate::view::CHANNELS`]).
    pub fn mul(&mut self, p: &[&[f64]], out: &mut [&mut [f64]]) {
        match p.len() {
            0 => {}
            1 => self.mul_lanes::<1>(p, out),
            2 => self.mul_lanes::<2>(p, out),
            3 => self.mul_lanes::<3>(p, out),
            n => unreachable!("{n} lanes: at most {} (colour channels)", crate::view::CHANNELS),
        }
    }

    fn mul_lanes<const L: usize>(&mut self, p: &[&[f64]], out: &mut [&mut [f64]]) {
        let n_x = p[0].len();
        let n_t = self.chain.map_or(n_x, |d| d.layout.texel_count());
        let [p0, h0, pf, hf, t, u] = &mut self.scratch;
        let sized = |v: &mut Vec<f64>, n: usize| v.resize(n, 0.0);
        sized(p0, n_x * L);
        p0.par_chunks_mut(L).enumerate().for_each(|(i, v)| {
            for (l, p) in p.iter().enumerate() {
                v[l] = p[i];
            }
        });
        match self.chain {
            None => {
                sized(h0, n_x * L);
                chain_product::<L>(self.op, self.pyramid, p0, h0, t, u);
            }
            Some(d) => {
                sized(pf, n_t * L);
                d.expand_lanes::<L>(p0, pf);
                sized(hf, n_t * L);
                chain_product::<L>(self.op, self.pyramid, pf, hf, t, u);
                sized(h0, n_x * L);
                d.reduce_lanes::<L>(hf, h0);
            }
        }
        let h0: &[f64] = h0;
        out.par_iter_mut().enumerate().for_each(|(l, out)| {
            out.iter_mut().zip(h0.iter().skip(l).step_by(L)).for_each(|(o, h)| *o = *h);
        });
    }
}

/// H·p over the whole chain for the L interleaved lanes of `p`; `t` and `u` are work
/// vectors.
fn chain_product<const L: usize>(
    op: &DataOperator,
    pyramid: Option<&PyramidTerm>,
    p: &[f64],
    out: &mut [f64],
    t: &mut Vec<f64>,
    u: &mut Vec<f64>,
) {
    match op {
        DataOperator::A { a, at } => {
            t.resize(a.rows * L, 0.0);
            a.mul_lanes::<L>(p, t);
            at.mul_lanes::<L>(t, out);
        }
        DataOperator::Normal { h, .. } | DataOperator::Gram { h } => h.mul_lanes::<L>(p, out),
    }
    if let Some(pt) = pyramid {
        t.resize(pt.p.rows * L, 0.0);
        pt.p.mul_lanes::<L>(p, t);
        u.resize(out.len(), 0.0);
        pt.pt.mul_lanes::<L>(t, u);
        out.par_iter_mut().zip(&*u).for_each(|(o, u)| *o += pt.lambda * u);
    }
}

impl ChannelProblem<'_> {
    /// f and its gradient over the whole chain.
    fn value_gradient_chain(&self, x: &[f64], grad: &mut [f64]) -> f64 {
        let mut f = match self.op {
            DataOperator::A { a, at } => {
                let mut r = vec![0.0; a.rows];
                a.mul(x, &mut r);
                r.iter_mut().zip(&self.rhs.b).for_each(|(r, b)| *r -= b);
                at.mul(&r, grad);
                grad.iter_mut().for_each(|g| *g *= 2.0);
                dot(&r, &r)
            }
            DataOperator::Normal { h, .. } | DataOperator::Gram { h } => {
                h.mul(x, grad);
                let f = dot(x, grad) - 2.0 * dot(x, &self.rhs.atb) + self.rhs.bb;
                grad.iter_mut().zip(&self.rhs.atb).for_each(|(g, c)| *g = 2.0 * (*g - c));
                f.max(0.0)
            }
        };
        if let Some(pt) = self.pyramid {
            let mut t = vec![0.0; pt.p.rows];
            pt.p.mul(x, &mut t);
            let mut u = vec![0.0; grad.len()];
            pt.pt.mul(&t, &mut u);
            grad.iter_mut().zip(&u).for_each(|(g, u)| *g += 2.0 * pt.lambda * u);
            f += pt.lambda * dot(&t, &t);
        }
        f
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_rule_of_thesis_3_5() {
        assert_eq!(Form::choose(200, 100, 4.0), Form::Normal);
        assert_eq!(Form::choose(199, 100, 4.0), Form::A);
    }
}
