//! Relightable layers (SPEC.md 7.1, 9; Wong et al.): a coefficient layer's texture is drawn
//! times its weight for the frame's lights, w_c = Σ_j E_j / E₀ · Y_c(ω_j) (+ s_c / E₀ for a
//! sky), computed by [`pis_compile::relight::Lights::weights`], the function the pack's
//! basis and `pis-bench relight` use: the same function, not a twin. Without lights of the
//! user's the frame shows the file's own light at the parameter point: each blended
//! sample's direction, with the sample's blend weight.

use glam::Vec3;
use pis_compile::relight::{basis, coefficients, Lights, MAX_BAND};
use pis_format::relight::LightDirections;

/// A file's light directions and the lights a frame shows.
#[derive(Clone, Debug)]
pub struct Relight {
    pub file: LightDirections,
    /// `None`: the file's own light at the parameter point.
    pub lights: Option<Lights>,
}

/// The lights of one frame, as coefficient weights.
pub(super) struct Lit {
    dim: usize,
    /// The user's lights: w_c (RGB) for every c up to band 8.
    weights: Vec<[f64; 3]>,
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
        match &self.lights {
            Some(lights) => Lit {
                dim: self.file.dim,
                weights: lights.weights(self.file.radiance, MAX_BAND),
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
                    weights: Vec::new(),
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
            None => self.weights.get(c).map_or([0.0; 3], |w| w.map(|v| v as f32)),
        }
    }
}
