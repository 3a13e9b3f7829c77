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
/// level images held in 16 bits a value ([`Level16`]) against frames drawn from the textures
/// as decoded. Absent where a level image holds a value that is not finite.
pub const LEVEL16_PSNR_SETTING: &str = "level16_psnr_db";

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

    /// What the file records of its level images held in 16 bits a value
    /// ([`LEVEL16_PSNR_SETTING`]) against its coding error.
    pub fn of_levels(p: Option<&Provenance>) -> Option<HalfFloatFit> {
        HalfFloatFit::of_setting(p, LEVEL16_PSNR_SETTING)
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

/// A level image held in 16 bits a value (SPEC.md 6.6 `level16_psnr_db`): each value v as
/// q = round((v − lo) / step) in 0..=65535, read back as lo + q · step, with lo the image's
/// least value and step = (its greatest − lo) / 65535 (0 for a constant image). The error is
/// at most step / 2 wherever the value lies: a pyramid's level images are gamma-compensated
/// (display-like) values of a small range, which a half float would round relative to their
/// size instead.
#[derive(Clone, Debug, PartialEq)]
pub struct Level16 {
    pub lo: f32,
    pub step: f32,
    pub q: Vec<u16>,
}

impl Level16 {
    /// `values` in 16 bits; `None` where one is not finite.
    pub fn of(values: &[f32]) -> Option<Level16> {
        let (lo, hi) =
            values.iter().try_fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), &v| {
                v.is_finite().then_some((a.min(v), b.max(v)))
            })?;
        if values.is_empty() {
            return Some(Level16 { lo: 0.0, step: 0.0, q: Vec::new() });
        }
        let step = (hi - lo) / 65535.0;
        let q = values
            .iter()
            .map(|&v| match step > 0.0 {
                true => ((v - lo) / step).round().clamp(0.0, 65535.0) as u16,
                false => 0,
            })
            .collect();
        Some(Level16 { lo, step, q })
    }

    /// Value `i` as read back: lo + q · step.
    pub fn value(&self, i: usize) -> f32 {
        self.lo + self.q[i] as f32 * self.step
    }

    /// Every value as read back.
    pub fn values(&self) -> Vec<f32> {
        (0..self.q.len()).map(|i| self.value(i)).collect()
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
    fn sixteen_bits_hold_a_level_image_within_half_a_step() {
        let values: Vec<f32> = (0..1000).map(|k| ((k * 37 % 1000) as f32 * 0.0021) - 0.7).collect();
        let l = Level16::of(&values).unwrap();
        assert_eq!((l.lo, l.q.iter().max(), l.q.iter().min()), (-0.7, Some(&65535), Some(&0)));
        let worst = values.iter().zip(l.values()).map(|(a, b)| (a - b).abs()).fold(0.0, f32::max);
        assert!(worst <= l.step * 0.5 + 1e-6, "{worst} against a step of {}", l.step);
        let constant = Level16::of(&[0.25; 5]).unwrap();
        assert_eq!(constant.values(), vec![0.25; 5]);
        assert_eq!(Level16::of(&[0.0, f32::NAN]), None);
        assert_eq!(Level16::of(&[]).unwrap().values(), Vec::<f32>::new());
    }

    #[test]
    fn level_images_have_a_measurement_of_their_own() {
        let p = prov(&[(PREDICTED_PSNR_SETTING, "30"), (LEVEL16_PSNR_SETTING, "52")]);
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
