//! How well a set traced over light directions can be relit at all (seed 003): each pixel of
//! the traced set fitted to the spherical harmonics up to a band, losslessly (no texture, no
//! coding), and drawn under the lights of each point of a second set (other directions, two
//! coloured lights, a sky). This is the truncation's own ceiling that any stored form of the
//! fit stays under; beside it, what the sampled dimension can show under those lights: the
//! image of the sampled direction nearest each directional light, by its colour.

use std::path::Path;

use anyhow::{anyhow, bail, Context, Result};
use glam::Vec3;
use pis_compile::relight::{coefficients, Cover, DirectionalLight, LightFit, Lights};
use pis_trace::set::RaySet;

use super::held::{light_dimension, others, HeldLights, Placement};
use super::CeilingRow;
use crate::metrics::SquaredError;

/// The combined images of `set`'s points whose samples less dimension `k` are `rest`, in
/// point order, with their point indices.
fn images_at(set: &RaySet, k: Option<usize>, rest: &[u32]) -> Result<Vec<(usize, Vec<f32>)>> {
    let mut out = Vec::new();
    for (i, p) in set.meta.points.iter().enumerate() {
        if others(&p.samples, k) == rest {
            let images = set.read_point(i)?;
            let c = images.layer("combined").ok_or_else(|| anyhow!("point {i}: no combined"))?;
            let n = c.planes[0].len();
            out.push((i, (0..n * 3).map(|v| c.planes[v % 3][v / 3]).collect()));
        }
    }
    Ok(out)
}

/// The irradiance of the fitted set's light: the directional light shining from the first
/// point's direction.
fn fitted_e0(set: &RaySet, k: usize, dirs: &[Vec3]) -> Option<[f32; 3]> {
    let p = set.meta.points.first()?;
    let w = dirs.get(p.samples[k] as usize)?;
    p.lights
        .iter()
        .find(|l| l.kind == "directional" && Vec3::from(l.direction).dot(*w) < -0.999)
        .map(|l| l.radiance)
}

/// The non-light dimensions' names of a set.
fn other_names(set: &RaySet, k: Option<usize>) -> Vec<&str> {
    let dims = set.meta.space.iter().enumerate();
    dims.filter(|(j, _)| Some(*j) != k).map(|(_, d)| d.name.as_str()).collect()
}

