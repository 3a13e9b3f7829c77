//! A plain compressed-row sparse matrix for the solver's operators (Aᵀ, AᵀA, the pyramid
//! constraint), with deterministic parallel products: every output entry is summed by one
//! thread in a fixed order, so results do not depend on the thread count.

use rayon::prelude::*;

use crate::{CompileError, RenderMatrix};

/// A sparse `rows × cols` matrix in compressed-row form with f64 values.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Csr {
    pub rows: usize,
    pub cols: usize,
    pub row_start: Vec<usize>,
    pub col: Vec<u32>,
    pub val: Vec<f64>,
}

impl Csr {
    /// Row `r`'s column indices and values.
    pub fn row(&self, r: usize) -> (&[u32], &[f64]) {
        let (a, b) = (self.row_start[r], self.row_start[r + 1]);
        (&self.col[a..b], &self.val[a..b])
    }

    /// Number of stored entries.
    pub fn nnz(&self) -> usize {
        self.val.len()
    }

    /// The render matrix A as a `Csr`, after checking its structure and values.
    pub fn from_render_matrix(a: &RenderMatrix) -> Result<Csr, CompileError> {
        let (rows, cols) = (a.rows(), a.cols());
        if a.row_start.len() != rows + 1 {
            return Err(CompileError::Matrix(format!(
                "{} row pointers for {rows} rows",
                a.row_start.len()
            )));
        }
        if a.cols.len() != a.vals.len()
            || a.row_start[rows] as usize != a.vals.len()
            || a.row_start[0] != 0
        {
            return Err(CompileError::Matrix("row pointers disagree with the entry count".into()));
        }
        if a.row_start.windows(2).any(|w| w[0] > w[1]) {
            return Err(CompileError::Matrix("row pointers decrease".into()));
        }
        if let Some(i) = a.cols.iter().position(|&c| c as usize >= cols) {
            return Err(CompileError::Matrix(format!(
                "entry {i} names column {} of {cols}",
                a.cols[i]
            )));
        }
        crate::error::check_finite("A", &a.vals)?;
        Ok(Csr {
            rows,
            cols,
            row_start: a.row_start.iter().map(|&s| s as usize).collect(),
            col: a.cols.clone(),
            val: a.vals.iter().map(|&v| v as f64).collect(),
        })
    }

    /// y = M·x, parallel over rows.
    pub fn mul(&self, x: &[f64], y: &mut [f64]) {
        self.mul_lanes::<1>(x, y);
    }

    /// y_l = M·x_l for the L vectors of `x`, interleaved (`x[c·L + l]`, `y[r·L + l]`):
    /// M's entries are read once for all of them. Each lane's entry is summed in the order
    /// of [`Csr::mul`] (from −0.0, as `Iterator::sum`), so each lane equals `mul` of that
    /// lane bit for bit.
    pub fn mul_lanes<const L: usize>(&self, x: &[f64], y: &mut [f64]) {
        y.par_chunks_mut(L).enumerate().with_min_len(256).for_each(|(r, out)| {
            let (c, v) = self.row(r);
            let mut acc = [-0.0f64; L];
            for (&c, &v) in c.iter().zip(v) {
                let xc = &x[c as usize * L..c as usize * L + L];
                for l in 0..L {
                    acc[l] += v * xc[l];
                }
            }
            out.copy_from_slice(&acc);
        });
    }

    /// Mᵀ, entries of each new row ordered by the old row index.
    pub fn transpose(&self) -> Csr {
        let mut count = vec![0usize; self.cols + 1];
        for &c in &self.col {
            count[c as usize + 1] += 1;
        }
        for i in 0..self.cols {
            count[i + 1] += count[i];
        }
        let row_start = count.clone();
        let mut next = count;
        let mut col = vec![0u32; self.nnz()];
        let mut val = vec![0.0; self.nnz()];
        for r in 0..self.rows {
            let (cs, vs) = self.row(r);
            for (&c, &v) in cs.iter().zip(vs) {
                let k = &mut next[c as usize];
                col[*k] = r as u32;
                val[*k] = v;
                *k += 1;
            }
        }
        Csr { rows: self.cols, cols: self.rows, row_start, col, val }
    }

    /// Stacks matrices with the same column count on top of each other (thesis eq. 3.7).
    pub fn stack(parts: &[Csr]) -> Result<Csr, CompileError> {
        let cols = parts.first().map_or(0, |p| p.cols);
        let mut out = Csr { rows: 0, cols, row_start: vec![0], col: vec![], val: vec![] };
        for p in parts {
            if p.cols != cols {
                return Err(CompileError::Size {
                    what: "stacked matrices' column count".into(),
                    expected: cols,
                    found: p.cols,
                });
            }
            let base = out.nnz();
            out.row_start.extend(p.row_start[1..].iter().map(|s| s + base));
            out.col.extend_from_slice(&p.col);
            out.val.extend_from_slice(&p.val);
            out.rows += p.rows;
        }
        Ok(out)
    }

    /// MᵀM, assembled sparse (thesis eq. 3.5). `mt` must be `self.transpose()`. Row i is
    /// accumulated by one thread, visiting M's rows in order, so the sums are deterministic.
    pub fn gram(&self, mt: &Csr) -> Csr {
        Csr::zeros(self.cols).add_gram(self, mt)
    }

    /// The `n × n` matrix with no entries.
    pub fn zeros(n: usize) -> Csr {
        Csr { rows: n, cols: n, row_start: vec![0; n + 1], col: vec![], val: vec![] }
    }

