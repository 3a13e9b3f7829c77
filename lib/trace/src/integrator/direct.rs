//! Light reaching a surface point: the diffuse lobe's irradiance (next-event estimation
//! towards the lights and the environment, and an indirect bounce), cached per surface cell
//! at first hits, and next-event estimation for the opaque GGX lobe.

use super::pdf::{diffuse_pdf, ggx_reflection_pdf};
use super::{Integrator, PathContext};
use crate::bvh::{offset_origin, SurfacePoint};
use crate::environment::balance;
use crate::lights::sample_light;
use crate::material::ShadingMaterial;
use crate::sampling::{cosine_hemisphere, ggx_g1, Rng};
use glam::Vec3;
use std::f32::consts::PI;

impl Integrator<'_> {
    /// Radiance of the diffuse lobe: albedo × [`Self::irradiance`] with one sample.
    pub(super) fn diffuse(
        &self,
        sp: &SurfacePoint,
        m: &ShadingMaterial,
        depth: u32,
        diffuse_left: u32,
        rng: &mut Rng,
        ctx: &mut PathContext,
    ) -> Vec3 {
        m.diffuse * self.irradiance(sp, depth, diffuse_left, 1, rng, ctx)
    }

    /// Incident irradiance / π at `sp` (so that albedo × it is the diffuse radiance):
    /// next-event estimation towards every light and the environment, plus with
    /// `diffuse_left > 0` an indirect bounce (the environment weighed against it by multiple
    /// importance sampling), averaged over `samples` estimates.
    fn irradiance(
        &self,
        sp: &SurfacePoint,
        depth: u32,
        diffuse_left: u32,
        samples: u32,
        rng: &mut Rng,
        ctx: &mut PathContext,
    ) -> Vec3 {
        let n = sp.normal;
        let bounce = diffuse_left > 0 && depth < self.settings.max_depth;
        let mut direct = Vec3::ZERO;
        let mut indirect = Vec3::ZERO;
        for _ in 0..samples.max(1) {
            for light in &self.frame.lights {
                let Some(ls) = sample_light(light, sp.position, rng) else { continue };
                let cos = n.dot(ls.direction);
                if cos <= 0.0 || sp.geometric_normal.dot(ls.direction) <= 0.0 {
                    continue;
                }
                let o = offset_origin(sp.position, sp.geometric_normal, ls.direction);
                ctx.rays += 1;
                let tmax = if ls.distance.is_finite() {
                    ls.distance * (1.0 - 1e-4)
                } else {
                    f32::INFINITY
                };
                if !self.geometry.occluded(o, ls.direction, tmax) {
                    direct += ls.weight * cos;
                }
            }
            indirect += self.environment_direct(sp, bounce, rng, ctx);
            if bounce {
                let mut d = cosine_hemisphere(rng.next_2d(), n);
                // A direction below the geometric surface (shading normals differ from the
                // facets) is mirrored back above it, keeping the lobe's energy.
                let below = sp.geometric_normal.dot(d);
                if below <= 0.0 {
                    d = (d - sp.geometric_normal * (2.0 * below)).normalize();
                }
                let o = offset_origin(sp.position, sp.geometric_normal, d);
                indirect += if self.environment.is_some() {
                    self.radiance_mis(
                        o,
                        d,
                        depth + 1,
                        diffuse_left - 1,
                        diffuse_pdf(n, sp.geometric_normal, d),
                        n,
                        ctx,
                    )
                } else {
                    self.radiance(o, d, depth + 1, diffuse_left - 1, false, None, ctx)
                };
            }
        }
        (direct / PI + indirect) / samples.max(1) as f32
    }

    /// Next-event estimation of the environment's irradiance / π at `sp`, weighed against
    /// the diffuse lobe's sampled ray when `bounce` (that ray is traced). Both estimate
    /// ∫ L p_d with p_d the diffuse lobe's density ([`diffuse_pdf`]): each contributes
    /// L · p_d / (p_env + p_d) with the balance heuristic.
    fn environment_direct(
        &self,
        sp: &SurfacePoint,
        bounce: bool,
        rng: &mut Rng,
        ctx: &mut PathContext,
    ) -> Vec3 {
        let Some(env) = &self.environment else { return Vec3::ZERO };
        let Some(s) = env.sample(sp.normal, rng.next_2d()) else { return Vec3::ZERO };
        let p_d = diffuse_pdf(sp.normal, sp.geometric_normal, s.direction);
        if p_d <= 0.0 {
            return Vec3::ZERO;
        }
        let o = offset_origin(sp.position, sp.geometric_normal, s.direction);
        ctx.rays += 1;
        if self.geometry.occluded(o, s.direction, f32::INFINITY) {
            return Vec3::ZERO;
        }
        s.radiance * if bounce { p_d / (s.pdf + p_d) } else { p_d / s.pdf }
    }

    /// Irradiance / π at a camera ray's first hit. With coherent sampling it is a function of
    /// the surface cell: estimated once per cell (with `diffuse_samples` estimates seeded by
    /// the cell) at the first point that reaches the cell, and reused by later camera samples
    /// of the same image row (the cache lives in `ctx`, one per row, so the result does not
    /// depend on the thread count).
    pub(super) fn first_irradiance(
        &self,
        sp: &SurfacePoint,
        diffuse_left: u32,
        ctx: &mut PathContext,
    ) -> Vec3 {
        let samples = self.settings.diffuse_samples.max(1);
        if self.cell <= 0.0 {
            let mut rng = Rng::at_surface(sp.object_position, 0.0, sp.object, 0, ctx.fallback_seed);
            return self.irradiance(sp, 0, diffuse_left, samples, &mut rng, ctx);
        }
        let q = (sp.object_position / self.cell).floor();
        let key = (q.x as i64, q.y as i64, q.z as i64, sp.object, sp.front_face);
        if let Some(&e) = ctx.irradiance_cache.get(&key) {
            return e;
        }
        let mut rng =
            Rng::at_surface(sp.object_position, self.cell, sp.object, 0, ctx.fallback_seed);
        let e = self.irradiance(sp, 0, diffuse_left, samples, &mut rng, ctx);
        ctx.irradiance_cache.insert(key, e);
        e
    }

    /// Next-event estimation for the opaque GGX lobe: Σ lights f_s(v, l) L cos θ_l / pdf.
    pub(super) fn specular_direct(
        &self,
        sp: &SurfacePoint,
        m: &ShadingMaterial,
        dir: Vec3,
        rng: &mut Rng,
        ctx: &mut PathContext,
    ) -> Vec3 {
        let (wo, n) = (-dir, sp.normal);
        let cos_o = wo.dot(n);
        if cos_o <= 0.0 {
            return Vec3::ZERO;
        }
        let mut sum = Vec3::ZERO;
        for light in &self.frame.lights {
            let Some(ls) = sample_light(light, sp.position, rng) else { continue };
            let l = ls.direction;
            let Some((f, lobe)) = ggx_reflection(sp, m, wo, l, cos_o) else { continue };
            let o = offset_origin(sp.position, sp.geometric_normal, l);
            ctx.rays += 1;
            let tmax =
                if ls.distance.is_finite() { ls.distance * (1.0 - 1e-4) } else { f32::INFINITY };
            if !self.geometry.occluded(o, l, tmax) {
                sum += f * ls.weight * lobe;
            }
        }
        // The environment, weighed against the lobe's sampled ray (always traced after this).
        if let Some(s) = self.environment.as_ref().and_then(|env| env.sample(n, rng.next_2d())) {
            let l = s.direction;
            if let Some((f, lobe)) = ggx_reflection(sp, m, wo, l, cos_o) {
                let o = offset_origin(sp.position, sp.geometric_normal, l);
                ctx.rays += 1;
                if !self.geometry.occluded(o, l, f32::INFINITY) {
                    let w = balance(s.pdf, ggx_reflection_pdf(n, wo, l, m.alpha));
                    sum += f * s.radiance * (lobe / s.pdf * w);
                }
            }
        }
        sum
    }
}

/// The opaque GGX lobe towards the unit direction `l` seen from `wo` at `sp` (`cos_o` =
/// n·wo > 0): its Fresnel factor and D G / (4 cos_o), so that the reflected radiance of light
/// L arriving along `l` is F · L · that; `None` where `l` is below the shading or the
/// geometric surface.
fn ggx_reflection(
    sp: &SurfacePoint,
    m: &ShadingMaterial,
    wo: Vec3,
    l: Vec3,
    cos_o: f32,
) -> Option<(Vec3, f32)> {
    let n = sp.normal;
    let cos_l = n.dot(l);
    if cos_l <= 0.0 || sp.geometric_normal.dot(l) <= 0.0 {
        return None;
    }
    let a2 = m.alpha * m.alpha;
    let h = (wo + l).normalize();
    let nh = n.dot(h).max(0.0);
    let dd = nh * nh * (a2 - 1.0) + 1.0;
    let d = a2 / (PI * dd * dd);
    let g = ggx_g1(cos_o, m.alpha) * ggx_g1(cos_l, m.alpha);
    Some((m.fresnel(wo.dot(h)), d * g / (4.0 * cos_o)))
}
