//! The distribution ray tracer: radiance along rays, and the segmented first hit that
//! produces the per-object layers (thesis 3.1, 5.7, 6.2).
//!
//! Emitters are reached in two ways. Light spheres and the environment are seen by camera
//! rays (the environment only as a `background`) and by rays of mirror, glossy and
//! dielectric lobes until the path's first diffuse bounce; after it, and from diffuse and
//! rough specular lobes, lights are reached by next-event estimation only (no caustics
//! through diffuse paths: no fireflies). The environment is also sampled by next-event
//! estimation at diffuse and rough specular lobes, and there weighed against the lobe's own
//! sampled ray (which may leave the scene and see it) by multiple importance sampling.

use crate::bvh::{offset_origin, Hit, SceneGeometry, SurfacePoint};
use crate::environment::{balance, EnvironmentLight};
use crate::lights::{hit_light_sphere, sample_light};
use crate::material::ShadingMaterial;
use crate::sampling::{cosine_hemisphere, ggx_g1, ggx_half_vector, luminance, Rng};
use crate::settings::TraceSettings;
use glam::Vec3;
use pis_scene::optics::{fresnel_dielectric, reflect, refract};
use pis_scene::{Frame, ObjectRole, Scene};
use std::f32::consts::PI;

/// GGX alpha from which the opaque specular lobe samples lights explicitly.
pub const NEE_ALPHA: f32 = 0.1;

/// Seed stream of the specular lobes at a camera ray's first hit (the depth slot of
/// [`Rng::at_surface`]; paths use their depth, the first-hit irradiance depth 0).
const FIRST_HIT_SPECULAR_STREAM: u32 = 0x8000_0000;

/// Key of a surface cell: quantized object-space point, object, front or back side.
pub type CellKey = (i64, i64, i64, u32, bool);

/// Lobe weight (luminance) below which first-hit specular lobes are sampled by Russian roulette.
pub const ROULETTE_WEIGHT: f32 = 0.25;

/// Per-path bookkeeping: ray counts, the fallback seed and the first-hit irradiance cache.
#[derive(Clone, Debug, Default)]
pub struct PathContext {
    /// Rays traced (BVH queries, shadow rays included).
    pub rays: u64,
    /// Seed used instead of the surface point when coherence is off.
    pub fallback_seed: u64,
    /// Irradiance / π per surface cell at first hits (one image row's worth).
    pub irradiance_cache: std::collections::HashMap<CellKey, Vec3>,
}

/// The two terms of the greedy two-path model (thesis 6.2).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GreedyTerm {
    /// The path that starts with a reflection.
    ReflectionFirst = 0,
    /// The path that starts with a refraction.
    RefractionFirst = 1,
}

/// A front-facing hit along a continued outgoing ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContinuedHit {
    /// Distance from the exit origin.
    pub t: f32,
    pub position: Vec3,
    pub object: u32,
    /// Radiance leaving the hit point towards the exit origin.
    pub colour: Vec3,
}

/// One term of the greedy two-path model for one camera sample.
#[derive(Clone, Debug, Default)]
pub struct TermSample {
    /// Product of the Fresnel coefficients and transparency attenuation along the path (F·G).
    pub modulation: Vec3,
    /// Radiance along the exit ray (T or R).
    pub radiance: Vec3,
    /// Where the path left the lens object: origin and unit direction; `None` when the path
    /// does not exist (refraction-first under total internal reflection) or was cut.
    pub exit: Option<(Vec3, Vec3)>,
    /// Front-facing hits along the continued exit ray, nearest first (records only).
    pub hits: Vec<ContinuedHit>,
}

/// Layers of a reflective object for one camera sample (thesis 5.7).
#[derive(Clone, Copy, Debug, Default)]
pub struct ReflectiveSample {
    /// Fresnel modulation F(n·v) of the specular lobe.
    pub fresnel: Vec3,
    /// Incident specular radiance when the reflected ray hits the reflector again: the object
    /// or another part of it (else 0).
    pub local: Vec3,
    /// 1 when the reflected ray hits the reflector again, else 0.
    pub local_alpha: f32,
    /// Incident specular radiance with the reflector made transparent for the reflected ray.
    pub distant: Vec3,
}

/// Everything one camera sample contributes.
#[derive(Clone, Debug, Default)]
pub struct CameraSample {
    /// The object hit first, if any.
    pub object: Option<u32>,
    /// Full radiance (the gold standard).
    pub combined: Vec3,
    /// Radiance from the first diffuse interaction.
    pub diffuse: Vec3,
    /// Everything else (emission, specular reflection, transmission).
    pub specular: Vec3,
    pub reflective: Option<ReflectiveSample>,
    /// The greedy terms, reflection-first then refraction-first, for refractive objects.
    pub lens: Option<[TermSample; 2]>,
}

