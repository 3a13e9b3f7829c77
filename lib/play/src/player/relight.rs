//! Relightable layers (SPEC.md 7.1, 9; Wong et al.): a coefficient layer's texture is drawn
//! times its weight for the frame's lights, w_c = Σ_j E_j / E₀ · Y_c(ω_j), the basis Y_c
//! being the one the pack fitted with ([`pis_compile::relight::basis`]: the same function,
//! not a twin). Without lights of the user's the frame shows the file's own light at the
//! parameter point: each blended sample's direction, with the sample's blend weight.

use glam::Vec3;
use pis_compile::relight::{basis, coefficients, MAX_BAND};
use pis_format::relight::LightDirections;

/// A directional light of the user's: the direction it comes from (unit, from the scene
/// towards the light) and its radiance (illuminance times colour, linear RGB).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DirectionalLight {
    pub direction: Vec3,
    pub radiance: [f32; 3],
}

/// A file's light directions and the lights a frame shows.
#[derive(Clone, Debug)]
pub struct Relight {
    pub file: LightDirections,
    /// `None`: the file's own light at the parameter point.
    pub lights: Option<Vec<DirectionalLight>>,
}

/// The lights of one frame, as per-light basis values and RGB scales.
pub(super) struct Lit {
    dim: usize,
    /// Per light: its scale E/E₀ per channel and Y_c for every c up to band 8.
    lights: Vec<([f32; 3], Vec<f64>)>,
    /// The file's light: Y_c at each sample of its dimension, where the frame shows it.
    samples: Option<Vec<Vec<f64>>>,
}

fn basis_at(w: Vec3) -> Vec<f64> {
    let mut y = vec![0.0; coefficients(MAX_BAND)];
    basis(MAX_BAND, w.normalize_or(Vec3::Y), &mut y);
    y
}

impl Relight {
    /// The lights of a frame blended from `samples` (sample, weight).
    pub(super) fn lit(&self, samples: &[(Vec<u32>, f32)]) -> Lit {
        let e0 = self.file.radiance;
        match &self.lights {
            Some(lights) => Lit {
                dim: self.file.dim,
                lights: lights
                    .iter()
                    .map(|l| {
                        let scale = [0, 1, 2].map(|c| l.radiance[c] / e0[c]);
                        (scale, basis_at(l.direction))
                    })
                    .collect(),
                samples: None,
            },
            None => {
                let mut used: Vec<Option<Vec<f64>>> = vec![None; self.file.directions.len()];
                for (s, _) in samples {
                    let i = s[self.file.dim] as usize;
                    if let Some(slot) = used.get_mut(i).filter(|u| u.is_none()) {
                        *slot = Some(basis_at(Vec3::from(self.file.directions[i])));
                    }
                }
                Lit {
                    dim: self.file.dim,
                    lights: Vec::new(),
                    samples: Some(used.into_iter().map(Option::unwrap_or_default).collect()),
                }
            }
        }
    }
}

impl Lit {
    /// Coefficient c's weight, per channel, for a class of blended samples `members`
    /// (sample, weight) that a layer cannot tell apart: the user's lights, or the file's
    /// light at each member's light sample, averaged by the members' weights.
    pub(super) fn weight(&self, c: usize, members: &[&(Vec<u32>, f32)]) -> [f32; 3] {
        match &self.samples {
            Some(per_sample) => {
                let total: f32 = members.iter().map(|m| m.1).sum();
                let y: f64 = members
                    .iter()
                    .map(|(s, w)| {
                        let y = per_sample.get(s[self.dim] as usize).and_then(|y| y.get(c));
                        *w as f64 * y.copied().unwrap_or(0.0)
                    })
                    .sum();
                [(y / total.max(f32::MIN_POSITIVE) as f64) as f32; 3]
            }
            None => {
                let mut w = [0.0f64; 3];
                for (scale, y) in &self.lights {
                    for ch in 0..3 {
                        w[ch] += scale[ch] as f64 * y.get(c).copied().unwrap_or(0.0);
                    }
                }
                w.map(|v| v as f32)
            }
        }
    }
}
