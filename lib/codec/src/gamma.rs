//! Gamma compensation (thesis 4.6, SPEC.md 8.4 step 3).
//!
//! Lighting layers are summed in linear space, but a display's gamma magnifies errors in dark
//! regions. Writers therefore encode `γ(L) = sign(L) · |L|^(1/g)` and players apply
//! `γ⁻¹(v) = sign(v) · |v|^g` after summing the pyramid levels and before summing layers in
//! linear space. With g = 1 both are the identity. `pis_format::reconstruct::{prepare,
//! finish}` call these functions, so the container and the codecs share one definition.
//! Values are floats throughout: bright specular layers above 1 are not clipped.

/// The display gamma writers compensate for unless told otherwise (pis-pack's and
/// pis-reencode's `--gamma`); [`uncompensate`] has a fast path for it.
pub const DEFAULT_GAMMA: f32 = 2.2;

/// `sign(v) · |v|^(1/g)` in place: the values a pyramid encodes for linear values `v`.
pub fn compensate(values: &mut [f32], g: f32) {
    if g != 1.0 {
        let inv = 1.0 / g;
        values.iter_mut().for_each(|v| *v = v.signum() * v.abs().powf(inv));
    }
}

/// `sign(v) · |v|^g` in place: linear values from decoded, summed pyramid values. The
/// writers' gamma, [`DEFAULT_GAMMA`] = 2.2, takes [`pow_11_5`], four times faster than
/// `powf` and closer to |v|^2.2, in the widest vectors the processor has
/// ([`uncompensate_default`]); other exponents take `powf`.
pub fn uncompensate(values: &mut [f32], g: f32) {
    if g == DEFAULT_GAMMA {
        uncompensate_default(values);
    } else if g != 1.0 {
        values.iter_mut().for_each(|v| *v = v.signum() * v.abs().powf(g));
    }
}

/// [`pow_11_5`] over `values`, compiled three times on x86-64 and chosen at run time: for
/// AVX-512, for AVX2 and for the baseline. The arithmetic is the same IEEE operations in
/// the same order at every width (Rust never fuses a multiply and an add), so the bits are
/// the same on every processor; AVX-512 takes a quarter of the baseline's time.
fn uncompensate_default(values: &mut [f32]) {
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx512f") {
            // SAFETY: the processor has AVX-512F, checked above.
            return unsafe { pow_11_5_avx512(values) };
        }
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the processor has AVX2, checked above.
            return unsafe { pow_11_5_avx2(values) };
        }
    }
    pow_11_5_each(values);
}

