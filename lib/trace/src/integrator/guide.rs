//! The denoiser's guides of a camera sample: albedo and shading normal at the first
//! non-specular hit (Open Image Denoise's convention for mirrors and glass: guides taken at a
//! delta surface itself would carry none of the detail seen through it, and make mirror and
//! glass pixels denoise worse than without guides).

use super::{Integrator, PathContext};
use crate::bvh::{offset_origin, SurfacePoint};
use crate::material::ShadingMaterial;
use glam::Vec3;
use pis_scene::optics::{fresnel_dielectric, reflect, refract};

/// Below this GGX alpha (roughness 0.2) a mirror or glass lobe is followed for the guides.
const SPECULAR_GUIDE_ALPHA: f32 = 0.04;

/// Most specular bounces followed before the guides are taken where the path is.
const MAX_GUIDE_BOUNCES: u32 = 4;

/// Albedo and normal of one camera sample.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Guide {
    /// Reflectance at the first non-specular hit, times the specular tint on the way there.
    pub albedo: Vec3,
    /// Its shading normal (world, unit); zero where the path leaves the scene.
    pub normal: Vec3,
}

/// Whether the guides look through the surface: a smooth lobe that carries most of the
/// light (a metal, or a dielectric that mostly transmits).
fn delta_like(m: &ShadingMaterial) -> bool {
    m.alpha < SPECULAR_GUIDE_ALPHA && (m.metallic >= 0.5 || m.transmission >= 0.5)
}

/// The reflectance a denoiser reads at a non-specular surface: the diffuse albedo plus the
/// specular lobe's normal-incidence reflectance.
fn surface_albedo(m: &ShadingMaterial) -> Vec3 {
    let specular = m.f0_dielectric * ((1.0 - m.metallic) * m.specular) + m.base * m.metallic;
    (m.diffuse + specular).min(Vec3::ONE)
}

impl Integrator<'_> {
    /// The guides of a camera ray travelling along `dir` whose first hit is `sp` with
    /// material `m`.
    pub(super) fn guide(
        &self,
        sp: &SurfacePoint,
        m: &ShadingMaterial,
        dir: Vec3,
        ctx: &mut PathContext,
    ) -> Guide {
        let (mut sp, mut m, mut dir) = (*sp, *m, dir);
        let mut tint = Vec3::ONE;
        for _ in 0..MAX_GUIDE_BOUNCES {
            if !delta_like(&m) {
                break;
            }
            let cos = (-dir).dot(sp.normal).max(0.0);
            let eta = if sp.front_face { 1.0 / m.ior } else { m.ior };
            let through = (m.transmission >= 0.5)
                .then(|| refract(dir, sp.normal, eta))
                .flatten()
                .filter(|_| fresnel_dielectric(cos, eta) < 0.5);
            let next = match through {
                Some(t) => {
                    tint *= if sp.front_face { m.base } else { Vec3::ONE };
                    t
                }
                None => {
                    tint *= m.fresnel(cos).max(Vec3::splat(fresnel_dielectric(cos, eta)));
                    reflect(dir, sp.normal)
                }
            };
            let o = offset_origin(sp.position, sp.geometric_normal, next);
            let Some(hit) = self.trace(o, next, None, ctx) else { return Guide::default() };
            sp = self.geometry.surface(&hit, o, next);
            m = self.material(&mut sp);
            dir = next;
        }
        Guide { albedo: tint * surface_albedo(&m), normal: sp.normal }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn material(metallic: f32, transmission: f32, alpha: f32) -> ShadingMaterial {
        ShadingMaterial {
            base: Vec3::new(0.8, 0.6, 0.4),
            diffuse: Vec3::new(0.8, 0.6, 0.4) * (1.0 - metallic) * (1.0 - transmission),
            f0_dielectric: Vec3::splat(0.04),
            metallic,
            specular: 1.0,
            alpha,
            transmission,
            ior: 1.5,
            sigma_a: Vec3::ZERO,
            emission: Vec3::ZERO,
        }
    }

    #[test]
    fn smooth_metal_and_glass_are_looked_through_and_rough_or_diffuse_surfaces_are_not() {
        assert!(delta_like(&material(1.0, 0.0, 0.0)));
        assert!(delta_like(&material(0.0, 1.0, 0.01)));
        assert!(!delta_like(&material(1.0, 0.0, 0.25)));
        assert!(!delta_like(&material(0.0, 0.0, 0.0)));
        let plastic = surface_albedo(&material(0.0, 0.0, 0.5));
        assert!((plastic - Vec3::new(0.84, 0.64, 0.44)).abs().max_element() < 1e-6);
    }
}
