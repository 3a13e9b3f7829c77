//! The precision a player may hold a file's textures in (SPEC.md 6.6): the writer's
//! `predicted_psnr_db` (the coding error, against the ray-traced set) and `half_float_psnr_db`
//! (frames drawn from the decoded textures rounded to half floats against frames drawn from
//! them in full, through the same hardware model). Where rounding to 16 bits costs far less
//! than the coding already did, a player holds the textures in 16-bit floats: half the
//! memory and upload, frames within the file's own error.

use crate::model::Provenance;

/// The writer's predicted PSNR of the file against its ray-traced set (dB, display values
/// over the pixels the objects cover).
pub const PREDICTED_PSNR_SETTING: &str = "predicted_psnr_db";
/// The PSNR (dB, display values over the pixels the objects cover) of frames drawn from the
/// decoded textures rounded to half floats against frames drawn from them in full. Absent
/// where a texel lies beyond the half-float range (±65504).
pub const HALF_FLOAT_PSNR_SETTING: &str = "half_float_psnr_db";
/// The PSNR (dB, as [`HALF_FLOAT_PSNR_SETTING`]) of frames drawn from textures rebuilt from
/// level images rounded to half floats against frames drawn from the textures as decoded.
/// Absent where a level image's value lies beyond the half-float range.
pub const HALF_LEVEL_PSNR_SETTING: &str = "half_level_psnr_db";

/// How far below the coding error half-float rounding must lie for 16-bit textures: 20 dB,
/// its squared error at most 1 % of the coding error's, so that the played PSNR drops by at
/// most 10·log10(1.01) = 0.043 dB.
pub const HALF_FLOAT_MARGIN_DB: f64 = 20.0;

/// What a file records of its textures' precision.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HalfFloatFit {
    /// `half_float_psnr_db`.
    pub half_psnr_db: f64,
    /// `predicted_psnr_db`: the coding error.
    pub coding_psnr_db: f64,
}

impl HalfFloatFit {
    /// Both settings, where the provenance records them as finite decimal numbers.
    pub fn of(p: Option<&Provenance>) -> Option<HalfFloatFit> {
        HalfFloatFit::of_setting(p, HALF_FLOAT_PSNR_SETTING)
    }

    /// What the file records of its level images rounded to half floats
    /// ([`HALF_LEVEL_PSNR_SETTING`]) against its coding error.
    pub fn of_levels(p: Option<&Provenance>) -> Option<HalfFloatFit> {
        HalfFloatFit::of_setting(p, HALF_LEVEL_PSNR_SETTING)
    }

    fn of_setting(p: Option<&Provenance>, half: &str) -> Option<HalfFloatFit> {
        let number = |k: &str| {
            p.and_then(|p| p.setting(k))
                .and_then(|v| v.trim().parse::<f64>().ok())
                .filter(|v| v.is_finite())
        };
        Some(HalfFloatFit {
            half_psnr_db: number(half)?,
            coding_psnr_db: number(PREDICTED_PSNR_SETTING)?,
        })
    }

    /// How far (dB) half-float rounding lies below the coding error.
    pub fn margin_db(&self) -> f64 {
        self.half_psnr_db - self.coding_psnr_db
    }

    /// Whether 16-bit textures keep frames within the file's coding error
    /// ([`HALF_FLOAT_MARGIN_DB`]).
    pub fn allows_half(&self) -> bool {
        self.margin_db() >= HALF_FLOAT_MARGIN_DB
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn prov(settings: &[(&str, &str)]) -> Provenance {
        Provenance {
            settings: settings.iter().map(|(k, v)| (k.to_string(), v.to_string())).collect(),
            ..Default::default()
        }
    }

    #[test]
    fn half_floats_need_the_margin_over_the_coding_error() {
        let p = prov(&[(PREDICTED_PSNR_SETTING, "36.5"), (HALF_FLOAT_PSNR_SETTING, "56.5")]);
        let fit = HalfFloatFit::of(Some(&p)).unwrap();
        assert!(fit.allows_half());
        let p = prov(&[(PREDICTED_PSNR_SETTING, "36.5"), (HALF_FLOAT_PSNR_SETTING, "56.4")]);
        assert!(!HalfFloatFit::of(Some(&p)).unwrap().allows_half());
    }

    #[test]
    fn level_images_have_a_measurement_of_their_own() {
        let p = prov(&[(PREDICTED_PSNR_SETTING, "30"), (HALF_LEVEL_PSNR_SETTING, "52")]);
        assert_eq!(HalfFloatFit::of(Some(&p)), None);
        let fit = HalfFloatFit::of_levels(Some(&p)).unwrap();
        assert_eq!((fit.half_psnr_db, fit.allows_half()), (52.0, true));
    }

    #[test]
    fn a_missing_or_malformed_setting_records_nothing() {
        assert_eq!(HalfFloatFit::of(None), None);
        assert_eq!(HalfFloatFit::of(Some(&prov(&[(HALF_FLOAT_PSNR_SETTING, "80")]))), None);
        let p = prov(&[(PREDICTED_PSNR_SETTING, "30"), (HALF_FLOAT_PSNR_SETTING, "inf")]);
        assert_eq!(HalfFloatFit::of(Some(&p)), None);
        let p = prov(&[(PREDICTED_PSNR_SETTING, "30"), (HALF_FLOAT_PSNR_SETTING, "many")]);
        assert_eq!(HalfFloatFit::of(Some(&p)), None);
    }
}
