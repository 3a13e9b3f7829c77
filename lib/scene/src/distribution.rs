//! Piecewise-constant distributions over a grid of cells: what an environment image is
//! importance-sampled by, built once when the scene is loaded.
//!
//! Densities are read from the cumulative tables themselves (a cell's probability is the
//! width of its step), so a sample's density and the density looked up for the same point
//! always agree, also where float rounding has left a cell of tiny weight with no
//! probability at all.

/// A piecewise-constant distribution over `width × height` cells of the unit square:
/// a row by the marginal, then a column by that row's conditional.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Distribution2D {
    width: usize,
    height: usize,
    /// Per row, `width + 1` cumulative probabilities from 0 to 1.
    rows: Vec<f32>,
    /// `height + 1` cumulative row probabilities from 0 to 1.
    marginal: Vec<f32>,
}

/// Cumulative probabilities (`weights.len() + 1` values, 0 to 1) of non-negative weights,
/// and their sum; uniform steps when the sum is 0.
fn cumulative(weights: impl ExactSizeIterator<Item = f64>, out: &mut Vec<f32>) -> f64 {
    let n = weights.len();
    let start = out.len();
    let mut sum = 0.0f64;
    out.push(0.0);
    let mut running = Vec::with_capacity(n);
    for w in weights {
        sum += w;
        running.push(sum);
    }
    if sum > 0.0 {
        out.extend(running.iter().map(|&r| (r / sum) as f32));
    } else {
        out.extend((1..=n).map(|k| (k as f64 / n as f64) as f32));
    }
    out[start + n] = 1.0;
    sum
}

/// The step of `cdf` that `u` ∈ [0, 1) falls in, and where in it (0..1).
fn find(cdf: &[f32], u: f32) -> (usize, f32) {
    let n = cdf.len() - 1;
    let i = cdf.partition_point(|&c| c <= u).clamp(1, n) - 1;
    let width = cdf[i + 1] - cdf[i];
    let along = if width > 0.0 { ((u - cdf[i]) / width).clamp(0.0, 0.999_999_94) } else { 0.5 };
    (i, along)
}

impl Distribution2D {
    /// The distribution proportional to `weight(column, row)` (finite, ≥ 0) over a
    /// `width × height` grid; `None` when the grid is empty or every weight is 0.
    pub fn new(
        width: usize,
        height: usize,
        weight: impl Fn(usize, usize) -> f32,
    ) -> Option<Distribution2D> {
        if width == 0 || height == 0 {
            return None;
        }
        let mut rows = Vec::with_capacity((width + 1) * height);
        let mut totals = Vec::with_capacity(height);
        for j in 0..height {
            totals
                .push(cumulative((0..width).map(|i| f64::from(weight(i, j).max(0.0))), &mut rows));
        }
        let mut marginal = Vec::with_capacity(height + 1);
        let total = cumulative(totals.into_iter(), &mut marginal);
        (total > 0.0 && total.is_finite()).then_some(Distribution2D {
            width,
            height,
            rows,
            marginal,
        })
    }

    /// Grid size (columns, rows).
    pub fn size(&self) -> (usize, usize) {
        (self.width, self.height)
    }

    fn row(&self, j: usize) -> &[f32] {
        &self.rows[j * (self.width + 1)..(j + 1) * (self.width + 1)]
    }

    /// The density at cell (i, j) with respect to area on the unit square.
    fn cell_density(&self, i: usize, j: usize) -> f32 {
        let row = self.row(j);
        let p_row = self.marginal[j + 1] - self.marginal[j];
        let p_col = row[i + 1] - row[i];
        p_row * p_col * (self.width * self.height) as f32
    }

    /// A point of the unit square drawn from the distribution with the uniform numbers
    /// `u` ∈ [0, 1)², its density and its cell (column, row). The cell is the one drawn:
    /// [`Self::cell`] of the point may name a neighbour where float rounding puts the point
    /// on the cell's edge.
    pub fn sample(&self, u: [f32; 2]) -> ([f32; 2], f32, (usize, usize)) {
        let (j, dv) = find(&self.marginal, u[1]);
        let (i, du) = find(self.row(j), u[0]);
        let point = [(i as f32 + du) / self.width as f32, (j as f32 + dv) / self.height as f32];
        (point, self.cell_density(i, j), (i, j))
    }

    /// The density at a point of the unit square (0 outside it).
    pub fn density(&self, point: [f32; 2]) -> f32 {
        if !(0.0..=1.0).contains(&point[0]) || !(0.0..=1.0).contains(&point[1]) {
            return 0.0;
        }
        let i = ((point[0] * self.width as f32) as usize).min(self.width - 1);
        let j = ((point[1] * self.height as f32) as usize).min(self.height - 1);
        self.cell_density(i, j)
    }

    /// The cell a point of the unit square lies in (clamped to the grid).
    pub fn cell(&self, point: [f32; 2]) -> (usize, usize) {
        let i = ((point[0].max(0.0) * self.width as f32) as usize).min(self.width - 1);
        let j = ((point[1].max(0.0) * self.height as f32) as usize).min(self.height - 1);
        (i, j)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn samples_fall_in_cells_by_weight_and_their_density_is_the_lookup() {
        // 4 × 2 cells; weights 0 1 2 0 / 0 0 0 5: probabilities 1/8, 2/8, 5/8.
        let w = [[0.0, 1.0, 2.0, 0.0], [0.0, 0.0, 0.0, 5.0]];
        let d = Distribution2D::new(4, 2, |i, j| w[j][i]).unwrap();
        let mut counts = [[0u32; 4]; 2];
        let n = 64u32;
        for a in 0..n {
            for b in 0..n {
                let u = [(a as f32 + 0.5) / n as f32, (b as f32 + 0.5) / n as f32];
                let (p, pdf, (i, j)) = d.sample(u);
                assert_eq!(d.cell(p), (i, j));
                counts[j][i] += 1;
                assert_eq!(pdf, d.density(p), "at {p:?}");
                // Density = probability w/8 over the cell's area 1/8.
                assert!((pdf - w[j][i]).abs() < 1e-5, "cell ({i},{j}): {pdf}");
            }
        }
        let total = (n * n) as f32;
        for (j, row) in counts.iter().enumerate() {
            for (i, &c) in row.iter().enumerate() {
                assert!(
                    (c as f32 / total - w[j][i] / 8.0).abs() < 2.0 / n as f32,
                    "cell ({i},{j}): {c}"
                );
            }
        }
        assert_eq!(d.density([1.5, 0.5]), 0.0);
    }

    #[test]
    fn an_all_zero_or_empty_grid_has_no_distribution() {
        assert!(Distribution2D::new(3, 2, |_, _| 0.0).is_none());
        assert!(Distribution2D::new(0, 2, |_, _| 1.0).is_none());
    }
}
