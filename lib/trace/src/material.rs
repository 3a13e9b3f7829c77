//! Materials at a surface point: glTF metallic-roughness with transmission, ior, volume and
//! specular, reduced to the three lobes the tracer samples.
//!
//! The model is additive, so the diffuse lobe stays view-independent (thesis 3.1):
//! f = diffuse · (1 − metallic)(1 − transmission) / π  +  Schlick-Fresnel GGX specular
//! + a smooth dielectric transmission lobe of weight (1 − metallic) · transmission.

use glam::{Vec2, Vec3};
use pis_scene::{Material, Scene, TextureImage};

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
    /// Evaluates `material` at texture coordinate `uv`.
    pub fn at(scene: &Scene, material: &Material, uv: Vec2) -> ShadingMaterial {
        let mut base = Vec3::new(material.base_color[0], material.base_color[1], material.base_color[2]);
        if let Some(tex) = material.base_color_texture.and_then(|t| scene.textures.get(t)) {
            base *= sample_texture(tex, uv);
        }
        let metallic = material.metallic.clamp(0.0, 1.0);
        let transmission = material.transmission.clamp(0.0, 1.0) * (1.0 - metallic);
        let ior = if material.ior.is_finite() && material.ior >= 1.0 { material.ior } else { 1.5 };
        let r0 = ((ior - 1.0) / (ior + 1.0)).powi(2);
        let dielectric_f0 = (Vec3::from(material.specular_color) * r0).min(Vec3::ONE);
        let roughness = material.roughness.clamp(0.0, 1.0);
        let sigma_a = if material.attenuation_distance.is_finite() && material.attenuation_distance > 0.0 {
            Vec3::from(material.attenuation_color).max(Vec3::splat(1e-6)).min(Vec3::ONE).map(|c| -c.ln())
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
            emission: Vec3::from(material.emissive),
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

/// Bilinear, wrapping lookup of a texture (UV (0,0) = top-left texel corner).
pub fn sample_texture(tex: &TextureImage, uv: Vec2) -> Vec3 {
    let (w, h) = (tex.width as usize, tex.height as usize);
    if w == 0 || h == 0 || tex.texels.len() < w * h {
        return Vec3::ONE;
    }
    let x = uv.x * w as f32 - 0.5;
    let y = uv.y * h as f32 - 0.5;
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let wrap = |v: f32, n: usize| (v as i64).rem_euclid(n as i64) as usize;
    let t = |xi: f32, yi: f32| {
        let c = tex.texels[wrap(yi, h) * w + wrap(xi, w)];
        Vec3::new(c[0], c[1], c[2])
    };
    let top = t(x0, y0).lerp(t(x0 + 1.0, y0), fx);
    let bottom = t(x0, y0 + 1.0).lerp(t(x0 + 1.0, y0 + 1.0), fx);
    top.lerp(bottom, fy)
}

/// Schlick's approximation of the Fresnel reflectance for reflectance `f0` at normal incidence.
pub fn schlick(f0: Vec3, cos_theta: f32) -> Vec3 {
    let m = (1.0 - cos_theta.clamp(0.0, 1.0)).powi(5);
    f0 + (Vec3::ONE - f0) * m
}

/// Exact unpolarised Fresnel reflectance of a dielectric interface. `cos_i` is the cosine
/// between the incident direction (reversed) and the normal on the incident side; `eta` is
/// n_incident / n_transmitted. Returns 1 under total internal reflection.
pub fn fresnel_dielectric(cos_i: f32, eta: f32) -> f32 {
    let cos_i = cos_i.clamp(0.0, 1.0);
    let sin2_t = eta * eta * (1.0 - cos_i * cos_i);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let rs = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let rp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    0.5 * (rs * rs + rp * rp)
}

/// Mirror reflection of direction `d` about normal `n`.
pub fn reflect(d: Vec3, n: Vec3) -> Vec3 {
    d - n * (2.0 * d.dot(n))
}

/// Refraction of unit direction `d` through the interface with unit normal `n` (facing
/// against `d`) and relative index `eta` = n_incident / n_transmitted; `None` under total
/// internal reflection.
pub fn refract(d: Vec3, n: Vec3, eta: f32) -> Option<Vec3> {
    let cos_i = -d.dot(n);
    let sin2_t = eta * eta * (1.0 - cos_i * cos_i);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some((d * eta + n * (eta * cos_i - cos_t)).normalize())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fresnel_at_normal_incidence_and_tir() {
        for n in [1.33f32, 1.5, 2.4] {
            let r0 = ((n - 1.0) / (n + 1.0)).powi(2);
            assert!((fresnel_dielectric(1.0, 1.0 / n) - r0).abs() < 1e-6);
            assert!((fresnel_dielectric(1.0, n) - r0).abs() < 1e-6);
        }
        // Beyond the critical angle inside glass.
        assert_eq!(fresnel_dielectric(0.3, 1.5), 1.0);
        assert!(refract(Vec3::new(0.95, -0.3122499, 0.0).normalize(), Vec3::Y, 1.5).is_none());
    }

    #[test]
    fn refraction_obeys_snell() {
        let d = Vec3::new(0.5, -0.8660254, 0.0);
        let t = refract(d, Vec3::Y, 1.0 / 1.5).unwrap();
        let sin_i = 0.5f32;
        let sin_t = t.x;
        assert!((sin_i - 1.5 * sin_t).abs() < 1e-5);
    }
}
