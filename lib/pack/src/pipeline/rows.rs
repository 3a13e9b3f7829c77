//! The rows of a render matrix that an object's pixels make up: those the tracer covers,
//! and the traced values at them (a row's b).

use pis_compile::RenderMatrix;

/// Keeps the rows of A whose pixels the tracer covers; returns the reduced A and its b.
pub fn restrict(a: &RenderMatrix, cov: &[f32], rgb: &[f32]) -> (RenderMatrix, Vec<f32>) {
    let out = restrict_rows(a, cov);
    let b = gather(&out.pixels, rgb);
    (out, b)
}

/// The RGB values of `rgb` (3 per pixel of the image) at `pixels`: a row's b.
pub fn gather(pixels: &[u32], rgb: &[f32]) -> Vec<f32> {
    let mut b = Vec::with_capacity(pixels.len() * 3);
    for &p in pixels {
        b.extend_from_slice(&rgb[p as usize * 3..p as usize * 3 + 3]);
    }
    b
}

/// The rows of A whose pixels the tracer covers.
pub fn restrict_rows(a: &RenderMatrix, cov: &[f32]) -> RenderMatrix {
    select_rows(a, |p| !cov.get(p as usize).is_none_or(|&c| c <= 0.0))
}

/// The rows of `a` whose pixel `keep` marks, in their order.
pub fn select_rows(a: &RenderMatrix, keep: impl Fn(u32) -> bool) -> RenderMatrix {
    let mut out = RenderMatrix {
        width: a.width,
        height: a.height,
        layout: a.layout,
        row_start: vec![0],
        ..Default::default()
    };
    for r in 0..a.rows() {
        if !keep(a.pixels[r]) {
            continue;
        }
        let (c, v) = a.row(r);
        out.cols.extend_from_slice(c);
        out.vals.extend_from_slice(v);
        out.row_start.push(out.cols.len() as u32);
        out.pixels.push(a.pixels[r]);
        out.coverage.push(a.coverage[r]);
    }
    out
}
