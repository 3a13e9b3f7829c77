//! Display metrics. PSNR is measured on display values: linear radiance clamped to [0, 1],
//! sRGB-encoded (IEC 61966-2-1), peak 1 — the values a viewer sees.

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

/// A running sum of squared display errors, for PSNR over any set of values.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SquaredError {
    pub sum: f64,
    pub count: u64,
    /// Largest absolute display error seen.
    pub max: f64,
}

impl SquaredError {
    /// Adds the display error of one linear value against its reference.
    #[inline]
    pub fn add(&mut self, value: f32, reference: f32) {
        let e = display(value) - display(reference);
        self.sum += e * e;
        self.count += 1;
        self.max = self.max.max(e.abs());
    }

    /// Adds the errors of two equally long slices of linear values.
    pub fn add_slices(&mut self, values: &[f32], reference: &[f32]) {
        for (v, r) in values.iter().zip(reference) {
            self.add(*v, *r);
        }
    }

    pub fn merge(&mut self, other: &SquaredError) {
        self.sum += other.sum;
        self.count += other.count;
        self.max = self.max.max(other.max);
    }

    pub fn mse(&self) -> f64 {
        self.sum / self.count.max(1) as f64
    }

    /// PSNR in dB, peak 1; an exact match (or no values) reports `f64::INFINITY`.
    pub fn psnr(&self) -> f64 {
        if self.sum == 0.0 {
            f64::INFINITY
        } else {
            10.0 * (1.0 / self.mse()).log10()
        }
    }
}

/// PSNR in dB (peak 1) of two equally long slices of linear values, on display values.
pub fn psnr_display(values: &[f32], reference: &[f32]) -> f64 {
    let mut e = SquaredError::default();
    e.add_slices(values, reference);
    e.psnr()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn psnr_of_a_known_error() {
        // Display values 0.5 vs 0.6 everywhere: MSE 0.01, PSNR 20 dB.
        let lin = |d: f32| if d <= 0.04045 { d / 12.92 } else { ((d + 0.055) / 1.055).powf(2.4) };
        let a = vec![lin(0.5); 12];
        let b = vec![lin(0.6); 12];
        assert!((psnr_display(&a, &b) - 20.0).abs() < 1e-3, "{}", psnr_display(&a, &b));
        assert_eq!(psnr_display(&a, &a), f64::INFINITY);
    }

    #[test]
    fn display_clamps_and_encodes() {
        assert_eq!(display(-1.0), 0.0);
        assert!((display(2.0) - 1.0).abs() < 1e-6);
        assert_eq!(display(f32::NAN), 0.0);
        assert!((display(0.214_041) - 0.5).abs() < 1e-4);
    }
}
