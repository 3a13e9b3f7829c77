//! The least-squares fit of a texel's radiance over the sampled light directions to the
//! spherical-harmonic basis (seed 003, 2.3, by least squares rather than quadrature, as the
//! sampled directions are scattered): x = argmin Σ_i |Σ_c Y_c(ω_i) x_c − t_i|². The basis
//! matrix is the same for every texel, so the fit is one C × N matrix, the **projector**,
//! made once and applied to every texel.
//!
//! Where only a hemisphere is sampled, the lower one is unconstrained and a fit to the
//! upper one alone rings below it and bends above it. Wong et al.'s treatment (section 3,
//! "Preventing Discontinuity") fills it: each sampled direction is mirrored below the
//! horizon, and there the radiance falls linearly, in polar angle, from the horizon's value
//! at the same azimuth to a constant at the lower pole, the horizon's mean. Every filled
//! value is a fixed linear combination of the sampled ones, so the projector holds the fill.
//!
//! Because texture inference is linear with the same render matrices at every light
//! direction of a view, fitting the per-direction solved textures is the joint least-squares
//! solve of Σ_c Y_c(ω_i)·A·x_c ≈ b_i (thesis 3.5) up to the solver's regularization.

use glam::Vec3;
use rayon::prelude::*;

use super::basis::{basis, coefficients, MAX_BAND};

/// Which directions the samples cover.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Cover {
    /// The hemisphere about a pole (unit): the lower one is filled (module comment).
    Hemisphere(Vec3),
    /// Every direction.
    Sphere,
}

/// The fit of one set of sampled directions at one band.
#[derive(Clone, Debug)]
pub struct LightFit {
    pub l_max: u32,
    /// Sampled directions N.
    pub samples: usize,
    /// C × N, row-major: coefficient c is Σ_i projector[c·N + i]·t_i.
    pub projector: Vec<f64>,
}

/// The width, in radians, of the kernel that reads the horizon's value from the samples
/// near it, in units of the samples' mean spacing.
const HORIZON_KERNEL: f64 = 1.5;

impl LightFit {
    /// The fit of samples at `directions` (unit, from the scene towards the light) to the
    /// bands up to `l_max` (≤ [`MAX_BAND`]). `None` when the samples are too few for the
    /// coefficients (N < C) or leave the fit singular.
    pub fn new(l_max: u32, directions: &[Vec3], cover: Cover) -> Option<LightFit> {
        let c = coefficients(l_max);
        let n = directions.len();
        if l_max > MAX_BAND || n < c {
            return None;
        }
        // Rows of the fit: the samples, then for a hemisphere the filled directions, each a
        // combination of the samples (weights over N).
        let mut rows: Vec<(Vec3, Vec<f64>)> = directions
            .iter()
            .enumerate()
            .map(|(i, &w)| {
                let mut unit = vec![0.0; n];
                unit[i] = 1.0;
                (w, unit)
            })
            .collect();
        if let Cover::Hemisphere(up) = cover {
            rows.extend(filled_rows(directions, up));
        }
        // Normal equations (YᵀY) x = Yᵀ (R t), R the rows' weights.
        let mut y = vec![0.0; c];
        let mut normal = vec![0.0f64; c * c];
        let mut rhs = vec![0.0f64; c * n];
        for (w, weights) in &rows {
            basis(l_max, *w, &mut y);
            for a in 0..c {
                for b in 0..c {
                    normal[a * c + b] += y[a] * y[b];
                }
                for (i, wi) in weights.iter().enumerate().filter(|(_, w)| **w != 0.0) {
                    rhs[a * n + i] += y[a] * wi;
                }
            }
        }
        let projector = solve_columns(&mut normal, c, &mut rhs, n)?;
        Some(LightFit { l_max, samples: n, projector })
    }

    /// The coefficients of one value per direction (`values[i]` at direction i).
    pub fn coefficients_of(&self, values: &[f64]) -> Vec<f64> {
        self.projector.chunks_exact(self.samples).map(|row| dot(row, values)).collect()
    }

