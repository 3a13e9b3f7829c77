//! Materials at a surface point: glTF metallic-roughness with transmission, ior, volume and
//! specular, reduced to the three lobes the tracer samples. Textures multiply their factors:
//! base colour, metallic-roughness (roughness in G, metallic in B) and emission.
//!
//! The model is additive, so the diffuse lobe stays view-independent (thesis 3.1):
//! f = diffuse · (1 − metallic)(1 − transmission) / π  +  Schlick-Fresnel GGX specular
//! + a smooth dielectric transmission lobe of weight (1 − metallic) · transmission.

use crate::textures::lookup;
use glam::{Vec2, Vec3};
pub use pis_scene::optics::{fresnel_dielectric, reflect, refract, schlick};
use pis_scene::{AlphaMode, Material, Scene};

pub use crate::textures::sample_texture;

/// Below this GGX alpha a specular lobe is treated as a perfect mirror.
pub const MIRROR_ALPHA: f32 = 1e-3;

/// A material evaluated at one surface point.
#[derive(Clone, Copy, Debug)]
pub struct ShadingMaterial {
    /// Base colour (factor × texture), linear RGB.
    pub base: Vec3,
    /// Lambertian albedo of the diffuse lobe.
    pub diffuse: Vec3,
    /// Reflectance at normal incidence of the dielectric part of the specular lobe
    /// (((ior − 1)/(ior + 1))² × specular colour).
    pub f0_dielectric: Vec3,
    /// Metallic factor (blends the dielectric and the metal Fresnel).
    pub metallic: f32,
    /// KHR_materials_specular factor: scales the dielectric Fresnel.
    pub specular: f32,
    /// GGX alpha (roughness²).
    pub alpha: f32,
    /// Weight of the dielectric transmission lobe, in [0, 1].
    pub transmission: f32,
    pub ior: f32,
    /// Beer absorption coefficient per unit length (0 = clear).
    pub sigma_a: Vec3,
    pub emission: Vec3,
}

impl ShadingMaterial {
    /// Evaluates `material` where both texture-coordinate sets are `uv`.
    pub fn at(scene: &Scene, material: &Material, uv: Vec2) -> ShadingMaterial {
        ShadingMaterial::at_uvs(scene, material, [uv, uv])
    }

    /// Evaluates `material` at a point whose texture-coordinate sets are `uvs` (TEXCOORD_0,
    /// TEXCOORD_1).
    pub fn at_uvs(scene: &Scene, material: &Material, uvs: [Vec2; 2]) -> ShadingMaterial {
        let mut base =
            Vec3::new(material.base_color[0], material.base_color[1], material.base_color[2]);
        if let Some(t) = lookup(scene, material.base_color_texture.as_ref(), uvs) {
            base *= t.truncate();
        }
        let (mut metallic, mut roughness) = (material.metallic, material.roughness);
        if let Some(t) = lookup(scene, material.metallic_roughness_texture.as_ref(), uvs) {
            roughness *= t.y;
            metallic *= t.z;
        }
        let mut emission = Vec3::from(material.emissive);
        if let Some(t) = lookup(scene, material.emissive_texture.as_ref(), uvs) {
            emission *= t.truncate();
        }
        let metallic = metallic.clamp(0.0, 1.0);
        let transmission = material.transmission.clamp(0.0, 1.0) * (1.0 - metallic);
        let ior = if material.ior.is_finite() && material.ior >= 1.0 { material.ior } else { 1.5 };
        let r0 = ((ior - 1.0) / (ior + 1.0)).powi(2);
        let dielectric_f0 = (Vec3::from(material.specular_color) * r0).min(Vec3::ONE);
        let roughness = roughness.clamp(0.0, 1.0);
        let sigma_a =
            if material.attenuation_distance.is_finite() && material.attenuation_distance > 0.0 {
                Vec3::from(material.attenuation_color)
                    .max(Vec3::splat(1e-6))
                    .min(Vec3::ONE)
                    .map(|c| -c.ln())
                    / material.attenuation_distance
            } else {
                Vec3::ZERO
            };
        ShadingMaterial {
            base,
            diffuse: base * (1.0 - metallic) * (1.0 - transmission),
            f0_dielectric: dielectric_f0,
            metallic,
            specular: material.specular.clamp(0.0, 1.0),
            alpha: roughness * roughness,
            transmission,
            ior,
            sigma_a,
            emission,
        }
    }

    /// Fresnel reflectance of the opaque specular lobe at cosine `cos_theta`:
    /// mix(specular · Schlick(f0_dielectric), Schlick(base), metallic) (KHR_materials_specular).
    pub fn fresnel(&self, cos_theta: f32) -> Vec3 {
        schlick(self.f0_dielectric, cos_theta) * ((1.0 - self.metallic) * self.specular)
            + schlick(self.base, cos_theta) * self.metallic
    }

    /// True when the specular lobe is a perfect mirror.
    pub fn is_mirror(&self) -> bool {
        self.alpha < MIRROR_ALPHA
    }
}

