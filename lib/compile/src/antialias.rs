//! Inference with antialiasing (thesis 3.4.4): A is built at a supersampled resolution (no
//! antialiasing in the model), then its rows are filtered with the display filter — the ray
//! tracer's truncated Gaussian (format-spec/RAYSET.md: w(d) = exp(−|d|²/2σ²) for |d| ≤ R,
//! centred on the pixel centre, normalised) — and divided by the filtered coverage, so
//! sub-pixels the object does not cover do not count.

use rayon::prelude::*;

use crate::model::{render_matrix, scene_depth, ModelError, TexturedObject};
use crate::transform::{DrawMesh, Viewport};
use crate::RenderMatrix;

/// A display pixel's row: pixel, coverage, (column, weight) entries.
type FilteredRow = (u32, f32, Vec<(u32, f32)>);

/// The display filter of the ray-traced set (`set.json`: `filter.sigma_px`, `filter.radius_px`),
/// in display pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DisplayFilter {
    pub sigma_px: f32,
    pub radius_px: f32,
}

/// Filters a render matrix built at `factor`× the display resolution (in each dimension) down
/// to display pixels: row p = Σ_k w_k · row_k / c_p over the covered sub-pixels k within the
/// filter radius, with c_p = Σ_k w_k over those covered sub-pixels (weights normalised over
/// all sub-pixels in the radius), the pixel's coverage. Pixels with c_p = 0 have no row.
pub fn antialias(
    supersampled: &RenderMatrix,
    factor: u32,
    filter: DisplayFilter,
) -> Result<RenderMatrix, ModelError> {
    let bad = !(filter.sigma_px > 0.0
        && filter.sigma_px.is_finite()
        && filter.radius_px > 0.0
        && filter.radius_px.is_finite());
    if bad
        || factor == 0
        || !supersampled.width.is_multiple_of(factor)
        || !supersampled.height.is_multiple_of(factor)
    {
        return Err(ModelError::Filter {
            sigma: filter.sigma_px,
            radius: filter.radius_px,
            factor,
        });
    }
    let (sw, sh) = (supersampled.width as i64, supersampled.height as i64);
    let (w, h) = (supersampled.width / factor, supersampled.height / factor);
    let f = factor as f64;
    let (sigma, radius) = (filter.sigma_px as f64, filter.radius_px as f64);
    // Sub-pixel index → row of the supersampled matrix.
    let mut row_of = vec![u32::MAX; (sw * sh) as usize];
    for (r, &p) in supersampled.pixels.iter().enumerate() {
        row_of[p as usize] = r as u32;
    }
    // Candidate display pixels: those whose filter reaches a covered sub-pixel.
    let reach = (radius * f).ceil() as i64 + 1;
    let mut reached = vec![false; w as usize * h as usize];
    let r = reach / factor as i64 + 1;
    for &p in &supersampled.pixels {
        let (sx, sy) = ((p as i64 % sw) / factor as i64, (p as i64 / sw) / factor as i64);
        for y in (sy - r).max(0)..=(sy + r).min(h as i64 - 1) {
            for x in (sx - r).max(0)..=(sx + r).min(w as i64 - 1) {
                reached[(y * w as i64 + x) as usize] = true;
            }
        }
    }
    let candidates: Vec<u32> = (0..reached.len() as u32).filter(|&p| reached[p as usize]).collect();
    let rows: Vec<FilteredRow> = candidates
        .par_iter()
        .map_init(Vec::new, |acc: &mut Vec<(u32, f64)>, &p| {
            acc.clear();
            let (cx, cy) = ((p % w) as f64 + 0.5, (p / w) as f64 + 0.5);
            let (x0, x1) =
                (((cx - radius) * f - 0.5).ceil() as i64, ((cx + radius) * f - 0.5).floor() as i64);
            let (y0, y1) =
                (((cy - radius) * f - 0.5).ceil() as i64, ((cy + radius) * f - 0.5).floor() as i64);
            let (mut total, mut covered) = (0.0f64, 0.0f64);
            for sy in y0..=y1 {
                for sx in x0..=x1 {
                    let (dx, dy) = ((sx as f64 + 0.5) / f - cx, (sy as f64 + 0.5) / f - cy);
                    let d2 = dx * dx + dy * dy;
                    if d2 > radius * radius {
                        continue;
                    }
                    let wk = (-d2 / (2.0 * sigma * sigma)).exp();
                    total += wk;
                    if sx < 0 || sy < 0 || sx >= sw || sy >= sh {
                        continue;
                    }
                    let r = row_of[(sy * sw + sx) as usize];
                    if r == u32::MAX {
                        continue;
                    }
                    covered += wk;
                    let (c, v) = supersampled.row(r as usize);
                    acc.extend(c.iter().zip(v).map(|(&c, &v)| (c, wk * v as f64)));
                }
            }
            if covered <= 0.0 || total <= 0.0 {
                return None;
            }
            // Merge repeated columns (sub-pixels share texels), in column order.
            acc.sort_unstable_by_key(|e| e.0);
            let mut entries: Vec<(u32, f32)> = Vec::with_capacity(acc.len().min(64));
            let mut k = 0;
            while k < acc.len() {
                let (c, mut v) = acc[k];
                k += 1;
                while k < acc.len() && acc[k].0 == c {
                    v += acc[k].1;
                    k += 1;
                }
                entries.push((c, (v / covered) as f32));
            }
            Some((p, (covered / total) as f32, entries))
        })
        .flatten()
        .collect();
    let mut out =
        RenderMatrix { width: w, height: h, layout: supersampled.layout, ..Default::default() };
    out.row_start.push(0);
    for (p, c, entries) in rows {
        out.pixels.push(p);
        out.coverage.push(c);
        for (col, v) in entries {
            out.cols.push(col);
            out.vals.push(v);
        }
        out.row_start.push(out.cols.len() as u32);
    }
    Ok(out)
}

