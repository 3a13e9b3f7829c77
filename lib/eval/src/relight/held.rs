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

/// Where a light dimension placed its light: at `centre + distance · ω` for each direction ω
/// (a point or sphere light of `radius`; a directional light has no placement).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placement {
    pub centre: Vec3,
    pub distance: f32,
    pub radius: f32,
    /// The placed light's colour × intensity over the squared distance: its irradiance at
    /// the centre, as a file records a placed light's radiance (SPEC.md 6.6).
    pub radiance: [f32; 3],
}

impl Placement {
    /// The placement of `set`'s light dimension `k` of directions `dirs`, from the light
    /// that moves between its points; `None` where that light is directional.
    pub fn of(set: &RaySet, k: usize, dirs: &[Vec3]) -> Result<Option<Placement>> {
        let points = &set.meta.points;
        let Some(first) = points.first() else { return Ok(None) };
        let Some((j, other)) =
            points.iter().enumerate().find(|(_, p)| p.samples.get(k) != first.samples.get(k))
        else {
            return Ok(None);
        };
        let moved = first.lights.iter().zip(&other.lights).position(|(a, b)| {
            a.kind != "directional" && Vec3::from(a.position) != Vec3::from(b.position)
        });
        let Some(l) = moved else { return Ok(None) };
        let at = |i: usize, p: &pis_trace::set::PointMeta| {
            let light = p.lights.get(l);
            let w = p.samples.get(k).and_then(|&s| dirs.get(s as usize));
            match (light, w) {
                (Some(light), Some(&w)) => Ok((Vec3::from(light.position), w)),
                _ => Err(anyhow!(
                    "{}: point {i} lacks the light or its direction",
                    set.dir.display()
                )),
            }
        };
        let ((p0, w0), (p1, w1)) = (at(0, first)?, at(j, other)?);
        let distance = p0.distance(p1) / w0.distance(w1);
        if !(distance.is_finite() && distance > 0.0) {
            bail!("{}: two light samples share a direction", set.dir.display());
        }
        let centre = p0 - distance * w0;
        for (i, p) in points.iter().enumerate() {
            let (q, w) = at(i, p)?;
            if q.distance(centre + distance * w) > 1e-3 * distance.max(1.0) {
                bail!(
                    "{}: point {i}: the light stands off the sphere of radius {distance} \
                     about {centre} that the other points place it on",
                    set.dir.display(),
                );
            }
        }
        let light = &first.lights[l];
        let radiance = at_centre(light.radiance, distance);
        Ok(Some(Placement { centre, distance, radius: light.radius, radiance }))
    }

    /// `light` as the placed light moved (the same radius, at the same distance from the
    /// centre): the direction it stands in and its radiance as [`Placement::radiance`].
    fn as_placed(&self, light: &pis_trace::set::LightMeta) -> Option<DirectionalLight> {
        let to = Vec3::from(light.position) - self.centre;
        let near = |a: f32, b: f32| (a - b).abs() <= 1e-3 * b.max(1e-3);
        let same = light.kind != "directional"
            && near(light.radius, self.radius)
            && near(to.length(), self.distance);
        same.then(|| DirectionalLight {
            direction: to.normalize(),
            radiance: at_centre(light.radiance, self.distance),
        })
    }
}

/// A light's colour × intensity placed `distance` from the centre, as its irradiance there.
fn at_centre(radiance: [f32; 3], distance: f32) -> [f32; 3] {
    radiance.map(|c| c / (distance * distance))
}

/// How a held-out set was lit.
pub struct HeldLights {
    /// Its light dimension, where its points differ by one light's direction.
    pub dim: Option<(usize, Vec<Vec3>)>,
    /// Each point's lights; a light-dimension point's light has irradiance `e0`.
    pub points: Vec<Lights>,
}

impl HeldLights {
    /// The lights of every point of `held`; `e0` is the irradiance (or, placed, the
    /// radiance) of the fitted light. Where the fitted light was placed (`placement`),
    /// `held`'s lights may be that light placed from other directions.
    pub fn of(held: &RaySet, e0: [f32; 3], placement: Option<&Placement>) -> Result<HeldLights> {
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
                let light = match placement {
                    _ if l.kind == "directional" => DirectionalLight {
                        direction: -Vec3::from(l.direction).normalize_or(Vec3::NEG_Y),
                        radiance: l.radiance,
                    },
                    Some(placed) => placed.as_placed(l).ok_or_else(|| {
                        anyhow!(
                            "{}: point {i} is lit by {} light `{}` of radius {} at {:?}: the \
                             file relights only under its own light of radius {} placed at \
                             {} from {}, directional lights and the environment",
                            held.dir.display(),
                            l.kind,
                            l.name,
                            l.radius,
                            l.position,
                            placed.radius,
                            placed.distance,
                            placed.centre
                        )
                    })?,
                    None => bail!(
                        "{}: point {i} is lit by {} light `{}`: only directional lights and \
                         the environment relight a file traced with a directional light (one \
                         traced with a placed light names its set with --fitted)",
                        held.dir.display(),
                        l.kind,
                        l.name
                    ),
                };
                directional.push(light);
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