/// Traces rays in one evaluated scene.
pub struct Integrator<'s> {
    pub scene: &'s Scene,
    pub frame: &'s Frame,
    pub geometry: SceneGeometry<'s>,
    pub settings: TraceSettings,
    /// Coherent-sampling cell size actually used (0 = per pixel sample).
    pub cell: f32,
    /// The scene's environment light, if it emits.
    pub environment: Option<EnvironmentLight<'s>>,
}

/// Whether a uniform `u` drawn in [0, `first` + `second`) picks the first of two lobes of
/// those weights. `u` may round up to the sum (and past `first` when a preceding weight was
/// taken off it): a lobe of weight 0 is never picked, since its estimate divides by it.
fn picks_first(u: f32, first: f32, second: f32) -> bool {
    second <= 0.0 || (first > 0.0 && u < first)
}

impl<'s> Integrator<'s> {
    /// Builds the geometry of `scene` at `frame`.
    pub fn new(scene: &'s Scene, frame: &'s Frame, settings: &TraceSettings) -> Integrator<'s> {
        let geometry = SceneGeometry::build(scene, frame);
        let cell = match settings.coherence_cell {
            Some(c) => c.max(0.0),
            None => {
                let diag = (geometry.bounds.1 - geometry.bounds.0).length();
                if diag > 0.0 {
                    diag / 4096.0
                } else {
                    0.0
                }
            }
        };
        let environment = scene.environment.as_ref().and_then(EnvironmentLight::new);
        Integrator { scene, frame, geometry, settings: settings.clone(), cell, environment }
    }

    /// Whether a ray sees light spheres and the environment: `sees_lights` and no diffuse
    /// bounce on its path yet.
    fn sees_emitters(&self, sees_lights: bool, diffuse_left: u32) -> bool {
        sees_lights && diffuse_left >= self.settings.diffuse_bounces.max(1)
    }

    /// Radiance of the environment along a ray that leaves the scene, where the ray sees it.
    fn escaped(&self, dir: Vec3, sees_lights: bool, diffuse_left: u32) -> Vec3 {
        match &self.environment {
            Some(env) if self.sees_emitters(sees_lights, diffuse_left) => env.radiance(dir),
            _ => Vec3::ZERO,
        }
    }

    /// Radiance along a ray sampled by a lobe whose directions the environment is also drawn
    /// for by next-event estimation: where the ray leaves the scene, the environment weighed
    /// by the balance heuristic (`lobe_pdf` the lobe's density of `dir`, `n` the shading
    /// normal the environment was drawn for); where it hits, as [`Self::radiance`] with light
    /// spheres unseen.
    #[allow(clippy::too_many_arguments)]
    fn radiance_mis(
        &self,
        origin: Vec3,
        dir: Vec3,
        depth: u32,
        diffuse_left: u32,
        lobe_pdf: f32,
        n: Vec3,
        ctx: &mut PathContext,
    ) -> Vec3 {
        if depth > self.settings.max_depth {
            return Vec3::ZERO;
        }
        let hit = self.trace(origin, dir, None, ctx);
        match (&self.environment, hit) {
            (Some(env), None) => env.radiance(dir) * balance(lobe_pdf, env.pdf(dir, n)),
            _ => self.radiance_from(hit, origin, dir, depth, diffuse_left, false, ctx),
        }
    }

    fn rng_at(&self, sp: &SurfacePoint, depth: u32, ctx: &PathContext) -> Rng {
        Rng::at_surface(sp.object_position, self.cell, sp.object, depth, ctx.fallback_seed)
    }

    /// The material at `sp`, whose shading normal it bends by its normal map.
    fn material(&self, sp: &mut SurfacePoint) -> ShadingMaterial {
        let default;
        let m = match self.scene.materials.get(sp.material) {
            Some(m) => m,
            None => {
                default = pis_scene::Material::default();
                &default
            }
        };
        sp.apply_normal_map(self.scene, m);
        ShadingMaterial::at_uvs(self.scene, m, [sp.uv, sp.uv1])
    }

    /// Role of object `o`.
    pub fn role(&self, o: u32) -> ObjectRole {
        self.scene.objects.get(o as usize).map(|x| x.role).unwrap_or(ObjectRole::Diffuse)
    }

    /// Closest hit along a ray, counting it.
    fn trace(
        &self,
        origin: Vec3,
        dir: Vec3,
        skip: Option<u32>,
        ctx: &mut PathContext,
    ) -> Option<Hit> {
        ctx.rays += 1;
        self.geometry.closest(origin, dir, f32::INFINITY, skip)
    }

    /// Radiance arriving at `origin` along `-dir`.
    /// `sees_lights`: whether light spheres are visible to this ray (camera and specular rays
    /// of paths without a diffuse bounce; diffuse paths reach lights through next-event
    /// estimation instead).
    #[allow(clippy::too_many_arguments)]
    pub fn radiance(
        &self,
        origin: Vec3,
        dir: Vec3,
        depth: u32,
        diffuse_left: u32,
        sees_lights: bool,
        skip: Option<u32>,
        ctx: &mut PathContext,
    ) -> Vec3 {
        if depth > self.settings.max_depth {
            return Vec3::ZERO;
        }
        let hit = self.trace(origin, dir, skip, ctx);
        self.radiance_from(hit, origin, dir, depth, diffuse_left, sees_lights, ctx)
    }

    /// Like [`Self::radiance`] for a ray whose closest hit is already known.
    #[allow(clippy::too_many_arguments)]
    fn radiance_from(
        &self,
        hit: Option<Hit>,
        origin: Vec3,
        dir: Vec3,
        depth: u32,
        diffuse_left: u32,
        sees_lights: bool,
        ctx: &mut PathContext,
    ) -> Vec3 {
        // After a diffuse bounce light spheres and the environment are reached by next-event
        // estimation only, also along later specular segments (no caustics through diffuse
        // paths: no fireflies).
        if self.sees_emitters(sees_lights, diffuse_left) {
            let tmax = hit.map_or(f32::INFINITY, |h| h.t);
            if let Some((_, l)) = hit_light_sphere(&self.frame.lights, origin, dir, tmax) {
                return l;
            }
        }
        let Some(hit) = hit else { return self.escaped(dir, sees_lights, diffuse_left) };
        let mut sp = self.geometry.surface(&hit, origin, dir);
        let m = self.material(&mut sp);
        let absorb = self.absorption(&sp, &m, hit.t);
        let mut rng = self.rng_at(&sp, depth, ctx);
        absorb * (m.emission + self.scatter(&sp, &m, dir, depth, diffuse_left, &mut rng, ctx))
    }

    /// Beer attenuation of a segment of length `t` that ended at `sp` from inside.
    fn absorption(&self, sp: &SurfacePoint, m: &ShadingMaterial, t: f32) -> Vec3 {
        if !sp.front_face && m.transmission > 0.0 && m.sigma_a != Vec3::ZERO {
            (-m.sigma_a * t).exp()
        } else {
            Vec3::ONE
        }
    }

    /// One stochastic scattering event at `sp` for a ray arriving with direction `dir`.
    #[allow(clippy::too_many_arguments)]
    fn scatter(
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
    #[allow(clippy::too_many_arguments)]
    fn scatter_nondiffuse(
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

    /// Radiance of the diffuse lobe: albedo × [`Self::irradiance`] with one sample.
    fn diffuse(
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
    fn first_irradiance(
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
    fn specular_direct(
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

    /// Samples the opaque specular lobe: (direction, Fresnel, geometric weight), so that the
    /// estimator of the reflected radiance is F · g · L(direction).
    fn sample_specular(
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
    #[allow(clippy::too_many_arguments)]
    fn dielectric(
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
        if depth == 0 && f < 1.0 {
            // At a camera ray's first hit both children are traced (weights F and 1 − F),
            // deeper interfaces choose one by Fresnel.
            let r = reflect(dir, n);
            let reflected = self.radiance(
                offset_origin(sp.position, sp.geometric_normal, r),
                r,
                1,
                diffuse_left,
                true,
                None,
                ctx,
            );
            let refracted = match refract(dir, n, eta) {
                Some(t) => {
                    let o = offset_origin(sp.position, sp.geometric_normal, t);
                    self.radiance(o, t, 1, diffuse_left, true, None, ctx)
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

    /// Traces one camera ray and segments its radiance (thesis 3.1, 5.7, 6.2).
    /// `record` asks for the outgoing-ray records of refractive objects.
    pub fn camera_sample(
        &self,
        origin: Vec3,
        dir: Vec3,
        record: bool,
        ctx: &mut PathContext,
    ) -> CameraSample {
        let hit = self.trace(origin, dir, None, ctx);
        let tmax = hit.map_or(f32::INFINITY, |h| h.t);
        if let Some((_, l)) = hit_light_sphere(&self.frame.lights, origin, dir, tmax) {
            return CameraSample { combined: l, ..Default::default() };
        }
        let Some(hit) = hit else {
            // The environment is drawn behind the objects only when asked for (`background`):
            // the player draws none, and no object's layer holds it.
            let combined = match &self.environment {
                Some(env) if env.environment.background => env.radiance(dir),
                _ => Vec3::ZERO,
            };
            return CameraSample { combined, ..Default::default() };
        };
        let mut sp = self.geometry.surface(&hit, origin, dir);
        let m = self.material(&mut sp);
        let diffuse_left = self.settings.diffuse_bounces.max(1);
        let diffuse = if luminance(m.diffuse) > 0.0 {
            m.diffuse * self.first_irradiance(&sp, diffuse_left, ctx)
        } else {
            Vec3::ZERO
        };
        // The specular lobes draw from their own stream of the surface point.
        let mut rng = self.rng_at(&sp, FIRST_HIT_SPECULAR_STREAM, ctx);
        let mut out = CameraSample { object: Some(hit.object), diffuse, ..Default::default() };
        let role = self.role(hit.object);
        let mut specular = m.emission;
        match role {
            ObjectRole::Reflective => {
                let (refl, contrib) =
                    self.reflective_layers(&sp, &m, dir, hit.object, diffuse_left, &mut rng, ctx);
                out.reflective = Some(refl);
                specular += contrib;
                if m.transmission > 0.0 {
                    specular += self.dielectric(&sp, &m, dir, 0, diffuse_left, &mut rng, ctx)
                        * m.transmission;
                }
            }
            ObjectRole::Refractive => {
                let terms = [GreedyTerm::ReflectionFirst, GreedyTerm::RefractionFirst].map(|t| {
                    self.greedy_term(&sp, &m, dir, hit.object, t, record, diffuse_left, ctx)
                });
                out.lens = Some(terms);
                specular +=
                    self.scatter_nondiffuse(&sp, &m, dir, 0, diffuse_left, &mut rng, ctx, None);
            }
            ObjectRole::Diffuse => {
                specular +=
                    self.scatter_nondiffuse(&sp, &m, dir, 0, diffuse_left, &mut rng, ctx, None);
            }
        }
        out.specular = specular;
        out.combined = out.diffuse + out.specular;
        out
    }

    /// Fresnel modulation and local/distant incident specular radiance at a reflective
    /// object's first hit; also returns the specular reflection's contribution to the image.
    #[allow(clippy::too_many_arguments)]
    fn reflective_layers(
        &self,
        sp: &SurfacePoint,
        m: &ShadingMaterial,
        dir: Vec3,
        object: u32,
        diffuse_left: u32,
        rng: &mut Rng,
        ctx: &mut PathContext,
    ) -> (ReflectiveSample, Vec3) {
        let cos_o = (-dir).dot(sp.normal).max(0.0);
        let opaque = 1.0 - m.transmission;
        let mut s = ReflectiveSample { fresnel: m.fresnel(cos_o) * opaque, ..Default::default() };
        let Some((d, f, g)) = self.sample_specular(sp, m, dir, rng) else { return (s, Vec3::ZERO) };
        let o = offset_origin(sp.position, sp.geometric_normal, d);
        let hit = self.trace(o, d, None, ctx);
        let light_first =
            hit_light_sphere(&self.frame.lights, o, d, hit.map_or(f32::INFINITY, |h| h.t))
                .is_some();
        let incident = self.radiance_from(hit, o, d, 1, diffuse_left, true, ctx) * g;
        let reflectors = &self.geometry.reflectors;
        let reflector = reflectors[object as usize];
        if !light_first && hit.is_some_and(|h| reflectors[h.object as usize] == reflector) {
            s.local = incident;
            s.local_alpha = 1.0;
            s.distant = self.radiance(o, d, 1, diffuse_left, true, Some(reflector), ctx) * g;
        } else {
            s.distant = incident;
        }
        (s, incident * f * opaque)
    }

    /// Follows one term of the greedy two-path model from the first hit on lens object
    /// `object` until the path leaves the object (thesis 6.2, 6.3.1).
    #[allow(clippy::too_many_arguments)]
    fn greedy_term(
        &self,
        sp: &SurfacePoint,
        m: &ShadingMaterial,
        dir: Vec3,
        object: u32,
        term: GreedyTerm,
        record: bool,
        diffuse_left: u32,
        ctx: &mut PathContext,
    ) -> TermSample {
        let mut out = TermSample::default();
        let eta = if sp.front_face { 1.0 / m.ior } else { m.ior };
        let f = fresnel_dielectric(-dir.dot(sp.normal), eta);
        let (mut d, mut modulation) = match term {
            GreedyTerm::ReflectionFirst => (reflect(dir, sp.normal), Vec3::splat(f)),
            GreedyTerm::RefractionFirst => match refract(dir, sp.normal, eta) {
                Some(t) => {
                    (t, Vec3::splat(1.0 - f) * if sp.front_face { m.base } else { Vec3::ONE })
                }
                None => return out,
            },
        };
        let (mut p, mut ng) = (sp.position, sp.geometric_normal);
        for _ in 0..self.settings.max_depth {
            let o = offset_origin(p, ng, d);
            let hit = self.trace(o, d, None, ctx);
            let light_first =
                hit_light_sphere(&self.frame.lights, o, d, hit.map_or(f32::INFINITY, |h| h.t))
                    .is_some();
            match hit {
                Some(h) if h.object == object && !light_first => {
                    let mut s2 = self.geometry.surface(&h, o, d);
                    let m2 = self.material(&mut s2);
                    modulation *= self.absorption(&s2, &m2, h.t);
                    let eta2 = if s2.front_face { 1.0 / m2.ior } else { m2.ior };
                    let f2 = fresnel_dielectric(-d.dot(s2.normal), eta2);
                    let refracted = if f2 < 0.5 { refract(d, s2.normal, eta2) } else { None };
                    match refracted {
                        Some(t) => {
                            modulation *=
                                (1.0 - f2) * if s2.front_face { m2.base } else { Vec3::ONE };
                            d = t;
                        }
                        None => {
                            modulation *= f2;
                            d = reflect(d, s2.normal);
                        }
                    }
                    p = s2.position;
                    ng = s2.geometric_normal;
                }
                _ => {
                    out.radiance = self.radiance_from(hit, o, d, 1, diffuse_left, true, ctx);
                    out.modulation = modulation;
                    out.exit = Some((o, d));
                    if record {
                        out.hits = self.continued_hits(o, d, object, diffuse_left, ctx);
                    }
                    return out;
                }
            }
        }
        out
    }

    /// Every front-facing hit on environment geometry (not `object`) along a continued ray,
    /// nearest first, with the radiance leaving each towards the ray origin (thesis 6.3.1).
    fn continued_hits(
        &self,
        o: Vec3,
        d: Vec3,
        object: u32,
        diffuse_left: u32,
        ctx: &mut PathContext,
    ) -> Vec<ContinuedHit> {
        ctx.rays += 1;
        let mut hits = Vec::new();
        for h in self.geometry.all_hits(o, d, f32::INFINITY) {
            if hits.len() >= self.settings.max_record_hits as usize {
                break;
            }
            if h.object == object {
                continue;
            }
            let mut sp = self.geometry.surface(&h, o, d);
            if !sp.front_face {
                continue;
            }
            let m = self.material(&mut sp);
            let mut rng = self.rng_at(&sp, 1, ctx);
            let colour = m.emission + self.scatter(&sp, &m, d, 1, diffuse_left, &mut rng, ctx);
            hits.push(ContinuedHit { t: h.t, position: sp.position, object: h.object, colour });
        }
        hits
    }
}

/// The density of the diffuse lobe's sampled direction `d` ([`Integrator`]'s indirect
/// bounce): cosine-weighted about the shading normal `n`, a direction below the geometric
/// surface (normal `ng`) mirrored back above it, so that both the direction and its mirror
/// image lead to `d`.
pub fn diffuse_pdf(n: Vec3, ng: Vec3, d: Vec3) -> f32 {
    let c = ng.dot(d);
    if c <= 0.0 {
        return 0.0;
    }
    let mirrored = d - ng * (2.0 * c);
    (n.dot(d).max(0.0) + n.dot(mirrored).max(0.0)) / PI
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

/// The density of the GGX lobe's reflected direction `l` for the view direction `wo` (both
/// unit, away from the surface) about the shading normal `n`: D(h) (n·h) / (4 (wo·h)), the
/// half vector h drawn proportionally to D(h) (n·h).
pub fn ggx_reflection_pdf(n: Vec3, wo: Vec3, l: Vec3, alpha: f32) -> f32 {
    let h = (wo + l).normalize_or_zero();
    let (nh, vh) = (n.dot(h), wo.dot(h));
    if nh <= 0.0 || vh <= 0.0 {
        return 0.0;
    }
    let a2 = alpha * alpha;
    let dd = nh * nh * (a2 - 1.0) + 1.0;
    a2 / (PI * dd * dd) * nh / (4.0 * vh)
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