    /// The coefficient textures of the textures `samples` (one per sampled direction, of
    /// equal length): C textures, each Σ_i projector[c, i]·samples[i].
    pub fn project(&self, samples: &[&[f32]]) -> Vec<Vec<f32>> {
        let len = samples.first().map_or(0, |s| s.len());
        assert!(samples.len() == self.samples && samples.iter().all(|s| s.len() == len));
        self.projector
            .par_chunks_exact(self.samples)
            .map(|row| {
                let mut out = vec![0.0f64; len];
                for (&p, s) in row.iter().zip(samples) {
                    out.iter_mut().zip(s.iter()).for_each(|(o, &v)| *o += p * v as f64);
                }
                out.into_iter().map(|v| v as f32).collect()
            })
            .collect()
    }
}

/// Σ a_i·b_i.
fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// The lower hemisphere's filled rows: each sample mirrored below the horizon, its value
/// `(1 − s)·h(φ) + s·m` with s ∈ [0, 1] the mirrored direction's polar angle past the
/// horizon over a quarter turn, h(φ) the horizon's value at its azimuth (`horizon_of`) and m the mean of h over the mirrored
/// directions.
fn filled_rows(directions: &[Vec3], up: Vec3) -> Vec<(Vec3, Vec<f64>)> {
    let n = directions.len();
    // A hemisphere's 2π steradians over N samples: the mean spacing.
    let spacing = (std::f64::consts::TAU / n as f64).sqrt();
    let sigma = HORIZON_KERNEL * spacing;
    let elevation = |d: &Vec3| (d.dot(up) as f64).clamp(-1.0, 1.0).asin();
    // The horizon's value at w's azimuth: the samples near that point of the horizon,
    // Gaussian-weighted by angle, fitted by a line in elevation and read at elevation 0
    // (a mean alone would read the samples' value some way above the horizon).
    let horizon_of = |w: Vec3| -> Vec<f64> {
        let flat = (w - w.dot(up) * up).normalize_or(up.any_orthonormal_vector());
        let k: Vec<f64> = directions
            .iter()
            .map(|d| {
                let angle = (d.dot(flat) as f64).clamp(-1.0, 1.0).acos();
                (-(angle / sigma).powi(2)).exp()
            })
            .collect();
        let total: f64 = k.iter().sum();
        let mean_e = directions.iter().zip(&k).map(|(d, k)| k * elevation(d)).sum::<f64>() / total;
        let var = directions
            .iter()
            .zip(&k)
            .map(|(d, k)| k * (elevation(d) - mean_e).powi(2))
            .sum::<f64>();
        directions
            .iter()
            .zip(&k)
            .map(|(d, k)| k / total - mean_e * k * (elevation(d) - mean_e) / var)
            .collect()
    };
    let horizons: Vec<Vec<f64>> = directions.iter().map(|&w| horizon_of(w)).collect();
    let mean: Vec<f64> =
        (0..n).map(|i| horizons.iter().map(|h| h[i]).sum::<f64>() / n as f64).collect();
    directions
        .iter()
        .zip(horizons)
        .map(|(&w, h)| {
            let height = w.dot(up).clamp(0.0, 1.0) as f64;
            let s = height.asin() / std::f64::consts::FRAC_PI_2;
            let weights = h.iter().zip(&mean).map(|(hv, mv)| (1.0 - s) * hv + s * mv).collect();
            (w - 2.0 * w.dot(up) * up, weights)
        })
        .collect()
}

/// Solves `normal · X = rhs` for the C × N matrix X (rhs row-major C × N) by Gaussian
/// elimination with partial pivoting; `None` where `normal` is singular.
fn solve_columns(normal: &mut [f64], c: usize, rhs: &mut [f64], n: usize) -> Option<Vec<f64>> {
    let scale = (0..c).map(|i| normal[i * c + i]).fold(0.0f64, f64::max);
    for col in 0..c {
        let pivot = (col..c)
            .max_by(|&a, &b| normal[a * c + col].abs().total_cmp(&normal[b * c + col].abs()))?;
        if normal[pivot * c + col].abs() <= 1e-12 * scale {
            return None;
        }
        for k in 0..c {
            normal.swap(col * c + k, pivot * c + k);
        }
        for k in 0..n {
            rhs.swap(col * n + k, pivot * n + k);
        }
        let d = normal[col * c + col];
        for row in (0..c).filter(|&r| r != col) {
            let f = normal[row * c + col] / d;
            if f == 0.0 {
                continue;
            }
            for k in 0..c {
                normal[row * c + k] -= f * normal[col * c + k];
            }
            for k in 0..n {
                rhs[row * n + k] -= f * rhs[col * n + k];
            }
        }
    }
    for row in 0..c {
        let d = normal[row * c + row];
        rhs[row * n..(row + 1) * n].iter_mut().for_each(|v| *v /= d);
    }
    Some(rhs.to_vec())
}