#[inline(always)]
fn pow_11_5_each(values: &mut [f32]) {
    values.iter_mut().for_each(|v| *v = pow_11_5(*v));
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
fn pow_11_5_avx512(values: &mut [f32]) {
    pow_11_5_each(values);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn pow_11_5_avx2(values: &mut [f32]) {
    pow_11_5_each(values);
}

/// `sign(v) · |v|^(11/5)` as |v|² · |v|^(1/5), the fifth root by three Newton steps from a
/// guess made of the exponent bits (y ← 0.8 y + 0.2 |v| / y⁴): within 2.4e-7 of the exact
/// value relative to it for |v| from 1e-12 to 1e6, where `powf(2.2f32)` is within 1.4e-6.
/// Branch-free apart from infinity, so the loop over a level image vectorizes.
#[inline(always)]
pub fn pow_11_5(v: f32) -> f32 {
    let a = v.abs();
    let mut y = f32::from_bits(a.to_bits() / 5 + 0x32CC_CCCD);
    for _ in 0..3 {
        let y2 = y * y;
        y = 0.8 * y + 0.2 * a / (y2 * y2);
    }
    let r = if a == f32::INFINITY { a } else { a * a * y };
    r.copysign(v)
}

/// Mean squared error in linear space of `encoded` (gamma-compensated values as decoded)
/// against the linear `reference`: what a level's allocation costs on screen before the
/// display gamma.
pub fn linear_mse(reference: &[f32], encoded: &[f32], g: f32) -> f64 {
    let mut lin = encoded.to_vec();
    uncompensate(&mut lin, g);
    crate::mse(reference, &lin)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_keeps_sign_and_bright_values() {
        let orig = [0.0f32, 0.01, -0.2, 1.0, 7.5];
        let mut v = orig;
        compensate(&mut v, 2.2);
        assert!(v[1] > 0.1 && v[2] < 0.0 && v[4] > 1.0);
        uncompensate(&mut v, 2.2);
        for (a, b) in orig.iter().zip(&v) {
            assert!((a - b).abs() <= 1e-5 * a.abs().max(1.0));
        }
        assert!(
            linear_mse(
                &orig,
                &{
                    let mut e = orig;
                    compensate(&mut e, 2.2);
                    e
                },
                2.2
            ) < 1e-9
        );
    }

    #[test]
    fn the_fast_inverse_gamma_matches_the_exact_power() {
        // Every 97th float from 1e-12 to 1e6, and the edges; the exponent 11/5 in f64 as
        // the exact value.
        let (lo, hi) = (1e-12f32.to_bits(), 1e6f32.to_bits());
        let mut worst = 0f64;
        for b in (lo..hi).step_by(97).chain([lo, hi]) {
            let a = f32::from_bits(b);
            let exact = (a as f64).powf(2.2);
            worst = worst.max(((pow_11_5(a) as f64 - exact) / exact).abs());
            assert_eq!(pow_11_5(-a), -pow_11_5(a));
        }
        assert!(worst < 3e-7, "worst relative error {worst:e}");
        assert_eq!(pow_11_5(0.0), 0.0);
        assert!(pow_11_5(-0.0).is_sign_negative());
        assert_eq!(pow_11_5(1.0), 1.0);
        assert_eq!(pow_11_5(f32::INFINITY), f32::INFINITY);
        assert_eq!(pow_11_5(f32::NEG_INFINITY), f32::NEG_INFINITY);
        assert_eq!(pow_11_5(f32::MAX), f32::INFINITY);
        assert!(pow_11_5(f32::NAN).is_nan());
        assert_eq!(pow_11_5(1e-40), 0.0);
        // uncompensate takes it for 2.2 and powf for any other exponent.
        let mut v = [0.3f32, -2.0];
        uncompensate(&mut v, 2.2);
        assert_eq!(v, [pow_11_5(0.3), pow_11_5(-2.0)]);
        let mut w = [0.3f32, -2.0];
        uncompensate(&mut w, 1.8);
        assert_eq!(w, [0.3f32.powf(1.8), -(2.0f32.powf(1.8))]);
    }

    /// SPEC.md 8.4 step 3 states the inverse gamma for g = 2.2 as f32 operations; written
    /// from that text, it gives `uncompensate`'s bits for every 4099th finite float.
    #[test]
    fn the_default_inverse_gamma_is_the_arithmetic_the_spec_states() {
        let spec = |v: f32| -> f32 {
            let a = v.abs();
            let p = if a == f32::INFINITY {
                a
            } else {
                let mut y = f32::from_bits(a.to_bits() / 5 + 0x32CC_CCCD);
                let (c08, c02) = (f32::from_bits(0x3F4C_CCCD), f32::from_bits(0x3E4C_CCCD));
                for _ in 0..3 {
                    let yy = y * y;
                    y = (c08 * y) + ((c02 * a) / (yy * yy));
                }
                (a * a) * y
            };
            if v.is_sign_negative() {
                -p
            } else {
                p
            }
        };
        assert_eq!(DEFAULT_GAMMA.to_bits(), 0x400C_CCCD);
        let values: Vec<f32> = (0..0x7F80_0000u32)
            .step_by(4099)
            .chain([0x7F80_0000])
            .flat_map(|b| [f32::from_bits(b), -f32::from_bits(b)])
            .collect();
        // One value at a time (the vector loops' scalar tail) and the whole slice at once
        // (their vector bodies, at the processor's widest width).
        let mut whole = values.clone();
        uncompensate(&mut whole, DEFAULT_GAMMA);
        for (&v, w) in values.iter().zip(&whole) {
            let mut x = [v];
            uncompensate(&mut x, DEFAULT_GAMMA);
            assert_eq!(x[0].to_bits(), spec(v).to_bits(), "{v:e}");
            assert_eq!(w.to_bits(), spec(v).to_bits(), "{v:e} in a slice");
        }
    }

    /// Every width the processor has gives the baseline's bits.
    #[cfg(target_arch = "x86_64")]
    #[test]
    fn the_vector_widths_give_the_same_bits() {
        let values: Vec<f32> =
            (0..0x7F80_0000u32).step_by(7919).map(|b| f32::from_bits(b ^ (b << 31))).collect();
        let mut base = values.clone();
        pow_11_5_each(&mut base);
        let same = |w: &[f32]| w.iter().zip(&base).all(|(a, b)| a.to_bits() == b.to_bits());
        if std::arch::is_x86_feature_detected!("avx2") {
            let mut w = values.clone();
            // SAFETY: the processor has AVX2, checked above.
            unsafe { pow_11_5_avx2(&mut w) };
            assert!(same(&w), "AVX2");
        }
        if std::arch::is_x86_feature_detected!("avx512f") {
            let mut w = values.clone();
            // SAFETY: the processor has AVX-512F, checked above.
            unsafe { pow_11_5_avx512(&mut w) };
            assert!(same(&w), "AVX-512");
        }
    }

    #[test]
    fn compensation_spends_error_on_dark_values_less() {
        // The same coding error (±0.01 in the encoded domain) costs less linear error in
        // dark regions than it would in linear storage.
        let dark = [0.01f32; 4];
        let mut enc = dark;
        compensate(&mut enc, 2.2);
        enc.iter_mut().for_each(|v| *v += 0.01);
        let gamma_err = linear_mse(&dark, &enc, 2.2);
        assert!(gamma_err < 0.01f64 * 0.01);
    }
}
