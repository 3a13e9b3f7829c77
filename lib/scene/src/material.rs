//! Materials: glTF PBR metallic-roughness with the transmission, IOR, volume, specular and
//! emissive-strength extensions, and the object role they imply.

use crate::model::{AlphaMode, Material, TextureImage};
use crate::ObjectRole;

/// Converts a glTF material's factors and alpha mode (its textures are read by
/// [`crate::material_textures`]).
pub fn convert_material(m: &gltf::Material) -> Material {
    let pbr = m.pbr_metallic_roughness();
    let strength = m.emissive_strength().unwrap_or(1.0);
    let e = m.emissive_factor();
    let mut mat = Material {
        name: m
            .name()
            .map(str::to_owned)
            .unwrap_or_else(|| format!("material{}", m.index().unwrap_or(0))),
        base_color: pbr.base_color_factor(),
        base_color_texture: None,
        metallic: pbr.metallic_factor(),
        roughness: pbr.roughness_factor(),
        emissive: [e[0] * strength, e[1] * strength, e[2] * strength],
        transmission: m.transmission().map(|t| t.transmission_factor()).unwrap_or(0.0),
        ior: m.ior().unwrap_or(1.5),
        ..Material::default()
    };
    mat.alpha_mode = match m.alpha_mode() {
        gltf::material::AlphaMode::Opaque => AlphaMode::Opaque,
        gltf::material::AlphaMode::Mask => {
            AlphaMode::Mask { cutoff: m.alpha_cutoff().filter(|c| c.is_finite()).unwrap_or(0.5) }
        }
        gltf::material::AlphaMode::Blend => AlphaMode::Blend,
    };
    if let Some(v) = m.volume() {
        mat.attenuation_distance = v.attenuation_distance();
        mat.attenuation_color = v.attenuation_color();
    }
    if let Some(s) = m.specular() {
        mat.specular = s.specular_factor();
        mat.specular_color = s.specular_color_factor();
    }
    mat
}

/// `m` with its textures replaced by their means over all texels: base colour × the mean
/// base-colour texel, roughness × the mean G and metallic × the mean B of the
/// metallic-roughness texture, emission × the mean emissive texel; the normal map dropped.
/// What a per-object description (the role, the packed shading constants) reads.
pub fn mean_material(m: &Material, textures: &[TextureImage]) -> Material {
    let mean = |t: &Option<crate::TextureRef>| {
        t.and_then(|t| textures.get(t.texture)).map(TextureImage::mean)
    };
    let mut flat = m.clone();
    if let Some(c) = mean(&m.base_color_texture) {
        flat.base_color.iter_mut().zip(c).for_each(|(f, c)| *f *= c);
    }
    if let Some(c) = mean(&m.metallic_roughness_texture) {
        flat.roughness *= c[1];
        flat.metallic *= c[2];
    }
    if let Some(c) = mean(&m.emissive_texture) {
        flat.emissive.iter_mut().zip(c).for_each(|(f, c)| *f *= c);
    }
    flat.base_color_texture = None;
    flat.metallic_roughness_texture = None;
    flat.emissive_texture = None;
    flat.normal_texture = None;
    flat
}

/// Roughness below which any material is treated as a mirror-like reflector.
pub const MIRROR_ROUGHNESS: f32 = 0.1;

/// The role a material implies: transmission > 0 → refractive; metallic ≥ 0.5 with
/// roughness ≤ 0.3, or roughness < [`MIRROR_ROUGHNESS`] → reflective; else diffuse. A
/// textured material is judged by its [`mean_material`].
pub fn material_role(m: &Material) -> ObjectRole {
    if m.transmission > 0.0 {
        ObjectRole::Refractive
    } else if (m.metallic >= 0.5 && m.roughness <= 0.3) || m.roughness < MIRROR_ROUGHNESS {
        ObjectRole::Reflective
    } else {
        ObjectRole::Diffuse
    }
}

/// The role of an object with these materials: the most demanding one among them
/// (refractive over reflective over diffuse).
pub fn infer_role(materials: &[&Material]) -> ObjectRole {
    let rank = |r: ObjectRole| match r {
        ObjectRole::Diffuse => 0,
        ObjectRole::Reflective => 1,
        ObjectRole::Refractive => 2,
    };
    materials
        .iter()
        .map(|m| material_role(m))
        .max_by_key(|r| rank(*r))
        .unwrap_or(ObjectRole::Diffuse)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mat(metallic: f32, roughness: f32, transmission: f32) -> Material {
        Material { metallic, roughness, transmission, ..Material::default() }
    }

    #[test]
    fn role_inference_rules() {
        assert_eq!(material_role(&mat(0.0, 0.05, 1.0)), ObjectRole::Refractive);
        assert_eq!(material_role(&mat(1.0, 0.2, 0.0)), ObjectRole::Reflective);
        assert_eq!(material_role(&mat(1.0, 0.5, 0.0)), ObjectRole::Diffuse);
        assert_eq!(material_role(&mat(0.0, 0.05, 0.0)), ObjectRole::Reflective);
        assert_eq!(material_role(&mat(0.0, 0.8, 0.0)), ObjectRole::Diffuse);
        let (a, b) = (mat(0.0, 0.8, 0.0), mat(0.0, 0.0, 1.0));
        assert_eq!(infer_role(&[&a, &b]), ObjectRole::Refractive);
        assert_eq!(infer_role(&[]), ObjectRole::Diffuse);
    }

    #[test]
    fn a_textured_metal_is_judged_by_its_mean_texel() {
        // Factors 1 (as exporters write them) with a map of rough dielectric texels: the
        // object is not a mirror-like metal.
        let rough = TextureImage { width: 1, height: 1, texels: vec![[0.0, 0.9, 0.1, 1.0]] };
        let m = Material {
            metallic: 1.0,
            roughness: 1.0,
            metallic_roughness_texture: Some(crate::TextureRef::new(0)),
            ..Material::default()
        };
        let flat = mean_material(&m, &[rough]);
        assert!((flat.roughness - 0.9).abs() < 1e-6 && (flat.metallic - 0.1).abs() < 1e-6);
        assert_eq!(material_role(&flat), ObjectRole::Diffuse);
        let polished = TextureImage { width: 1, height: 1, texels: vec![[0.0, 0.2, 1.0, 1.0]] };
        assert_eq!(material_role(&mean_material(&m, &[polished])), ObjectRole::Reflective);
    }
}
