//! What lit each point of a held-out set: the light of a `light_direction` dimension from
//! the point's direction (of the traced irradiance E₀), or the scene's own lights, traced
//! with exactly those lights: its directional lights (set.json's per-point lights) and its
//! `[environment]` projected into the basis as one more light (seed 003, 2.4).

use anyhow::{anyhow, bail, Context, Result};
use glam::Vec3;
use pis_compile::relight::{
    project_lat_long, reduce_lat_long, DirectionalLight, Lights, MAX_BAND, SKY_PROJECTED_SIZE,
};
use pis_scene::EnvironmentRadiance;
use pis_trace::set::RaySet;

/// The light dimension of a set, if any: its index and its directions.
pub fn light_dimension(set: &RaySet) -> Result<Option<(usize, Vec<Vec3>)>> {
    let Some((k, d)) =
        set.meta.space.iter().enumerate().find(|(_, d)| d.driver == "light_direction")
    else {
        return Ok(None);
    };
    let dirs = d.directions.as_ref().ok_or_else(|| {
        anyhow!("{}: dimension `{}` records no directions", set.dir.display(), d.name)
    })?;
    Ok(Some((k, dirs.iter().map(|&w| Vec3::from(w)).collect())))
}

/// A point's samples without the light dimension `k`.
pub fn others(samples: &[u32], k: Option<usize>) -> Vec<u32> {
    samples.iter().enumerate().filter(|(j, _)| Some(*j) != k).map(|(_, s)| *s).collect()
}

/// How a held-out set was lit.
pub struct HeldLights {
    /// Its light dimension, where its points differ by one light's direction.
    pub dim: Option<(usize, Vec<Vec3>)>,
    /// Each point's lights; a light-dimension point's light has irradiance `e0`.
    pub points: Vec<Lights>,
}

impl HeldLights {
    /// The lights of every point of `held`; `e0` is the irradiance of the fitted light.
    pub fn of(held: &RaySet, e0: [f32; 3]) -> Result<HeldLights> {
        let dim = light_dimension(held)?;
        if let Some((k, dirs)) = &dim {
            let points = held
                .meta
                .points
                .iter()
                .map(|p| Lights {
                    directional: vec![DirectionalLight {
                        direction: dirs[p.samples[*k] as usize],
                        radiance: e0,
                    }],
                    sky: None,
                })
                .collect();
            return Ok(HeldLights { dim, points });
        }
        let sky = scene_sky(held)?;
        let mut points = Vec::with_capacity(held.meta.points.len());
        for (i, p) in held.meta.points.iter().enumerate() {
            let mut directional = Vec::new();
            for l in &p.lights {
                if l.kind != "directional" {
                    bail!(
                        "{}: point {i} is lit by {} light `{}`: only directional lights and \
                         the environment relight a file",
                        held.dir.display(),
                        l.kind,
                        l.name
                    );
                }
                let direction = -Vec3::from(l.direction).normalize_or(Vec3::NEG_Y);
                directional.push(DirectionalLight { direction, radiance: l.radiance });
            }
            points.push(Lights { directional, sky: sky.clone() });
        }
        Ok(HeldLights { dim: None, points })
    }

    /// Whether any point is lit by a sky.
    pub fn has_sky(&self) -> bool {
        self.points.iter().any(|l| l.sky.is_some())
    }
}

/// The held-out set's scene environment in the basis, if it has one that emits.
fn scene_sky(held: &RaySet) -> Result<Option<Vec<[f64; 3]>>> {
    let path = held.default_scene();
    let scene = pis_scene::load(&path, None)
        .with_context(|| format!("the held-out set's scene {}", path.display()))?;
    let Some(env) = scene.environment.filter(|e| e.emits()) else {
        return Ok(None);
    };
    let s = match &env.radiance {
        EnvironmentRadiance::Uniform(c) => {
            // ∫ Y_0 dω = 2√π; every other coefficient integrates to zero.
            let k = 2.0 * std::f64::consts::PI.sqrt();
            vec![c.map(|v| v as f64 * k)]
        }
        EnvironmentRadiance::Image(image) => {
            let rgb: Vec<f32> = image.texels.iter().flatten().copied().collect();
            let (w, h) = (image.width as usize, image.height as usize);
            let (w, h, rgb) = reduce_lat_long(w, h, &rgb, SKY_PROJECTED_SIZE);
            project_lat_long(w, h, &rgb, env.rotation, MAX_BAND)
        }
    };
    Ok(Some(s))
}