    /// `self + MᵀM` (`self` square, as many columns as M; `mt` must be `M.transpose()`).
    /// Each entry continues its running sum over M's rows in order: the Gram matrices of
    /// matrices added one after the other are the Gram matrix of the matrices stacked, bit
    /// for bit (thesis eq. 3.7 assembled view by view).
    pub fn add_gram(&self, m: &Csr, mt: &Csr) -> Csr {
        let n = self.rows;
        debug_assert!(self.cols == n && m.cols == n && mt.rows == n);
        let rows: Vec<(Vec<u32>, Vec<f64>)> = (0..n)
            .into_par_iter()
            .with_min_len(64)
            .map_init(
                || (vec![0.0f64; n], vec![false; n], Vec::<u32>::new()),
                |(acc, seen, touched), i| {
                    let (cs, vs) = self.row(i);
                    for (&j, &v) in cs.iter().zip(vs) {
                        seen[j as usize] = true;
                        touched.push(j);
                        acc[j as usize] = v;
                    }
                    let (rs, ws) = mt.row(i);
                    for (&r, &wi) in rs.iter().zip(ws) {
                        let (cs, vs) = m.row(r as usize);
                        for (&j, &wj) in cs.iter().zip(vs) {
                            let j = j as usize;
                            if !seen[j] {
                                seen[j] = true;
                                touched.push(j as u32);
                            }
                            acc[j] += wi * wj;
                        }
                    }
                    touched.sort_unstable();
                    let vals = touched.iter().map(|&j| acc[j as usize]).collect();
                    let cols = touched.clone();
                    for &j in touched.iter() {
                        acc[j as usize] = 0.0;
                        seen[j as usize] = false;
                    }
                    touched.clear();
                    (cols, vals)
                },
            )
            .collect();
        let mut out = Csr {
            rows: n,
            cols: n,
            row_start: Vec::with_capacity(n + 1),
            col: vec![],
            val: vec![],
        };
        out.row_start.push(0);
        for (c, v) in rows {
            out.col.extend(c);
            out.val.extend(v);
            out.row_start.push(out.col.len());
        }
        out
    }

    /// Diagonal of MᵀM (the squared column norms).
    pub fn column_norms_squared(&self) -> Vec<f64> {
        let mut d = vec![0.0; self.cols];
        for (&c, &v) in self.col.iter().zip(&self.val) {
            d[c as usize] += v * v;
        }
        d
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn small() -> Csr {
        // [[1 2 0], [0 3 4]]
        Csr {
            rows: 2,
            cols: 3,
            row_start: vec![0, 2, 4],
            col: vec![0, 1, 1, 2],
            val: vec![1.0, 2.0, 3.0, 4.0],
        }
    }

    #[test]
    fn transpose_and_gram_match_dense() {
        let m = small();
        let mt = m.transpose();
        let mut y = vec![0.0; 3];
        mt.mul(&[1.0, 1.0], &mut y);
        assert_eq!(y, vec![1.0, 5.0, 4.0]);
        let g = m.gram(&mt);
        // MᵀM = [[1 2 0], [2 13 12], [0 12 16]]
        let mut dense = [[0.0; 3]; 3];
        for (i, row) in dense.iter_mut().enumerate() {
            let (c, v) = g.row(i);
            for (&c, &v) in c.iter().zip(v) {
                row[c as usize] = v;
            }
        }
        assert_eq!(dense, [[1.0, 2.0, 0.0], [2.0, 13.0, 12.0], [0.0, 12.0, 16.0]]);
        assert_eq!(m.column_norms_squared(), vec![1.0, 13.0, 16.0]);
    }

    /// A pseudo-random sparse matrix (about a third of the entries set).
    fn random(rows: usize, cols: usize, seed: u64) -> Csr {
        let mut s = seed;
        let mut next = || {
            s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (s >> 33) as f64 / (1u64 << 31) as f64
        };
        let mut m = Csr { rows, cols, row_start: vec![0], col: vec![], val: vec![] };
        for _ in 0..rows {
            for c in 0..cols {
                if next() < 0.35 {
                    m.col.push(c as u32);
                    m.val.push(next() * 2.0 - 0.7);
                }
            }
            m.row_start.push(m.col.len());
        }
        m
    }

    #[test]
    fn products_of_interleaved_lanes_are_each_lanes_product_bit_for_bit() {
        let m = random(50, 37, 9);
        let x: Vec<Vec<f64>> = (0..3)
            .map(|l| (0..37).map(|c| ((c * 13 + l * 5) % 11) as f64 - 4.3).collect())
            .collect();
        let mut interleaved = vec![0.0; 37 * 3];
        for (c, v) in interleaved.chunks_mut(3).enumerate() {
            v.copy_from_slice(&[x[0][c], x[1][c], x[2][c]]);
        }
        let mut y = vec![0.0; 50 * 3];
        m.mul_lanes::<3>(&interleaved, &mut y);
        for (l, x) in x.iter().enumerate() {
            let mut alone = vec![0.0; 50];
            m.mul(x, &mut alone);
            let lane: Vec<u64> = y.iter().skip(l).step_by(3).map(|v| v.to_bits()).collect();
            assert_eq!(lane, alone.iter().map(|v| v.to_bits()).collect::<Vec<_>>());
        }
    }

    #[test]
    fn gram_matrices_added_view_by_view_are_the_stacked_gram_bit_for_bit() {
        let parts: Vec<Csr> = (0..5).map(|k| random(40 + 7 * k, 30, k as u64 + 1)).collect();
        let stacked = Csr::stack(&parts).unwrap();
        let whole = stacked.gram(&stacked.transpose());
        let mut sum = Csr::zeros(30);
        for p in &parts {
            sum = sum.add_gram(p, &p.transpose());
        }
        assert!(whole.nnz() > 0);
        assert_eq!(sum, whole);
    }
}
