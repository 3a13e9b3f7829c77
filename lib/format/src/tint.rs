//! The transmission tint of lens objects (SPEC.md 6.6): `transmission_tint.<object name>`
//! provenance settings. A refractive object's material may colour the light it transmits
//! (its base colour, multiplied into the refraction path's F·G at every entry through its
//! surface, as pis-trace shades it); the player's hybrid rendering applies the same tint.

use crate::model::{ObjectRole, Provenance};
use crate::object_setting::refractive_settings;

/// The settings' key prefix; the object's name follows.
pub const TINT_PREFIX: &str = "transmission_tint.";

/// The setting recording `object`'s tint `rgb` (decimal text, `r,g,b`).
pub fn tint_setting(object: &str, rgb: [f32; 3]) -> (String, String) {
    (format!("{TINT_PREFIX}{object}"), format!("{},{},{}", rgb[0], rgb[1], rgb[2]))
}

/// Per object (`objects`: each object's name and role, in file order), the tint its setting
/// records (white without one) — rule 9004: an error naming what is wrong for a setting that
/// names no refractive object, or whose value is not three comma-separated decimal numbers
/// in [0, 1].
pub fn tints(
    p: Option<&Provenance>,
    objects: &[(&str, ObjectRole)],
) -> Result<Vec<[f32; 3]>, String> {
    refractive_settings(
        p,
        objects,
        TINT_PREFIX,
        [1.0; 3],
        parse_tint,
        "is not three decimal numbers in [0, 1] separated by commas",
    )
}

/// `r,g,b`, each a decimal number in [0, 1].
fn parse_tint(v: &str) -> Option<[f32; 3]> {
    let parts: Vec<&str> = v.split(',').collect();
    let rgb: Vec<f32> = parts
        .iter()
        .filter_map(|s| s.trim().parse::<f32>().ok())
        .filter(|x| x.is_finite() && (0.0..=1.0).contains(x))
        .collect();
    (parts.len() == 3 && rgb.len() == 3).then(|| [rgb[0], rgb[1], rgb[2]])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::filter::tests::prov;

    #[test]
    fn tints_round_trip_and_bad_ones_are_named() {
        let objects = [("Cup", ObjectRole::Refractive), ("Table", ObjectRole::Diffuse)];
        let (k, v) = tint_setting("Cup", [0.7, 0.9, 0.75]);
        assert_eq!(
            tints(Some(&prov(&[(k.as_str(), v.as_str())])), &objects),
            Ok(vec![[0.7, 0.9, 0.75], [1.0; 3]])
        );
        assert_eq!(tints(None, &objects), Ok(vec![[1.0; 3]; 2]));
        // The number syntax of SPEC.md 6.6: white space around fields, signs, a point with
        // digits on either side, exponents; −0 lies in [0, 1].
        let (k, _) = tint_setting("Cup", [0.0; 3]);
        assert_eq!(
            tints(Some(&prov(&[(k.as_str(), " .5 ,1., +5E-1\t")])), &objects),
            Ok(vec![[0.5, 1.0, 0.5], [1.0; 3]])
        );
        let t = tints(Some(&prov(&[(k.as_str(), "-0,0,0")])), &objects).unwrap();
        assert!(t[0][0] == 0.0 && t[0][0].is_sign_negative());
        for (key, value, why) in [
            ("transmission_tint.Table", "1,1,1", "not refractive"),
            ("transmission_tint.Lamp", "1,1,1", "no object"),
            ("transmission_tint.Cup", "1,1", "three decimal"),
            ("transmission_tint.Cup", "1,1,2", "three decimal"),
            ("transmission_tint.Cup", "1,NaN,1", "three decimal"),
            ("transmission_tint.Cup", "1,1,1,1", "three decimal"),
            ("transmission_tint.Cup", "0x1,0,0", "three decimal"),
            ("transmission_tint.Cup", "1e,0,0", "three decimal"),
            ("transmission_tint.Cup", "inf,0,0", "three decimal"),
            ("transmission_tint.Cup", "1_0,0,0", "three decimal"),
        ] {
            let e = tints(Some(&prov(&[(key, value)])), &objects).unwrap_err();
            assert!(e.contains(why), "{key}={value}: {e}");
        }
    }
}