#[cfg(test)]
mod tests {
    use super::*;
    use pis_scene::light_direction::{light_directions, Cover as Spread};

    /// `n` spherical Fibonacci directions over the upper hemisphere or the sphere.
    fn fibonacci(n: u32, hemisphere: bool) -> Vec<Vec3> {
        let spread = if hemisphere { Spread::Hemisphere } else { Spread::Sphere };
        light_directions(n, spread, Vec3::Y)
    }

    #[test]
    fn a_function_of_the_bands_is_fitted_exactly_over_the_sphere() {
        let dirs = fibonacci(64, false);
        let fit = LightFit::new(3, &dirs, Cover::Sphere).unwrap();
        let want: Vec<f64> = (0..16).map(|c| (c as f64 * 0.37).sin()).collect();
        let mut y = vec![0.0; 16];
        let values: Vec<f64> = dirs
            .iter()
            .map(|&w| {
                basis(3, w, &mut y);
                dot(&y, &want)
            })
            .collect();
        let got = fit.coefficients_of(&values);
        for (g, w) in got.iter().zip(&want) {
            assert!((g - w).abs() < 1e-9, "{got:?}");
        }
        // The texture form agrees with the scalar form.
        let textures: Vec<Vec<f32>> =
            values.iter().map(|&v| vec![v as f32, 2.0 * v as f32]).collect();
        let refs: Vec<&[f32]> = textures.iter().map(|t| t.as_slice()).collect();
        let x = fit.project(&refs);
        assert_eq!(x.len(), 16);
        for (c, t) in x.iter().enumerate() {
            assert!(
                (t[0] as f64 - want[c]).abs() < 1e-5 && (t[1] as f64 - 2.0 * want[c]).abs() < 1e-5
            );
        }
    }

    #[test]
    fn a_hemisphere_is_filled_below_and_fits_the_samples_above() {
        // A cosine lobe about the pole, clamped at the horizon: smooth above, zero at it.
        let dirs = fibonacci(64, true);
        let fit = LightFit::new(4, &dirs, Cover::Hemisphere(Vec3::Y)).unwrap();
        let values: Vec<f64> = dirs.iter().map(|w| w.y as f64).collect();
        let x = fit.coefficients_of(&values);
        let mut y = vec![0.0; 25];
        let at = |w: Vec3, y: &mut Vec<f64>| {
            basis(4, w, y);
            dot(y, &x)
        };
        // Above, between the samples: the lobe within 0.06 (its kink at the horizon is
        // what band 4 cannot follow).
        for w in fibonacci(50, true).iter().map(|w| (*w + Vec3::new(0.05, 0.0, 0.0)).normalize()) {
            assert!((at(w, &mut y) - w.y as f64).abs() < 0.06, "{w}");
        }
        // Below: near the filled value (the horizon's 0 throughout), with no ringing.
        let below = fibonacci(50, false).into_iter().filter(|w| w.y < -0.1);
        for w in below {
            assert!(at(w, &mut y).abs() < 0.05, "{w}: {}", at(w, &mut y));
        }
        // Without the fill, the lower hemisphere is free and rings.
        let free = LightFit::new(4, &dirs, Cover::Sphere).map(|f| f.coefficients_of(&values));
        if let Some(free) = free {
            let worst = fibonacci(200, false)
                .into_iter()
                .filter(|w| w.y < -0.1)
                .map(|w| {
                    basis(4, w, &mut y);
                    dot(&y, &free).abs()
                })
                .fold(0.0, f64::max);
            assert!(worst > 0.2, "the unfilled fit stayed near 0 below: {worst}");
        }
    }

    #[test]
    fn too_few_samples_for_the_band_give_no_fit() {
        assert!(LightFit::new(4, &fibonacci(24, false), Cover::Sphere).is_none());
        assert!(LightFit::new(MAX_BAND + 1, &fibonacci(200, false), Cover::Sphere).is_none());
    }
}
