//! The lens model of lens objects (SPEC.md 6.6): `lens_model.<object name>` provenance
//! settings. Hybrid rendering traces the paths through a refractive object at its vertices
//! (section 9); the setting says which paths and how many terms the writer solved the
//! object's shells for, so that the player draws the same: the greedy two paths (thesis
//! 6.2, also without the setting) or the ray tree's terms.

use crate::model::{ObjectRole, Provenance};
use crate::object_setting::refractive_settings;

/// The settings' key prefix; the object's name follows.
pub const LENS_MODEL_PREFIX: &str = "lens_model.";

/// The most terms a ray tree has.
pub const MAX_LENS_TERMS: u8 = 4;

/// How a lens object's paths are followed and grouped into terms.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum LensTerms {
    /// Thesis 6.2: the reflection-first and refraction-first paths, each following the
    /// larger Fresnel branch.
    #[default]
    Greedy,
    /// The ray tree: both branches while a path carries at least `min_weight` of the light,
    /// grouped into `terms` terms (2 to [`MAX_LENS_TERMS`]).
    Tree { min_weight: f32, terms: u8 },
}

impl LensTerms {
    /// The setting's value: `greedy`, or `tree,MIN_WEIGHT,TERMS`.
    pub fn value(self) -> String {
        match self {
            LensTerms::Greedy => "greedy".to_string(),
            LensTerms::Tree { min_weight, terms } => format!("tree,{min_weight},{terms}"),
        }
    }

    fn parse(v: &str) -> Option<LensTerms> {
        if v.trim() == "greedy" {
            return Some(LensTerms::Greedy);
        }
        let parts: Vec<&str> = v.split(',').map(str::trim).collect();
        let [name, weight, terms] = parts[..] else { return None };
        let min_weight = weight.parse::<f32>().ok().filter(|w| *w > 0.0 && *w <= 1.0)?;
        let terms = terms.parse::<u8>().ok().filter(|t| (2..=MAX_LENS_TERMS).contains(t))?;
        (name == "tree").then_some(LensTerms::Tree { min_weight, terms })
    }
}

/// The setting recording `object`'s lens model.
pub fn lens_model_setting(object: &str, model: LensTerms) -> (String, String) {
    (format!("{LENS_MODEL_PREFIX}{object}"), model.value())
}

/// Per object (`objects`: each object's name and role, in file order), the lens model its
/// setting records (greedy without one) — rule 9005: an error naming what is wrong for a
/// setting that names no refractive object, or whose value is neither `greedy` nor
/// `tree,W,N` with W a decimal number in (0, 1] and N an integer from 2 to 4.
pub fn lens_models(
    p: Option<&Provenance>,
    objects: &[(&str, ObjectRole)],
) -> Result<Vec<LensTerms>, String> {
    refractive_settings(
        p,
        objects,
        LENS_MODEL_PREFIX,
        LensTerms::Greedy,
        LensTerms::parse,
        "is neither \"greedy\" nor \"tree,W,N\" (W in (0, 1], N 2 to 4)",
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::filter::tests::prov;

    #[test]
    fn lens_models_round_trip_and_bad_ones_are_named() {
        let objects = [("Cup", ObjectRole::Refractive), ("Table", ObjectRole::Diffuse)];
        let tree = LensTerms::Tree { min_weight: 0.01, terms: 4 };
        let (k, v) = lens_model_setting("Cup", tree);
        assert_eq!((k.as_str(), v.as_str()), ("lens_model.Cup", "tree,0.01,4"));
        assert_eq!(
            lens_models(Some(&prov(&[(k.as_str(), v.as_str())])), &objects),
            Ok(vec![tree, LensTerms::Greedy])
        );
        assert_eq!(lens_models(None, &objects), Ok(vec![LensTerms::Greedy; 2]));
        assert_eq!(
            lens_models(Some(&prov(&[("lens_model.Cup", " tree , 1 ,2 ")])), &objects),
            Ok(vec![LensTerms::Tree { min_weight: 1.0, terms: 2 }, LensTerms::Greedy])
        );
        for (key, value, why) in [
            ("lens_model.Table", "greedy", "not refractive"),
            ("lens_model.Lamp", "greedy", "no object"),
            ("lens_model.Cup", "tree", "neither"),
            ("lens_model.Cup", "tree,0,4", "neither"),
            ("lens_model.Cup", "tree,0.5,5", "neither"),
            ("lens_model.Cup", "tree,0.5,1", "neither"),
            ("lens_model.Cup", "tree,NaN,3", "neither"),
            ("lens_model.Cup", "bush,0.5,3", "neither"),
            ("lens_model.Cup", "tree,0.5,3,1", "neither"),
        ] {
            let err = lens_models(Some(&prov(&[(key, value)])), &objects).unwrap_err();
            assert!(err.contains(why), "{key}={value}: {err}");
        }
    }
}
