//! Gamma compensation (thesis 4.6, SPEC.md 8.4 step 3).
//!
//! Lighting layers are summed in linear space, but a display's gamma magnifies errors in dark
//! regions. Writers therefore encode `γ(L) = sign(L) · |L|^(1/g)` and players apply
//! `γ⁻¹(v) = sign(v) · |v|^g` after summing the pyramid levels and before summing layers in
//! linear space. With g = 1 both are the identity. `pis_format::reconstruct::{prepare,
//! finish}` call these functions, so the container and the codecs share one definition.
//! Values are floats throughout: bright specular layers above 1 are not clipped.

/// `sign(v) · |v|^(1/g)` in place: the values a pyramid encodes for linear values `v`.
pub fn compensate(values: &mut [f32], g: f32) {
    if g != 1.0 {
        let inv = 1.0 / g;
        values
            .iter_mut()
            .for_each(|v| *v = v.signum() * v.abs().powf(inv));
    }
}

/// `sign(v) · |v|^g` in place: linear values from decoded, summed pyramid values.
pub fn uncompensate(values: &mut [f32], g: f32) {
    if g != 1.0 {
        values
            .iter_mut()
            .for_each(|v| *v = v.signum() * v.abs().powf(g));
    }
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
