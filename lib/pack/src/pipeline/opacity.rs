//! A translucent object's opacity (SPEC.md 9): the tracer's coverage of each pixel over the
//! model's, the rows' radiance premultiplied by it as the player composites them, and the
//! solved opacity stored as the alpha channel of the object's first surface layer.

use pis_compile::RenderMatrix;

/// A translucent object's opacity per row of `a`: the tracer's coverage over the model's
/// (the fraction of the pixel's area the surface covers), in [0, 1].
fn opacity(a: &RenderMatrix, coverage: &[f32]) -> Vec<f32> {
    a.pixels
        .iter()
        .zip(&a.coverage)
        .map(|(&p, &m)| {
            let c = coverage.get(p as usize).copied().unwrap_or(0.0);
            if m > 0.0 {
                (c / m).clamp(0.0, 1.0)
            } else {
                0.0
            }
        })
        .collect()
}

/// Values per row (`channels` each) multiplied by the row's opacity.
fn premultiplied(values: &mut [f32], alpha: &[f32], channels: usize) {
    values
        .chunks_exact_mut(channels)
        .zip(alpha)
        .for_each(|(v, a)| v.iter_mut().for_each(|x| *x *= a));
}

/// Premultiplies the rows' radiance of every layer in `layers` (3 channels a row) by the
/// opacity of `a`'s rows under the tracer's `coverage`; returns that opacity, three channels
/// a row, as the radiance the alpha channel is solved for.
pub(super) fn premultiply(
    a: &RenderMatrix,
    coverage: &[f32],
    layers: [&mut Vec<f32>; 2],
) -> Vec<f32> {
    let opacity = opacity(a, coverage);
    for values in layers {
        premultiplied(values, &opacity, 3);
    }
    opacity.iter().flat_map(|&x| [x; 3]).collect()
}

/// RGBA texels: the colour of `rgb` and, as alpha, the first channel of `alpha` clamped to
/// [0, 1] (an opacity).
pub(super) fn with_alpha(rgb: &[f32], alpha: &[f32]) -> Vec<f32> {
    rgb.chunks_exact(3)
        .zip(alpha.chunks_exact(3))
        .flat_map(|(c, a)| [c[0], c[1], c[2], a[0].clamp(0.0, 1.0)])
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn texels_keep_their_colour_and_take_the_opacity_clamped() {
        let rgb = [0.5, 0.25, 2.0, 1.0, 1.0, 1.0];
        let alpha = [1.5, 0.0, 0.0, -0.25, 9.0, 9.0];
        assert_eq!(with_alpha(&rgb, &alpha), vec![0.5, 0.25, 2.0, 1.0, 1.0, 1.0, 1.0, 0.0]);
    }

    #[test]
    fn premultiplied_rows_scale_every_channel_by_their_own_opacity() {
        let mut values = vec![1.0, 2.0, 3.0, 4.0, 4.0, 4.0];
        premultiplied(&mut values, &[0.5, 0.25], 3);
        assert_eq!(values, vec![0.5, 1.0, 1.5, 1.0, 1.0, 1.0]);
    }
}
