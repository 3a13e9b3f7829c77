//! The render matrix A (thesis eq. 3.2): rows are the screen pixels an object covers,
//! columns the texels of its texture's MIP pyramid, entries the filter weights with which the
//! player blends texels into a pixel.

use rayon::prelude::*;

use crate::TextureLayout;

/// A sparse n_s × n_t matrix in compressed-row form, with the pixel and coverage of each row.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct RenderMatrix {
    /// Screen size in pixels.
    pub width: u32,
    pub height: u32,
    pub layout: TextureLayout,
    /// Per row: the pixel index `y · width + x` (y = 0 is the top row).
    pub pixels: Vec<u32>,
    /// Per row: the fraction of the pixel the object covers (after the display filter).
    pub coverage: Vec<f32>,
    /// Row r's entries are `cols[row_start[r]..row_start[r + 1]]` / `vals[...]`.
    pub row_start: Vec<u32>,
    pub cols: Vec<u32>,
    pub vals: Vec<f32>,
}

impl RenderMatrix {
    /// The matrix of one lookup's `taps` per pixel of `pixels` (increasing), each row with
    /// coverage 1, its entries sorted by column.
    pub fn from_taps(
        viewport: crate::Viewport,
        layout: TextureLayout,
        pixels: Vec<u32>,
        rows: &[crate::filter::Taps],
    ) -> RenderMatrix {
        let nnz: usize = rows.iter().map(|t| t.len).sum();
        let (mut cols, mut vals) = (Vec::with_capacity(nnz), Vec::with_capacity(nnz));
        let mut row_start = Vec::with_capacity(rows.len() + 1);
        row_start.push(0);
        for t in rows {
            for (c, v) in t.sorted() {
                cols.push(c);
                vals.push(v);
            }
            row_start.push(cols.len() as u32);
        }
        RenderMatrix {
            width: viewport.width,
            height: viewport.height,
            layout,
            coverage: vec![1.0; pixels.len()],
            pixels,
            row_start,
            cols,
            vals,
        }
    }

    /// The matrix of rows built in chunks of consecutive pixels of `pixels` (increasing):
    /// each chunk's columns and values, row after row, and its rows' entry counts; every
    /// row with coverage 1.
    pub fn from_row_chunks(
        viewport: crate::Viewport,
        layout: TextureLayout,
        pixels: Vec<u32>,
        chunks: Vec<(Vec<u32>, Vec<f32>, Vec<u32>)>,
    ) -> RenderMatrix {
        let nnz = chunks.iter().map(|c| c.0.len()).sum();
        let (mut cols, mut vals) = (Vec::with_capacity(nnz), Vec::with_capacity(nnz));
        let mut row_start = Vec::with_capacity(pixels.len() + 1);
        row_start.push(0u32);
        for (c, v, lens) in chunks {
            for len in lens {
                row_start.push(row_start[row_start.len() - 1] + len);
            }
            cols.extend(c);
            vals.extend(v);
        }
        RenderMatrix {
            width: viewport.width,
            height: viewport.height,
            layout,
            coverage: vec![1.0; pixels.len()],
            pixels,
            row_start,
            cols,
            vals,
        }
    }

    /// n_s.
    pub fn rows(&self) -> usize {
        self.pixels.len()
    }

    /// n_t.
    pub fn cols(&self) -> usize {
        self.layout.texel_count()
    }

    pub fn row(&self, r: usize) -> (&[u32], &[f32]) {
        let (a, b) = (self.row_start[r] as usize, self.row_start[r + 1] as usize);
        (&self.cols[a..b], &self.vals[a..b])
    }

    /// y = A·x (parallel over rows).
    pub fn mul(&self, x: &[f32], y: &mut [f32]) {
        y.par_iter_mut().enumerate().for_each(|(r, out)| {
            let (c, v) = self.row(r);
            *out = c.iter().zip(v).map(|(&c, &v)| v * x[c as usize]).sum();
        });
    }

    /// y = Aᵀ·x, summed in row order (deterministic).
    pub fn mul_t(&self, x: &[f32], y: &mut [f32]) {
        y.iter_mut().for_each(|v| *v = 0.0);
        for (r, &xr) in x[..self.rows()].iter().enumerate() {
            let (c, v) = self.row(r);
            for (&c, &v) in c.iter().zip(v) {
                y[c as usize] += v * xr;
            }
        }
    }
}
