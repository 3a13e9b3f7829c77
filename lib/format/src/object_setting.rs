//! Provenance settings about one refractive object (SPEC.md 6.6): `PREFIX<object name>` =
//! value, as `transmission_tint.` ([`crate::tint`]) and `lens_model.`
//! ([`crate::lens_model`]) record them.

use crate::model::{ObjectRole, Provenance};

/// Per object (`objects`: each object's name and role, in file order), the value its
/// `prefix` setting records (`default` without one), read by `parse`: an error naming what
/// is wrong for a setting that names no object or no refractive one, or whose value `parse`
/// refuses (the error saying the value `is` what `expected` says).
pub(crate) fn refractive_settings<T: Clone>(
    p: Option<&Provenance>,
    objects: &[(&str, ObjectRole)],
    prefix: &str,
    default: T,
    parse: impl Fn(&str) -> Option<T>,
    expected: &str,
) -> Result<Vec<T>, String> {
    let mut out = vec![default; objects.len()];
    let Some(p) = p else { return Ok(out) };
    for (k, v) in &p.settings {
        let Some(name) = k.strip_prefix(prefix) else { continue };
        let o = objects
            .iter()
            .position(|o| o.0 == name)
            .ok_or_else(|| format!("{k}: no object is named {name:?}"))?;
        if objects[o].1 != ObjectRole::Refractive {
            return Err(format!("{k}: object {name:?} is not refractive"));
        }
        out[o] = parse(v).ok_or_else(|| format!("{k} {v:?} {expected}"))?;
    }
    Ok(out)
}