/// Whether `material` lets rays through some of its surface: alpha mode MASK or BLEND with
/// a base-colour texture, or with a factor alpha that is not opaque.
pub fn has_holes(material: &Material) -> bool {
    let a = material.base_color[3];
    match material.alpha_mode {
        AlphaMode::Opaque => false,
        AlphaMode::Mask { cutoff } => material.base_color_texture.is_some() || a < cutoff,
        AlphaMode::Blend => material.base_color_texture.is_some() || a < 1.0,
    }
}

/// The coverage of `material` at a point with texture-coordinate sets `uvs`: base-colour
/// alpha (factor × texture), in [0, 1].
pub fn alpha(scene: &Scene, material: &Material, uvs: [Vec2; 2]) -> f32 {
    let t = lookup(scene, material.base_color_texture.as_ref(), uvs).map_or(1.0, |t| t.w);
    let a = material.base_color[3] * t;
    if a.is_finite() {
        a.clamp(0.0, 1.0)
    } else {
        1.0
    }
}

/// Whether a ray passes through `material` where its coverage is `alpha`: below the cutoff
/// for MASK; for BLEND with probability 1 − alpha, decided by `u`, uniform in [0, 1).
pub fn passes(material: &Material, alpha: f32, u: f32) -> bool {
    match material.alpha_mode {
        AlphaMode::Opaque => false,
        AlphaMode::Mask { cutoff } => alpha < cutoff,
        AlphaMode::Blend => u >= alpha,
    }
}

/// The tangent-space normal `material`'s normal map gives at a point with texture-coordinate
/// sets `uvs`: texel × 2 − 1 with X and Y times the map's scale, unit length; `None` without
/// a normal map.
pub fn mapped_normal(scene: &Scene, material: &Material, uvs: [Vec2; 2]) -> Option<Vec3> {
    let t = lookup(scene, material.normal_texture.as_ref(), uvs)?;
    let s = material.normal_scale;
    let n = Vec3::new((t.x * 2.0 - 1.0) * s, (t.y * 2.0 - 1.0) * s, t.z * 2.0 - 1.0);
    n.try_normalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn texture(texels: Vec<[f32; 4]>) -> Scene {
        let width = texels.len() as u32;
        Scene {
            textures: vec![pis_scene::TextureImage { width, height: 1, texels }],
            ..Scene::default()
        }
    }

    #[test]
    fn emissive_map_modulates_emissive_factor() {
        // Emissive factor 1 with a map black on its left half: the left does not glow.
        let s = texture(vec![[0.0, 0.0, 0.0, 1.0], [1.0, 0.5, 0.25, 1.0]]);
        let m = Material {
            emissive: [1.0; 3],
            emissive_texture: Some(pis_scene::TextureRef::new(0)),
            ..Material::default()
        };
        assert_eq!(ShadingMaterial::at(&s, &m, Vec2::new(0.25, 0.5)).emission, Vec3::ZERO);
        assert_eq!(
            ShadingMaterial::at(&s, &m, Vec2::new(0.75, 0.5)).emission,
            Vec3::new(1.0, 0.5, 0.25)
        );
    }

    #[test]
    fn metallic_roughness_map_is_read_per_texel() {
        // Factors 1 with a map of a rough dielectric texel beside a polished metal one.
        let s = texture(vec![[0.0, 0.9, 0.0, 1.0], [0.0, 0.1, 1.0, 1.0]]);
        let m = Material {
            metallic: 1.0,
            roughness: 1.0,
            metallic_roughness_texture: Some(pis_scene::TextureRef::new(0)),
            ..Material::default()
        };
        let left = ShadingMaterial::at(&s, &m, Vec2::new(0.25, 0.5));
        let right = ShadingMaterial::at(&s, &m, Vec2::new(0.75, 0.5));
        assert_eq!(left.metallic, 0.0);
        assert!((left.alpha - 0.81).abs() < 1e-6);
        assert_eq!(right.metallic, 1.0);
        assert!((right.alpha - 0.01).abs() < 1e-6);
    }

    #[test]
    fn alpha_modes_decide_which_rays_pass() {
        let s = texture(vec![[1.0, 1.0, 1.0, 0.2], [1.0, 1.0, 1.0, 0.8]]);
        let tex = Some(pis_scene::TextureRef::new(0));
        let mask = Material {
            base_color_texture: tex,
            alpha_mode: AlphaMode::Mask { cutoff: 0.5 },
            ..Material::default()
        };
        let (low, high) = ([Vec2::new(0.25, 0.5); 2], [Vec2::new(0.75, 0.5); 2]);
        assert!(has_holes(&mask));
        assert!(passes(&mask, alpha(&s, &mask, low), 0.0));
        assert!(!passes(&mask, alpha(&s, &mask, high), 0.99));
        let blend = Material { alpha_mode: AlphaMode::Blend, ..mask.clone() };
        assert!(
            passes(&blend, alpha(&s, &blend, high), 0.9)
                && !passes(&blend, alpha(&s, &blend, high), 0.7)
        );
        let opaque = Material { alpha_mode: AlphaMode::Opaque, ..mask.clone() };
        assert!(!has_holes(&opaque) && !passes(&opaque, 0.0, 0.5));
        // Without a texture, an opaque factor makes no holes.
        assert!(!has_holes(&Material { alpha_mode: AlphaMode::Blend, ..Material::default() }));
    }
}
