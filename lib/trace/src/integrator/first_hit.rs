//! A camera ray's first hit, segmented into the layers of its object (thesis 3.1, 5.7,
//! 6.2): diffuse and specular, a reflective object's local and distant reflections, and a
//! lens object's terms with the hits along their continued exit rays.

use super::guide::Guide;
use super::{Integrator, PathContext};
use crate::bvh::{offset_origin, SurfacePoint};
use crate::lights::{camera_hit_light_sphere, hit_light_sphere};
use crate::material::ShadingMaterial;
use crate::sampling::{luminance, Rng};
use glam::Vec3;
use pis_scene::lens_tree::{lens_paths, LensInterface, Step, MAX_TERMS};
use pis_scene::ObjectRole;

/// Seed stream of the specular lobes at a camera ray's first hit (the depth slot of
/// [`Rng::at_surface`]; paths use their depth, the first-hit irradiance depth 0).
const FIRST_HIT_SPECULAR_STREAM: u32 = 0x8000_0000;

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

/// One term of the lens model for one camera sample.
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
    /// The lens model's terms for refractive objects: reflection-first, refraction-first and
    /// (the tree) refraction-first with one and two internal reflections.
    pub lens: Option<[TermSample; MAX_TERMS]>,
    /// The denoiser's guides (renders that denoise only; else zero).
    pub guide: Guide,
}

impl Integrator<'_> {
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
        if let Some((_, l)) = camera_hit_light_sphere(&self.frame.lights, origin, dir, tmax) {
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
        let guide =
            if self.settings.denoise { self.guide(&sp, &m, dir, ctx) } else { Guide::default() };
        let mut out =
            CameraSample { object: Some(hit.object), diffuse, guide, ..Default::default() };
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
                out.lens =
                    Some(self.lens_terms(&sp, &m, dir, hit.object, record, diffuse_left, ctx));
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
    #[allow(
        clippy::too_many_arguments,
        reason = "the first hit's surface, material and object, the ray and the path's state, each apart"
    )]
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

    /// The terms of the lens model from the first hit on lens object `object`, each path
    /// followed until it leaves the object (thesis 6.2, 6.3.1, 7.3; [`lens_paths`]), with the
    /// radiance along its exit ray.
    #[allow(
        clippy::too_many_arguments,
        reason = "the first hit's surface, material and object, the ray and the path's state, each apart"
    )]
    fn lens_terms(
        &self,
        sp: &SurfacePoint,
        m: &ShadingMaterial,
        dir: Vec3,
        object: u32,
        record: bool,
        diffuse_left: u32,
        ctx: &mut PathContext,
    ) -> [TermSample; MAX_TERMS] {
        let first = LensInterface {
            position: sp.position,
            normal: sp.normal,
            geometric_normal: sp.geometric_normal,
            front_face: sp.front_face,
            ior: m.ior,
            base: m.base,
            absorption: Vec3::ONE,
        };
        let paths =
            lens_paths(&first, dir, self.settings.lens_model, self.settings.max_depth, |o, d| {
                let hit = self.trace(o, d, None, ctx);
                let light_first =
                    hit_light_sphere(&self.frame.lights, o, d, hit.map_or(f32::INFINITY, |h| h.t))
                        .is_some();
                match hit {
                    Some(h) if h.object == object && !light_first => {
                        let mut s2 = self.geometry.surface(&h, o, d);
                        let m2 = self.material(&mut s2);
                        Step::Interface(LensInterface {
                            position: s2.position,
                            normal: s2.normal,
                            geometric_normal: s2.geometric_normal,
                            front_face: s2.front_face,
                            ior: m2.ior,
                            base: m2.base,
                            absorption: self.absorption(&s2, &m2, h.t),
                        })
                    }
                    _ => Step::Exit(hit),
                }
            });
        paths.map(|path| {
            let Some(p) = path else { return TermSample::default() };
            let (o, d) = (p.exit_origin, p.exit_direction);
            // The exit ray at the depth a path tracer reaches it (one per interface), so
            // that the term sees what the traced image sees of long paths.
            let depth = p.topology.interfaces as u32;
            TermSample {
                modulation: p.modulation,
                radiance: self.radiance_from(p.exit, o, d, depth, diffuse_left, true, ctx),
                exit: Some((o, d)),
                hits: if record {
                    self.continued_hits((o, d), depth, object, diffuse_left, ctx)
                } else {
                    Vec::new()
                },
            }
        })
    }

    /// Every front-facing hit on environment geometry (not `object`) along a continued ray,
    /// nearest first, with the radiance leaving each towards the ray origin (thesis 6.3.1),
    /// shaded at the exit ray's `depth` (as the term's radiance).
    fn continued_hits(
        &self,
        (o, d): (Vec3, Vec3),
        depth: u32,
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
            let mut rng = self.rng_at(&sp, depth, ctx);
            let colour = m.emission + self.scatter(&sp, &m, d, depth, diffuse_left, &mut rng, ctx);
            hits.push(ContinuedHit { t: h.t, position: sp.position, object: h.object, colour });
        }
        hits
    }
}
