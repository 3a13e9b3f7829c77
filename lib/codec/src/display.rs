//! Display values, what a viewer sees: linear radiance clamped to [0, 1] and sRGB-encoded
//! (IEC 61966-2-1), peak 1. PSNR across the toolchain is measured on them, as the thesis
//! compares 8-bit frames.

/// The mean squared error below which PSNR reads as [`MAX_PSNR_DB`]: a display error of
/// 10⁻¹⁰, far under one 8-bit step.
pub const MIN_MSE: f64 = 1e-20;

/// The PSNR of no error: 200 dB, finite, so that JSON reports (where serde_json writes
/// infinity as `null`) carry a number.
pub const MAX_PSNR_DB: f64 = 200.0;

/// The sRGB encoding of a linear value clamped to [0, 1]; non-finite values display as 0.
pub fn srgb_encode(linear: f32) -> f32 {
    let l = if linear.is_finite() { linear.clamp(0.0, 1.0) } else { 0.0 };
    if l <= 0.003_130_8 {
        12.92 * l
    } else {
        1.055 * l.powf(1.0 / 2.4) - 0.055
    }
}

/// The display value of a linear radiance value.
pub fn display(linear: f32) -> f64 {
    srgb_encode(linear) as f64
}

/// PSNR in dB (peak 1) of two equally long slices of linear values, on display values;
/// no error reads as [`MAX_PSNR_DB`].
pub fn psnr_display(values: &[f32], reference: &[f32]) -> f64 {
    let sse: f64 =
        values.iter().zip(reference).map(|(x, y)| (display(*x) - display(*y)).powi(2)).sum();
    let mse = sse / values.len().max(1) as f64;
    10.0 * (1.0 / mse.max(MIN_MSE)).log10()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_encoding_clamps_and_maps_non_finite_values_to_black() {
        assert_eq!(srgb_encode(0.0), 0.0);
        assert!((srgb_encode(1.0) - 1.0).abs() < 1e-6);
        assert!((srgb_encode(0.18) - 0.4614).abs() < 1e-3);
        assert_eq!(srgb_encode(f32::NAN), 0.0);
        assert_eq!(srgb_encode(7.0), srgb_encode(1.0));
    }

    #[test]
    fn psnr_of_a_known_error_and_of_none() {
        // Display values 0.5 vs 0.6 everywhere: MSE 0.01, PSNR 20 dB.
        let lin = |d: f32| if d <= 0.04045 { d / 12.92 } else { ((d + 0.055) / 1.055).powf(2.4) };
        let (a, b) = (vec![lin(0.5); 12], vec![lin(0.6); 12]);
        assert!((psnr_display(&a, &b) - 20.0).abs() < 1e-3, "{}", psnr_display(&a, &b));
        assert!((psnr_display(&a, &a) - MAX_PSNR_DB).abs() < 1e-9);
    }
}
