//! glTF extensions: which PIS implements, which it may ignore, and what it says about the
//! others — a warning naming each one a glTF uses, an error for one it requires.

use std::path::Path;

use crate::SceneError;

/// Extensions PIS reads (docs/SCENE.md says how far).
pub const IMPLEMENTED: &[&str] = &[
    "KHR_lights_punctual",
    "KHR_materials_emissive_strength",
    "KHR_materials_ior",
    "KHR_materials_specular",
    "KHR_materials_transmission",
    "KHR_materials_volume",
    "KHR_texture_transform",
];

/// Extensions that change nothing in an image: ignored without a word, required or not.
pub const WITHOUT_EFFECT: &[&str] = &["KHR_xmp", "KHR_xmp_json_ld"];

/// Extensions PIS does not implement that a glTF may require and still be rendered as its
/// author meant by default: `KHR_materials_variants` (the primitives' own materials are the
/// default variant). Warned of like any other unimplemented extension.
pub const IGNORABLE_WHEN_REQUIRED: &[&str] = &["KHR_materials_variants"];

/// An error naming the first extension of `extensionsRequired` that PIS neither implements
/// nor may ignore.
pub(crate) fn check_required(path: &Path, required: &[String]) -> Result<(), SceneError> {
    let known = |e: &str| {
        IMPLEMENTED.contains(&e)
            || WITHOUT_EFFECT.contains(&e)
            || IGNORABLE_WHEN_REQUIRED.contains(&e)
    };
    match required.iter().enumerate().find(|(_, e)| !known(e)) {
        Some((i, e)) => Err(SceneError::unsupported(
            path,
            format!("extensionsRequired[{i}]"),
            format!("the glTF requires extension {e}, which PIS does not implement"),
        )),
        None => Ok(()),
    }
}

/// One warning per extension named in `used` (extensionsUsed, and any other place the caller
/// found extensions in) that PIS does not implement, in the order first named.
pub(crate) fn unimplemented_warnings<'a>(used: impl IntoIterator<Item = &'a str>) -> Vec<String> {
    let mut seen: Vec<&str> = Vec::new();
    for e in used {
        if !IMPLEMENTED.contains(&e) && !WITHOUT_EFFECT.contains(&e) && !seen.contains(&e) {
            seen.push(e);
        }
    }
    seen.into_iter()
        .map(|e| {
            format!("the glTF uses extension {e}, which PIS does not implement: it is ignored")
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unsupported_extension_is_named_once() {
        let used = [
            "KHR_materials_clearcoat",
            "KHR_texture_transform",
            "KHR_materials_sheen",
            "KHR_materials_clearcoat",
            "KHR_xmp_json_ld",
        ];
        let w = unimplemented_warnings(used);
        assert_eq!(w.len(), 2, "{w:?}");
        assert!(
            w[0].contains("KHR_materials_clearcoat") && w[1].contains("KHR_materials_sheen"),
            "{w:?}"
        );
    }

    #[test]
    fn required_extension_not_implemented_is_an_error_naming_it() {
        let path = Path::new("a.gltf");
        let ok: Vec<String> =
            ["KHR_materials_volume", "KHR_texture_transform", "KHR_materials_variants"]
                .map(String::from)
                .to_vec();
        assert!(check_required(path, &ok).is_ok());
        let bad: Vec<String> =
            ["KHR_materials_ior", "KHR_draco_mesh_compression"].map(String::from).to_vec();
        let e = check_required(path, &bad).unwrap_err().to_string();
        assert!(
            e.contains("extensionsRequired[1]") && e.contains("KHR_draco_mesh_compression"),
            "{e}"
        );
    }
}
