//! Display metrics. PSNR is measured on display values: linear radiance clamped to [0, 1],
//! sRGB-encoded (IEC 61966-2-1), peak 1 — the values a viewer sees ([`pis_codec::display`]).

pub use pis_codec::display::{display, psnr_display, srgb_encode};

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

/// The squared display error of values against the image two independent renders of one
/// reference estimate (the same renderer, samples drawn from different streams), with the
/// references' own noise taken out. For values `v`, references `r₁ = t + n₁`, `r₂ = t + n₂`
/// with independent zero-mean noise of equal variance σ² about the converged `t`:
/// E[(v − r̄)²] = (v − t)² + σ²/2 and E[(r₁ − r₂)²] = 2σ², so (v − r̄)² − (r₁ − r₂)²/4 is
/// an unbiased estimate of (v − t)², the error a noiseless reference would measure. On
/// display values this holds to first order in the noise: the variance is taken out, but
/// where the noise is large against the sRGB curve's bend or the clamp at white (rare,
/// bright paths), a render's expected display value is itself off the converged one, and
/// that bias, which shrinks only with more samples, stays in.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PairedError {
    /// Against the references' mean r̄ (itself a render of twice the samples).
    pub against_mean: SquaredError,
    /// Between the two references.
    pub between: SquaredError,
}

impl PairedError {
    /// Adds one linear value against its two references.
    #[inline]
    pub fn add(&mut self, value: f32, first: f32, second: f32) {
        self.against_mean.add(value, 0.5 * (first + second));
        self.between.add(first, second);
    }

    /// Adds equally long slices of linear values and their references.
    pub fn add_slices(&mut self, values: &[f32], first: &[f32], second: &[f32]) {
        for ((v, a), b) in values.iter().zip(first).zip(second) {
            self.add(*v, *a, *b);
        }
    }

    pub fn merge(&mut self, other: &PairedError) {
        self.against_mean.merge(&other.against_mean);
        self.between.merge(&other.between);
    }

    /// The mean squared display error of the references' mean about its expectation (its
    /// noise: the variance part of its error about the converged image).
    pub fn reference_mse(&self) -> f64 {
        self.between.mse() / 4.0
    }

    /// PSNR of the references' mean against its expectation (its own noise), dB.
    pub fn reference_psnr(&self) -> f64 {
        psnr_of(self.reference_mse())
    }

    /// PSNR of the values against the converged image, the references' noise taken out;
    /// `f64::INFINITY` when the measured error is within that noise.
    pub fn psnr_noise_removed(&self) -> f64 {
        psnr_of(self.against_mean.mse() - self.reference_mse())
    }
}

/// PSNR in dB (peak 1) of a mean squared error; 0 or less reports `f64::INFINITY`.
fn psnr_of(mse: f64) -> f64 {
    if mse <= 0.0 {
        f64::INFINITY
    } else {
        10.0 * (1.0 / mse).log10()
    }
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
        // No error: 200 dB on display values (a number in JSON), infinity in a running sum.
        assert!((psnr_display(&a, &a) - pis_codec::display::MAX_PSNR_DB).abs() < 1e-9);
        let mut same = SquaredError::default();
        same.add_slices(&a, &a);
        assert_eq!(same.psnr(), f64::INFINITY);
    }

    /// A deterministic stream of uniforms in [0, 1) (splitmix64).
    fn uniforms(seed: u64) -> impl FnMut() -> f32 {
        let mut x = seed;
        move || {
            x = x.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = x;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            ((z ^ (z >> 31)) >> 40) as f32 / (1u64 << 24) as f32
        }
    }

    #[test]
    fn a_pair_of_noisy_references_measures_the_error_against_the_converged_image() {
        // A converged image t, values v off it (σ ≈ 0.03 linear, about 33 dB), and two
        // references whose noise (σ ≈ 0.06 each) is larger than that error.
        let mut u = uniforms(11);
        let n = 400_000;
        let t: Vec<f32> = (0..n).map(|_| 0.3 + 0.3 * u()).collect();
        let v: Vec<f32> = t.iter().map(|&x| x + 0.1 * (u() - 0.5)).collect();
        let noisy = |u: &mut dyn FnMut() -> f32| -> Vec<f32> {
            t.iter().map(|&x| x + 0.2 * (u() - 0.5)).collect()
        };
        let (r1, r2) = (noisy(&mut u), noisy(&mut u));
        let truth = psnr_display(&v, &t);
        let mut e = PairedError::default();
        e.add_slices(&v, &r1, &r2);
        let raw = e.against_mean.psnr();
        eprintln!("truth {truth:.2} dB, against the references' mean {raw:.2}, noise removed {:.2}, references {:.2}", e.psnr_noise_removed(), e.reference_psnr());
        assert!(
            truth - raw > 4.0,
            "the references' noise should dominate the raw figure: {raw} against {truth}"
        );
        assert!(
            (e.psnr_noise_removed() - truth).abs() < 0.25,
            "noise removed {} against the truth {truth}",
            e.psnr_noise_removed()
        );
        // The references' own noise: the mean's error about t, measured without t.
        let mean: Vec<f32> = r1.iter().zip(&r2).map(|(a, b)| 0.5 * (a + b)).collect();
        assert!(
            (e.reference_psnr() - psnr_display(&mean, &t)).abs() < 0.1,
            "{} against {}",
            e.reference_psnr(),
            psnr_display(&mean, &t)
        );
        // Values exactly at the converged image score above any finite figure, as they should.
        let mut exact = PairedError::default();
        exact.add_slices(&t, &r1, &r2);
        assert!(exact.psnr_noise_removed() > truth + 10.0, "{}", exact.psnr_noise_removed());
    }

    #[test]
    fn display_clamps_and_encodes() {
        assert_eq!(display(-1.0), 0.0);
        assert!((display(2.0) - 1.0).abs() < 1e-6);
        assert_eq!(display(f32::NAN), 0.0);
        assert!((display(0.214_041) - 0.5).abs() < 1e-4);
    }
}
