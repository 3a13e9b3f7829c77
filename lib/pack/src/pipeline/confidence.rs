//! The set's confidence in each pixel, which weighs the pixel's rows in the solves (thesis
//! 6.3.3, where a confidence image multiplies both sides of the least-squares system; there
//! from the spread of a pixel's exit rays, here from the tracer's own error estimate).
//!
//! A set traced with adaptive sampling records, per pixel, the relative error e it stopped
//! at (RAYSET.md 5.4, the `error` layer): below the noise threshold τ unless the pixel took
//! the most samples. The confidence is c = min(1, τ / e): 1 where the pixel met the
//! threshold, τ / e where it stopped short of it, so that a row's weight in the normal
//! equations, c², is the inverse of its error's variance relative to the threshold's.
//! A set without the layer (a fixed sample count, another renderer) weighs every row 1.
//!
//! Only the view-dependent surface layers' solves (one view each) weigh their rows, and not
//! where the layer was read from its denoised twin (RAYSET.md 5.4). Measured
//! on teapot-pem at CI size, adaptive sampling 4–64 at 0.05, lossless, against 1024 spp
//! (docs/benchmarks/clean-sets.md): there the mirror teapot stored as textures gains 2.3 dB
//! on its body and 1.5 on its lid, while weighing the stacked solves too (the diffuse layer
//! over every view, the layered shells) lost 0.1–0.8 dB on every object, with this
//! confidence and with an absolute one alike: a pixel's error estimate is one pair of half
//! means, and where many views constrain a texel, reweighting them by it adds more
//! variance than it removes.

use anyhow::Result;
use pis_compile::RenderMatrix;

use super::input::LoadedSet;

/// The error layer's name (RAYSET.md 5.4).
const ERROR_LAYER: &str = "error";

/// Per pixel of point `p`, the confidence in it; `None` where the pack does not weigh rows
/// (`--confidence off`) or the set records no error for its pixels.
pub fn pixel_confidence(set: &LoadedSet, p: usize) -> Result<Option<Vec<f32>>> {
    let tau = set.trace.noise_threshold;
    if !set.weigh_rows || tau <= 0.0 {
        return Ok(None);
    }
    let images = set.images.shared(p)?;
    let Some(error) = images.layer(ERROR_LAYER).and_then(|l| l.channel("Y")) else {
        return Ok(None);
    };
    Ok(Some(error.iter().map(|&e| confidence(e, tau)).collect()))
}

/// c = min(1, τ / e); a non-finite or non-positive error counts as met.
pub fn confidence(error: f32, tau: f32) -> f32 {
    if error.is_finite() && error > tau {
        tau / error
    } else {
        1.0
    }
}

/// The confidence of object `o`'s rows at point `p` (its covered `pixels`, `y · width + x`)
/// for the solves of its view-dependent layers; empty (every row 1) where the pack does not
/// weigh rows, the set records no error, or the object's specular layer at `p` is read from
/// its denoised twin, whose error the raw estimate does not describe.
pub fn rows_confidence(set: &LoadedSet, p: usize, o: usize, pixels: &[u32]) -> Result<Vec<f32>> {
    let specular = pis_trace::layers::object_layer_name(
        &set.channels[o],
        pis_trace::layers::LayerKind::Specular,
    );
    if set.denoised.get(p).is_some_and(|d| d.contains(&specular)) {
        return Ok(Vec::new());
    }
    Ok(pixel_confidence(set, p)?.map_or_else(Vec::new, |c| {
        pixels.iter().map(|&p| c.get(p as usize).copied().unwrap_or(1.0)).collect()
    }))
}

/// `a`'s rows and their right-hand sides `b` (`b.len() / a.rows()` values a row), each
/// multiplied by its confidence in `w`; `a` and `b` as they are where `w` is empty.
pub fn weigh<'a>(
    a: &'a RenderMatrix,
    b: &'a [f32],
    w: &[f32],
) -> (std::borrow::Cow<'a, RenderMatrix>, std::borrow::Cow<'a, [f32]>) {
    use std::borrow::Cow;
    if w.is_empty() || a.rows() == 0 {
        return (Cow::Borrowed(a), Cow::Borrowed(b));
    }
    let per_row = b.len() / a.rows();
    let mut m = a.clone();
    for (r, &c) in w.iter().enumerate().take(m.rows()) {
        let (lo, hi) = (m.row_start[r] as usize, m.row_start[r + 1] as usize);
        m.vals[lo..hi].iter_mut().for_each(|v| *v *= c);
    }
    let b =
        b.iter().enumerate().map(|(k, &x)| x * w.get(k / per_row.max(1)).copied().unwrap_or(1.0));
    (Cow::Owned(m), Cow::Owned(b.collect()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use pis_compile::{TextureLayout, Viewport};

    #[test]
    fn a_pixel_that_met_the_threshold_counts_fully() {
        assert_eq!(confidence(0.01, 0.05), 1.0);
        assert_eq!(confidence(0.05, 0.05), 1.0);
        assert_eq!(confidence(0.2, 0.05), 0.25);
        assert_eq!(confidence(f32::NAN, 0.05), 1.0);
    }

    #[test]
    fn a_weighed_row_pulls_the_solution_less() {
        // One texel seen by two pixels that disagree: 1.0 (trusted) and 0.0 (c = 0.25).
        let layout = TextureLayout::full(1, 1);
        let vp = Viewport { width: 2, height: 1 };
        let taps: Vec<pis_compile::filter::Taps> = (0..2)
            .map(|_| {
                let mut t = pis_compile::filter::Taps::default();
                t.add(0, 1.0);
                t
            })
            .collect();
        let a = RenderMatrix::from_taps(vp, layout, vec![0, 1], &taps);
        let b = [1.0, 1.0, 1.0, 0.0, 0.0, 0.0];
        let (wa, wb) = weigh(&a, &b, &[1.0, 0.25]);
        assert_eq!(wa.vals, vec![1.0, 0.25]);
        assert_eq!(&wb[..], &[1.0, 1.0, 1.0, 0.0, 0.0, 0.0]);
        // The least-squares texel: Σ c²·b / Σ c² = 1 / 1.0625.
        let x: f32 = wa.vals.iter().zip(wb.chunks(3)).map(|(v, b)| v * b[0]).sum::<f32>()
            / wa.vals.iter().map(|v| v * v).sum::<f32>();
        assert!((x - 1.0 / 1.0625).abs() < 1e-6, "{x}");
        let (same_a, same_b) = weigh(&a, &b, &[]);
        assert!(matches!(same_a, std::borrow::Cow::Borrowed(_)) && same_b.len() == 6);
    }
}
