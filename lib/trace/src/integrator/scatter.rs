//! One scattering event at a surface: a lobe chosen by its weight (diffuse, opaque specular,
//! smooth dielectric), its sampled ray traced on, and the opaque specular lobe's sampling.

use super::pdf::ggx_reflection_pdf;
use super::{Integrator, PathContext};
use crate::bvh::{offset_origin, SurfacePoint};
use crate::material::ShadingMaterial;
use crate::sampling::{ggx_g1, ggx_half_vector, luminance, Rng};
use glam::Vec3;
use pis_scene::optics::{fresnel_dielectric, reflect, refract};

/// GGX alpha from which the opaque specular lobe samples lights explicitly.
pub const NEE_ALPHA: f32 = 0.1;

/// Interfaces of a smooth dielectric (counted from the camera ray's first hit) at which both
/// children are traced rather than one chosen by Fresnel.
pub const SPLIT_DEPTH: u32 = 3;

/// Lobe weight (luminance) below which first-hit specular lobes are sampled by Russian roulette.
pub const ROULETTE_WEIGHT: f32 = 0.25;

/// Whether a uniform `u` drawn in [0, `first` + `second`) picks the first of two lobes of
/// those weights. `u` may round up to the sum (and past `first` when a preceding weight was
/// taken off it): a lobe of weight 0 is never picked, since its estimate divides by it.
fn picks_first(u: f32, first: f32, second: f32) -> bool {
    second <= 0.0 || (first > 0.0 && u < first)
}