/// The ceiling table of `set` (fitted) under the lights of `held`'s points (its other
/// dimensions as `set`'s), for each band in `bands`.
pub fn ceiling(set: &Path, held: &Path, bands: &[u32], cover: Cover) -> Result<Vec<CeilingRow>> {
    let set = RaySet::open(set).context("the fitted set")?;
    let held = RaySet::open(held).context("the held-out set")?;
    let (k, dirs) = light_dimension(&set)?
        .ok_or_else(|| anyhow!("{}: no light_direction dimension", set.dir.display()))?;
    let placement = Placement::of(&set, k, &dirs)?;
    let e0 = placement.map(|p| p.radiance).or_else(|| fitted_e0(&set, k, &dirs));
    let lights = HeldLights::of(&held, e0.unwrap_or([1.0; 3]), placement.as_ref())?;
    if lights.dim.is_none() && e0.is_none() {
        bail!(
            "{}: the fitted light is neither directional nor placed: its irradiance is unknown",
            set.dir.display()
        );
    }
    let e0 = e0.unwrap_or([1.0; 3]);
    let hk = lights.dim.as_ref().map(|d| d.0);
    if other_names(&set, Some(k)) != other_names(&held, hk) {
        bail!("the two sets' parameter spaces differ beyond the light");
    }
    let mut groups: Vec<Vec<u32>> =
        set.meta.points.iter().map(|p| others(&p.samples, Some(k))).collect();
    groups.sort();
    groups.dedup();
    let fits: Vec<Option<LightFit>> =
        bands.iter().map(|&b| LightFit::new(b, &dirs, cover)).collect();
    let mut errors = vec![(SquaredError::default(), SquaredError::default()); bands.len() + 1];
    for rest in &groups {
        let fitted: Vec<Vec<f32>> =
            images_at(&set, Some(k), rest)?.into_iter().map(|(_, v)| v).collect();
        let truth = images_at(&held, hk, rest)?;
        let refs: Vec<&[f32]> = fitted.iter().map(|v| v.as_slice()).collect();
        for (row, fit) in fits.iter().enumerate() {
            let Some(fit) = fit else { continue };
            let x = fit.project(&refs);
            let draw = |w: &[[f64; 3]], t: &[f32], e: &mut SquaredError| {
                let img: Vec<f32> = (0..t.len())
                    .map(|v| {
                        x.iter().zip(w).map(|(xc, wc)| xc[v] as f64 * wc[v % 3]).sum::<f64>() as f32
                    })
                    .collect();
                e.add_slices(&img, t);
            };
            for (i, t) in &truth {
                draw(&lights.points[*i].weights(e0, fit.l_max), t, &mut errors[row].0);
            }
            for (t, w) in fitted.iter().zip(&dirs) {
                let own = Lights {
                    directional: vec![DirectionalLight { direction: *w, radiance: e0 }],
                    sky: None,
                };
                draw(&own.weights(e0, fit.l_max), t, &mut errors[row].1);
            }
        }
        if !lights.has_sky() {
            for (i, t) in &truth {
                errors[bands.len()]
                    .0
                    .add_slices(&nearest_image(&fitted, &dirs, &lights.points[*i], e0), t);
            }
        }
    }
    let mut rows: Vec<CeilingRow> = bands
        .iter()
        .zip(&fits)
        .zip(&errors)
        .filter(|((_, f), _)| f.is_some())
        .map(|((&b, _), (h, s))| CeilingRow {
            band: Some(b),
            coefficients: coefficients(b),
            held_out_db: h.psnr(),
            samples_db: s.psnr(),
        })
        .collect();
    if !lights.has_sky() {
        rows.push(CeilingRow {
            band: None,
            coefficients: 0,
            held_out_db: errors[bands.len()].0.psnr(),
            samples_db: f64::INFINITY,
        });
    }
    Ok(rows)
}

/// What samples of the light show under directional `lights`: for each light, the image of
/// the sampled direction nearest it, scaled by the light's colour over E₀, added.
fn nearest_image(fitted: &[Vec<f32>], dirs: &[Vec3], lights: &Lights, e0: [f32; 3]) -> Vec<f32> {
    let mut out = vec![0.0f32; fitted.first().map_or(0, Vec::len)];
    for l in &lights.directional {
        let near = (0..dirs.len())
            .max_by(|&a, &b| dirs[a].dot(l.direction).total_cmp(&dirs[b].dot(l.direction)))
            .unwrap_or(0);
        for (v, (o, f)) in out.iter_mut().zip(&fitted[near]).enumerate() {
            *o += f * l.radiance[v % 3] / e0[v % 3].max(f32::MIN_POSITIVE);
        }
    }
    out
}

/// [`ceiling`] with the cover the fitted set's directions span (the upper hemisphere, or
/// the sphere where a direction lies below the horizon).
pub fn ceiling_of(set: &Path, held: &Path, bands: &[u32]) -> Result<Vec<CeilingRow>> {
    let fitted = RaySet::open(set).context("the fitted set")?;
    let (_, dirs) = light_dimension(&fitted)?
        .ok_or_else(|| anyhow!("{}: no light_direction dimension", fitted.dir.display()))?;
    let cover =
        if dirs.iter().any(|w| w.y < -1e-6) { Cover::Sphere } else { Cover::Hemisphere(Vec3::Y) };
    ceiling(set, held, bands, cover)
}

/// Where `set`'s light dimension placed its light, if it placed one (a point or sphere light).
pub fn placement_of(set: &Path) -> Result<Option<Placement>> {
    let set = RaySet::open(set).context("the fitted set")?;
    let Some((k, dirs)) = light_dimension(&set)? else { return Ok(None) };
    Placement::of(&set, k, &dirs)
}
