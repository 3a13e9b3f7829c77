//! Relightable surface textures (Wong et al., seed 003, on the thesis's textures): where the
//! set turns a light over a hemisphere or the sphere (`light_direction`), each surface layer
//! of an object is stored as spherical-harmonic coefficient textures x_c over the light
//! direction ω, such that Σ_c Y_c(ω_i)·A·x_c matches the traced layer at every light sample
//! ω_i: one set of coefficients per sample of the other dimensions, serving every light
//! direction, any number of lights and a sky by superposition.
//!
//! The joint least-squares solve separates: with the same render matrices A at every light
//! sample of a view, it is the texture solved at each light sample (chapter 3's solver,
//! warm-started along the samples) fitted per texel to the basis
//! ([`pis_compile::relight::LightFit`], with Wong's fill of an unsampled lower hemisphere).
//! The band is chosen per layer by measurement ("model no more than a scene needs"): every
//! eighth light sample is held out, each band fitted from the others predicts it through A,
//! and the smallest band within [`BAND_MARGIN`] of the best held-out error is kept.

use std::sync::Arc;

use anyhow::{anyhow, Result};
use glam::Vec3;
use pis_compile::relight::{basis, coefficients, Cover, LightFit, MAX_BAND};
use pis_compile::SolveSettings;
use pis_format::DepMask;
use pis_scene::{Driver, LightKind};

use super::input::LoadedSet;
use super::mesh::Placed;
use super::model::{key, InferredLayer, LightBasis, Views};
use super::radiance::Radiance;
use super::sample::{LayerPlan, Sample};
use super::texture_form::TextureForm;
use super::textures::Textures;
use crate::solutions::Solver;

/// The held-out error a smaller band may exceed the best band's by and still be kept
/// (5%, 0.2 dB).
pub const BAND_MARGIN: f64 = 1.05;

/// Every `HOLD_OUT`-th light sample, from the fourth, is held out to choose the band.
const HOLD_OUT: usize = 8;

/// A set's light-direction dimension, as the relightable layers span it.
#[derive(Clone, Debug)]
pub struct Relit {
    /// The dimension's index.
    pub dim: usize,
    pub name: String,
    pub directions: Vec<Vec3>,
    pub cover: Cover,
    /// The radiance the samples were traced with: a directional light's illuminance times
    /// its colour; a placed light's intensity over the squared distance to its centre.
    pub radiance: [f32; 3],
}

impl Relit {
    /// The set's light-direction dimension, where it has one.
    pub fn of(set: &LoadedSet) -> Option<Relit> {
        let dims = &set.scene.space.dims;
        let (dim, d) = dims
            .iter()
            .enumerate()
            .find(|(_, d)| matches!(d.driver, Driver::LightDirection { .. }))?;
        let Driver::LightDirection { light, directions, distance, arc, .. } = &d.driver else {
            return None;
        };
        if *arc {
            // An arc does not span the directions a basis is fitted over.
            return None;
        }
        let lit = set.frames.first()?.lights.iter().find(|l| &l.name == light)?;
        let scale =
            if lit.kind == LightKind::Directional { 1.0 } else { 1.0 / (distance * distance) };
        let below = directions.iter().any(|w| w.y < -1e-6);
        Some(Relit {
            dim,
            name: d.name.clone(),
            directions: directions.clone(),
            cover: if below { Cover::Sphere } else { Cover::Hemisphere(Vec3::Y) },
            radiance: lit.radiance.map(|c| c * scale),
        })
    }

    /// The mask `mask` without the light dimension.
    pub fn without(&self, mask: DepMask) -> DepMask {
        DepMask(mask.0 & !(1 << self.dim))
    }

    /// The file's settings that record the directions (SPEC.md 6.6).
    pub fn settings(&self) -> [(String, String); 2] {
        let l = pis_format::relight::LightDirections {
            dim: self.dim,
            radiance: self.radiance,
            directions: self.directions.iter().map(|w| w.to_array()).collect(),
        };
        pis_format::relight::light_settings(&self.name, &l)
    }
}

/// The textures of one coefficient key: per light sample, its solved texture.
struct OverLight {
    key: Vec<u32>,
    placement: usize,
    /// Per light sample: the points it was solved from.
    points: Vec<Vec<usize>>,
    textures: Vec<Vec<f32>>,
}

/// The layer `plan` (its mask without the light dimension) solved as coefficient layers,
/// with a sentence on the band chosen.
pub(super) fn solve_relit_layer(
    set: &LoadedSet,
    views: &Views,
    placements: &[Placed],
    plan: &LayerPlan,
    (settings, solver): (&SolveSettings, &Solver),
    relit: &Relit,
) -> Result<(Vec<InferredLayer>, String)> {
    let (keys, iterations) =
        solve_over_light(set, views, placements, plan, (settings, solver), relit)?;
    let (fit, why) = choose_band(views, plan, &keys, relit)?;
    let c_count = coefficients(fit.l_max);
    let mut layers: Vec<Textures> =
        (0..c_count).map(|_| Textures::new(set.scratch.as_ref())).collect();
    let mut placement_of = std::collections::BTreeMap::new();
    for k in &keys {
        let refs: Vec<&[f32]> = k.textures.iter().map(Vec::as_slice).collect();
        for (c, x) in fit.project(&refs).into_iter().enumerate() {
            layers[c].insert(k.key.clone(), x)?;
        }
        placement_of.insert(k.key.clone(), k.placement);
    }
    let mut y = vec![0.0; c_count];
    let per_point: Vec<Vec<f32>> = set
        .samples
        .iter()
        .map(|s| {
            basis(fit.l_max, relit.directions[s[relit.dim] as usize], &mut y);
            y.iter().map(|&v| v as f32).collect()
        })
        .collect();
    let out = layers
        .into_iter()
        .enumerate()
        .map(|(c, textures)| InferredLayer {
            kind: plan.kind,
            depends_on: plan.depends_on,
            textures,
            block_placements: plan.block_placements.clone(),
            placement_of: placement_of.clone(),
            iterations: if c == 0 { iterations } else { 0 },
            form: Box::new(TextureForm {
                placements: placements.to_vec(),
                block_placements: plan.block_placements.clone(),
                placement_of: placement_of.clone(),
                channels: 3,
            }),
            shell: None,
            light: Some(LightBasis {
                c,
                weights: Arc::new(per_point.iter().map(|w| w[c]).collect()),
            }),
        })
        .collect();
    Ok((out, why))
}