/// The antialiased render matrix of `object` at display resolution `viewport` (thesis 3.4.4):
/// A at `factor`× the resolution, its fragments tested against the depth of `occluders` at
/// that resolution, filtered with the display filter and divided by coverage.
pub fn antialiased_render_matrix(
    viewport: Viewport,
    factor: u32,
    filter: DisplayFilter,
    object: &TexturedObject,
    occluders: &[DrawMesh],
) -> Result<RenderMatrix, ModelError> {
    if factor == 0 || factor > 16 {
        return Err(ModelError::Filter {
            sigma: filter.sigma_px,
            radius: filter.radius_px,
            factor,
        });
    }
    let ss = Viewport {
        width: viewport.width.saturating_mul(factor),
        height: viewport.height.saturating_mul(factor),
    };
    let depth = scene_depth(ss, occluders, None)?;
    antialias(&render_matrix(ss, object, Some(&depth))?, factor, filter)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::TextureLayout;

    #[test]
    fn half_covered_pixel_has_half_coverage_and_unit_rows() {
        // 4×4 supersampled (factor 2 → 2×2): the left half of the sub-pixels are covered, all
        // reading texel 0.
        let layout = TextureLayout::full(1, 1);
        let mut a = RenderMatrix { width: 4, height: 4, layout, ..Default::default() };
        a.row_start.push(0);
        for y in 0..4 {
            for x in 0..2 {
                a.pixels.push(y * 4 + x);
                a.coverage.push(1.0);
                a.cols.push(0);
                a.vals.push(1.0);
                a.row_start.push(a.cols.len() as u32);
            }
        }
        let f = DisplayFilter { sigma_px: 0.5, radius_px: 0.5 };
        let d = antialias(&a, 2, f).unwrap();
        // Display pixels (0, y) fully covered; (1, y) not reached (radius 0.5 px).
        assert_eq!(d.pixels, vec![0, 2]);
        assert!(d.coverage.iter().all(|&c| (c - 1.0).abs() < 1e-6));
        let wide = antialias(&a, 2, DisplayFilter { sigma_px: 0.5, radius_px: 1.5 }).unwrap();
        assert_eq!(wide.pixels, vec![0, 1, 2, 3]);
        assert!(wide.coverage[1] > 0.0 && wide.coverage[1] < 0.5);
        for r in 0..wide.rows() {
            assert!((wide.row(r).1.iter().sum::<f32>() - 1.0).abs() < 1e-6);
        }
    }

    #[test]
    fn edge_pixels_get_fractional_coverage() {
        use crate::{Address, Filter, Sampler, TextureTransform};
        // A quad over the left 40 % of an 10×4 screen.
        let positions = [[-1.0, 1.0, 0.5], [-0.2, 1.0, 0.5], [-0.2, -1.0, 0.5], [-1.0, -1.0, 0.5]];
        let uvs = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        let object = TexturedObject {
            mesh: DrawMesh {
                positions: &positions,
                uvs: &uvs,
                indices: &[0, 1, 2, 0, 2, 3],
                clip_from_object: glam::Mat4::IDENTITY,
            },
            transform: TextureTransform::IDENTITY,
            layout: TextureLayout::full(8, 8),
            sampler: Sampler { filter: Filter::Trilinear, address: [Address::ClampToEdge; 2] },
        };
        let f = DisplayFilter { sigma_px: 0.5, radius_px: 1.5 };
        let a = antialiased_render_matrix(Viewport { width: 10, height: 4 }, 4, f, &object, &[])
            .unwrap();
        let cov = |x: u32, y: u32| {
            a.pixels.iter().position(|&p| p == y * 10 + x).map(|r| a.coverage[r]).unwrap_or(0.0)
        };
        assert!(cov(1, 1) > 0.99, "{}", cov(1, 1));
        // The edge x = 4 px runs between pixels 3 and 4: about half each side of the edge.
        assert!(
            cov(3, 1) > 0.6 && cov(3, 1) < 1.0 && cov(4, 1) > 0.0 && cov(4, 1) < 0.4,
            "{} {}",
            cov(3, 1),
            cov(4, 1)
        );
        assert!((cov(3, 1) + cov(4, 1) - 1.0).abs() < 0.05);
        assert_eq!(cov(7, 1), 0.0);
        for r in 0..a.rows() {
            assert!((a.row(r).1.iter().sum::<f32>() - 1.0).abs() < 1e-5);
        }
    }
}
