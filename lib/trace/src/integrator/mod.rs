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
//!
//! Here: radiance along a ray. The rest, in the order a camera ray meets it: `first_hit`
//! (a camera sample segmented into its object's layers), `scatter` (one scattering event,
//! its lobe chosen by weight), `direct` (irradiance and next-event estimation), `pdf` (the
//! lobes' densities, for multiple importance sampling).

use crate::bvh::{Hit, SceneGeometry, SurfacePoint};
use crate::environment::{balance, EnvironmentLight};
use crate::lights::hit_light_sphere;
use crate::material::ShadingMaterial;
use crate::sampling::Rng;
use crate::settings::TraceSettings;
use glam::Vec3;
use pis_scene::{Frame, ObjectRole, Scene};

mod direct;
mod first_hit;
mod guide;
mod pdf;
mod scatter;

pub use first_hit::{CameraSample, ContinuedHit, ReflectiveSample, TermSample};
pub use guide::Guide;
pub use pdf::{diffuse_pdf, ggx_reflection_pdf};
pub use scatter::{NEE_ALPHA, ROULETTE_WEIGHT};

/// Key of a surface cell: quantized object-space point, object, front or back side.
pub type CellKey = (i64, i64, i64, u32, bool);

/// Pixels on an image's longer side up to which the default surface cell is 1/4096 of the
/// scene's diagonal.
const CELL_PIXELS: f32 = 160.0;

/// The surface cell where [`TraceSettings::coherence_cell`] is `None`: 1/N of the scene's
/// diagonal, N [`TraceSettings::shading_cells`] or by default 4096 for images up to
/// [`CELL_PIXELS`] on their longer side and more in proportion beyond, so that a pixel spans
/// about as many cells at every size. A pixel's camera samples then meet about as many
/// independent first-hit irradiance estimates at 640×480 as at 160×120, and its noise stays
/// its own rather than a pattern shared with its neighbours, which a denoiser cannot tell
/// from texture.
fn default_cell(diag: f32, settings: &TraceSettings) -> f32 {
    if diag <= 0.0 {
        return 0.0;
    }
    let cells = match settings.shading_cells {
        Some(n) => n.max(1) as f32,
        None => {
            let (w, h) = settings.resolution;
            4096.0 * (w.max(h) as f32 / CELL_PIXELS).max(1.0)
        }
    };
    diag / cells
}

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

impl<'s> Integrator<'s> {
    /// Builds the geometry of `scene` at `frame`.
    pub fn new(scene: &'s Scene, frame: &'s Frame, settings: &TraceSettings) -> Integrator<'s> {
        let geometry = SceneGeometry::build(scene, frame);
        let cell = match settings.coherence_cell {
            Some(c) => c.max(0.0),
            None => default_cell((geometry.bounds.1 - geometry.bounds.0).length(), settings),
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
    #[allow(
        clippy::too_many_arguments,
        reason = "the ray, the path's state and the density to weigh the environment by, each apart"
    )]
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
    #[allow(
        clippy::too_many_arguments,
        reason = "the ray, the path's state and what the ray sees, each apart"
    )]
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
    #[allow(
        clippy::too_many_arguments,
        reason = "the ray with its hit, the path's state and what the ray sees, each apart"
    )]
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
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_cell_keeps_a_pixels_share_of_cells_at_every_size() {
        let cell = |w, h| default_cell(4096.0, &TraceSettings::new((w, h), 16));
        assert_eq!(cell(160, 120), 1.0);
        assert_eq!(cell(80, 60), 1.0, "never coarser than at 160 pixels");
        assert_eq!(cell(640, 480), 0.25, "four times the pixels across, a quarter the cell");
        assert_eq!(cell(480, 640), 0.25, "the longer side counts");
        assert_eq!(default_cell(0.0, &TraceSettings::new((640, 480), 16)), 0.0);
        let set = TraceSettings::new((640, 480), 16).with_shading_cells(Some(4096));
        assert_eq!(default_cell(4096.0, &set), 1.0, "--shading-cells 4096");
    }
}