impl Integrator<'_> {
    /// One stochastic scattering event at `sp` for a ray arriving with direction `dir`.
    #[allow(
        clippy::too_many_arguments,
        reason = "a scattering event reads the surface, its material, the ray and the path's state, each apart"
    )]
    pub(super) fn scatter(
        &self,
        sp: &SurfacePoint,
        m: &ShadingMaterial,
        dir: Vec3,
        depth: u32,
        diffuse_left: u32,
        rng: &mut Rng,
        ctx: &mut PathContext,
    ) -> Vec3 {
        let p_d = luminance(m.diffuse);
        let rest = self.lobe_weights(sp, m, dir);
        let total = p_d + rest.0 + rest.1;
        if total <= 0.0 {
            return Vec3::ZERO;
        }
        let u = rng.next_f32() * total;
        if picks_first(u, p_d, rest.0 + rest.1) {
            self.diffuse(sp, m, depth, diffuse_left, rng, ctx) * (total / p_d)
        } else {
            self.scatter_nondiffuse(
                sp,
                m,
                dir,
                depth,
                diffuse_left,
                rng,
                ctx,
                Some((u - p_d, rest)),
            ) * (total / (rest.0 + rest.1))
        }
    }

    /// Selection weights of the opaque specular and the transmission lobes.
    fn lobe_weights(&self, sp: &SurfacePoint, m: &ShadingMaterial, dir: Vec3) -> (f32, f32) {
        let cos_o = (-dir).dot(sp.normal).max(0.0);
        let p_s = luminance(m.fresnel(cos_o)) * (1.0 - m.transmission);
        (p_s, m.transmission)
    }

    /// The non-diffuse lobes at `sp`, one chosen stochastically; returns their estimated sum.
    /// `choice` carries a uniform already drawn in [0, p_s + p_t) with the weights.
    #[allow(
        clippy::too_many_arguments,
        reason = "the path's state, the surface and the lobe already chosen are each read apart"
    )]
    pub(super) fn scatter_nondiffuse(
        &self,
        sp: &SurfacePoint,
        m: &ShadingMaterial,
        dir: Vec3,
        depth: u32,
        diffuse_left: u32,
        rng: &mut Rng,
        ctx: &mut PathContext,
        choice: Option<(f32, (f32, f32))>,
    ) -> Vec3 {
        let mut survival = 1.0;
        let (u, (p_s, p_t)) = match choice {
            Some(c) => c,
            None => {
                // Called on its own (at a first hit, beside the diffuse lobe): weak lobes such
                // as the 4 % reflection of a matte dielectric are continued by Russian
                // roulette with probability ∝ their weight.
                let w = self.lobe_weights(sp, m, dir);
                survival = ((w.0 + w.1) / ROULETTE_WEIGHT).min(1.0);
                if survival < 1.0 && rng.next_f32() >= survival {
                    return Vec3::ZERO;
                }
                (rng.next_f32() * (w.0 + w.1), w)
            }
        };
        let total = p_s + p_t;
        if total <= 0.0 || depth >= self.settings.max_depth {
            return Vec3::ZERO;
        }
        let total = total / survival;
        if picks_first(u, p_s, p_t) {
            // Rough lobes reach the lights by next-event estimation, their sampled rays do
            // not see light spheres; glossy and mirror lobes see them along sampled rays.
            let rough = m.alpha >= NEE_ALPHA;
            let direct =
                if rough { self.specular_direct(sp, m, dir, rng, ctx) } else { Vec3::ZERO };
            let Some((d, f, g)) = self.sample_specular(sp, m, dir, rng) else {
                return direct * (1.0 - m.transmission) * (total / p_s);
            };
            let o = offset_origin(sp.position, sp.geometric_normal, d);
            let l = if rough && self.environment.is_some() {
                self.radiance_mis(
                    o,
                    d,
                    depth + 1,
                    diffuse_left,
                    ggx_reflection_pdf(sp.normal, -dir, d, m.alpha),
                    sp.normal,
                    ctx,
                )
            } else {
                self.radiance(o, d, depth + 1, diffuse_left, !rough, None, ctx)
            };
            (direct + l * f * g) * (1.0 - m.transmission) * (total / p_s)
        } else {
            self.dielectric(sp, m, dir, depth, diffuse_left, rng, ctx)
                * m.transmission
                * (total / p_t)
        }
    }

    /// Samples the opaque specular lobe: (direction, Fresnel, geometric weight), so that the
    /// estimator of the reflected radiance is F · g · L(direction).
    pub(super) fn sample_specular(
        &self,
        sp: &SurfacePoint,
        m: &ShadingMaterial,
        dir: Vec3,
        rng: &mut Rng,
    ) -> Option<(Vec3, Vec3, f32)> {
        let wo = -dir;
        let n = sp.normal;
        let cos_o = wo.dot(n);
        if cos_o <= 0.0 {
            return None;
        }
        if m.is_mirror() {
            let r = reflect(dir, n);
            return (r.dot(sp.geometric_normal) > 0.0).then(|| (r, m.fresnel(cos_o), 1.0));
        }
        let u = rng.next_2d();
        let h = ggx_half_vector(u, n, m.alpha);
        let r = reflect(dir, h);
        let cos_r = r.dot(n);
        let vh = wo.dot(h);
        if cos_r <= 0.0 || vh <= 0.0 || r.dot(sp.geometric_normal) <= 0.0 {
            return None;
        }
        let g = ggx_g1(cos_o, m.alpha) * ggx_g1(cos_r, m.alpha) * vh / (cos_o * n.dot(h).max(1e-6));
        Some((r, m.fresnel(vh), g))
    }

    /// The smooth dielectric lobe: Fresnel-weighted choice of reflection or refraction.
    #[allow(
        clippy::too_many_arguments,
        reason = "a scattering event reads the surface, its material, the ray and the path's state, each apart"
    )]
    pub(super) fn dielectric(
        &self,
        sp: &SurfacePoint,
        m: &ShadingMaterial,
        dir: Vec3,
        depth: u32,
        diffuse_left: u32,
        rng: &mut Rng,
        ctx: &mut PathContext,
    ) -> Vec3 {
        let (eta, n) = (if sp.front_face { 1.0 / m.ior } else { m.ior }, sp.normal);
        let f = fresnel_dielectric(-dir.dot(n), eta);
        if depth < SPLIT_DEPTH && f < 1.0 {
            // Near the camera both children are traced (weights F and 1 − F), deeper
            // interfaces choose one by Fresnel: a lesser branch chosen with probability F
            // that meets a light carries L/F into one sample, and at 256 samples a glass
            // teapot's glints of the lamp (through its internal reflections) stayed 24 dB
            // from converged.
            let r = reflect(dir, n);
            let reflected = self.radiance(
                offset_origin(sp.position, sp.geometric_normal, r),
                r,
                depth + 1,
                diffuse_left,
                true,
                None,
                ctx,
            );
            let refracted = match refract(dir, n, eta) {
                Some(t) => {
                    let o = offset_origin(sp.position, sp.geometric_normal, t);
                    self.radiance(o, t, depth + 1, diffuse_left, true, None, ctx)
                        * if sp.front_face { m.base } else { Vec3::ONE }
                }
                None => reflected / f.max(1e-6) * (1.0 - f),
            };
            return reflected * f + refracted * (1.0 - f);
        }
        let (d, w) = if rng.next_f32() < f {
            (reflect(dir, n), Vec3::ONE)
        } else {
            match refract(dir, n, eta) {
                Some(t) => (t, if sp.front_face { m.base } else { Vec3::ONE }),
                None => (reflect(dir, n), Vec3::ONE),
            }
        };
        let o = offset_origin(sp.position, sp.geometric_normal, d);
        self.radiance(o, d, depth + 1, diffuse_left, true, None, ctx) * w
    }
}

#[cfg(test)]
mod tests {
    use super::picks_first;

    /// A sample of the floor of teapot-pem (a rough dielectric: diffuse weight 0.0481,
    /// specular 0.1302, transmission 0) drew u = 0.1782612, which rounds to the sum of the
    /// weights: with the diffuse weight taken off it is not below the specular weight, and
    /// picking the transmission lobe of weight 0 gave 0 × ∞ = NaN in the traced image.
    #[test]
    fn a_lobe_of_weight_zero_is_never_picked() {
        let (p_d, p_s, p_t) = (0.048_096_44f32, 0.130_164_77f32, 0.0f32);
        let total = p_d + p_s + p_t;
        let u = 0.999_999_94f32 * total;
        assert!(!picks_first(u, p_d, p_s + p_t));
        assert!(picks_first(u - p_d, p_s, p_t), "u − p_d = {} against p_s = {p_s}", u - p_d);
        assert!(
            picks_first(total, p_s, 0.0)
                && !picks_first(0.0, 0.0, 0.5)
                && picks_first(1.0, 1.0, 0.0)
        );
        assert!(picks_first(0.2, 0.5, 0.5) && !picks_first(0.7, 0.5, 0.5));
        for k in 0..1000 {
            let u = k as f32 / 1000.0 * total;
            let specular = picks_first(u - p_d, p_s, p_t);
            assert!(picks_first(u, p_d, p_s + p_t) || specular, "u = {u}");
        }
    }
}