/// Every coefficient key's textures at each light sample, solved from the key's points at
/// that sample (stacked over the views for a view-independent layer), warm-started from the
/// previous light sample's; and the solver's iterations.
fn solve_over_light(
    set: &LoadedSet,
    views: &Views,
    placements: &[Placed],
    plan: &LayerPlan,
    (settings, solver): (&SolveSettings, &Solver),
    relit: &Relit,
) -> Result<(Vec<OverLight>, u64)> {
    let n = relit.directions.len();
    let mut groups: std::collections::BTreeMap<Vec<u32>, Vec<Vec<usize>>> = Default::default();
    for (p, s) in set.samples.iter().enumerate() {
        let g = groups.entry(key(s, plan.depends_on)).or_insert_with(|| vec![Vec::new(); n]);
        g[s[relit.dim] as usize].push(p);
    }
    let view_independent = plan.radiance == Radiance::Diffuse;
    let mut iterations = 0;
    let mut out = Vec::new();
    for (k, points) in groups {
        let pid = plan.point_placement[points[0][0]];
        let mut textures: Vec<Vec<f32>> = Vec::with_capacity(n);
        for ps in &points {
            let sample = Sample { views, points: ps, placement: &placements[pid], pid };
            let start = textures.last().map(Vec::as_slice);
            let (x, it) = sample.solve(plan.radiance, view_independent, start, settings, solver)?;
            iterations += it;
            textures.push(x);
        }
        out.push(OverLight { key: k, placement: pid, points, textures });
    }
    Ok((out, iterations))
}

/// The band whose fit predicts the held-out light samples best, or the smallest within
/// [`BAND_MARGIN`] of it, fitted again from every sample; and why, in a sentence.
fn choose_band(
    views: &Views,
    plan: &LayerPlan,
    keys: &[OverLight],
    relit: &Relit,
) -> Result<(LightFit, String)> {
    let n = relit.directions.len();
    let held: Vec<usize> = (HOLD_OUT / 2..n).step_by(HOLD_OUT).collect();
    let kept: Vec<usize> = (0..n).filter(|i| !held.contains(i)).collect();
    let dirs: Vec<Vec3> = kept.iter().map(|&i| relit.directions[i]).collect();
    let mut tried: Vec<(u32, f64)> = Vec::new();
    for band in 0..=MAX_BAND {
        let Some(fit) = LightFit::new(band, &dirs, relit.cover) else { break };
        if held.is_empty() {
            break;
        }
        let mut sse = 0.0f64;
        let mut y = vec![0.0; coefficients(band)];
        for k in keys {
            let refs: Vec<&[f32]> = kept.iter().map(|&i| k.textures[i].as_slice()).collect();
            let x = fit.project(&refs);
            for &i in &held {
                basis(band, relit.directions[i], &mut y);
                let t: Vec<f32> = (0..x[0].len())
                    .map(|v| x.iter().zip(&y).map(|(xc, yc)| xc[v] as f64 * yc).sum::<f64>() as f32)
                    .collect();
                for &p in &k.points[i] {
                    let v = views.get(p)?;
                    let drawn = pis_compile::render(v.a(k.placement), &t);
                    let gold = plan.radiance.at(&v);
                    sse += drawn
                        .iter()
                        .zip(gold.iter())
                        .map(|(a, b)| ((a - b) as f64).powi(2))
                        .sum::<f64>();
                }
            }
        }
        tried.push((band, sse));
    }
    let best = tried.iter().map(|t| t.1).fold(f64::INFINITY, f64::min);
    let band = tried.iter().find(|t| t.1 <= best * BAND_MARGIN).map_or(0, |t| t.0);
    let all = relit.directions.clone();
    let fit = LightFit::new(band, &all, relit.cover)
        .ok_or_else(|| anyhow!("{} light samples fit no spherical-harmonic band", n))?;
    let figures: Vec<String> = tried
        .iter()
        .map(|(b, e)| {
            format!("band {b} {:+.2} dB", 10.0 * (best.max(1e-30) / e.max(1e-30)).log10())
        })
        .collect();
    let why = format!(
        "{} over the light: band {band} ({} coefficients), the smallest within {:.1} dB of the best at {} held-out light directions ({})",
        plan.kind.name(),
        coefficients(band),
        10.0 * BAND_MARGIN.log10(),
        held.len(),
        figures.join(", ")
    );
    Ok((fit, why))
}
