//! Relighting by superposition (seed 003, section 2.4): a texel fitted to one light of
//! irradiance E₀ from ω, f(ω) = Σ_c Y_c(ω) x_c, shows Σ_c w_c x_c under any set of lights,
//! with w_c = Σ_j E_j/E₀ · Y_c(ω_j) for directional lights j and + s_c/E₀ for a sky whose
//! radiance projects to s_c ([`super::sky`]). The player draws coefficient layers with these
//! weights and `pis-bench relight` fits its ceiling with them: one function for both.

use glam::Vec3;

use super::basis::{basis, coefficients};

/// A directional light: the direction it comes from (unit, from the scene towards the
/// light) and its irradiance times colour, linear RGB (a scene.toml light's colour ×
/// intensity).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DirectionalLight {
    pub direction: Vec3,
    pub radiance: [f32; 3],
}

/// Lights a relightable file is drawn under: any number of directional lights and a sky.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Lights {
    pub directional: Vec<DirectionalLight>,
    /// The sky's radiance in the basis, s_c (RGB), as [`super::sky::project_lat_long`]
    /// gives it; shorter than the file's bands reads as zero beyond.
    pub sky: Option<Vec<[f64; 3]>>,
}

impl Lights {
    /// The weights w_c (RGB) up to band `l_max` of a file whose light had irradiance `e0`.
    pub fn weights(&self, e0: [f32; 3], l_max: u32) -> Vec<[f64; 3]> {
        let n = coefficients(l_max);
        let mut w = vec![[0.0f64; 3]; n];
        let mut y = vec![0.0; n];
        let inv = e0.map(|e| if e > 0.0 { 1.0 / e as f64 } else { 0.0 });
        for light in &self.directional {
            basis(l_max, light.direction.normalize_or(Vec3::Y), &mut y);
            for (wc, yc) in w.iter_mut().zip(&y) {
                for ch in 0..3 {
                    wc[ch] += light.radiance[ch] as f64 * inv[ch] * yc;
                }
            }
        }
        for (wc, sc) in w.iter_mut().zip(self.sky.iter().flatten()) {
            for ch in 0..3 {
                wc[ch] += sc[ch] * inv[ch];
            }
        }
        w
    }
}

/// A relightable layer's texture under weights `weights` (w_c, RGB, as
/// [`Lights::weights`] gives them): Σ_c w_c · x_c per texel of the RGBA coefficient textures
/// `textures` (one size), alpha 1, in f32 as the GPU sums it. The player's `relit.wgsl` is
/// this function written twice.
pub fn sum_coefficients(textures: &[&[f32]], weights: &[[f32; 3]]) -> Vec<f32> {
    let n = textures.first().map_or(0, |t| t.len());
    let mut out = vec![0.0f32; n];
    for (t, w) in textures.iter().zip(weights) {
        for (o, x) in out.chunks_exact_mut(4).zip(t.chunks_exact(4)) {
            for ch in 0..3 {
                o[ch] += x[ch] * w[ch];
            }
        }
    }
    out.chunks_exact_mut(4).for_each(|o| o[3] = 1.0);
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::relight::sky::project_lat_long;

    #[test]
    fn a_light_of_the_files_own_irradiance_weighs_the_basis_at_its_direction() {
        let w = Vec3::new(0.3, 0.8, -0.52).normalize();
        let e0 = [3.0, 3.0, 3.0];
        let lights = Lights {
            directional: vec![DirectionalLight { direction: w, radiance: [3.0, 1.5, 0.0] }],
            sky: None,
        };
        let got = lights.weights(e0, 4);
        let mut y = vec![0.0; 25];
        basis(4, w, &mut y);
        for (g, yc) in got.iter().zip(&y) {
            assert!((g[0] - yc).abs() < 1e-12 && (g[1] - yc / 2.0).abs() < 1e-12 && g[2] == 0.0);
        }
    }

    #[test]
    fn lights_add_and_a_sky_is_one_more_light() {
        let a = DirectionalLight { direction: Vec3::Y, radiance: [1.0, 2.0, 3.0] };
        let b = DirectionalLight { direction: Vec3::X, radiance: [0.5, 0.5, 0.5] };
        let e0 = [2.0, 2.0, 2.0];
        let one = |l: DirectionalLight| Lights { directional: vec![l], sky: None }.weights(e0, 3);
        let both = Lights { directional: vec![a, b], sky: None }.weights(e0, 3);
        let (wa, wb) = (one(a), one(b));
        for c in 0..16 {
            for ch in 0..3 {
                assert!((both[c][ch] - wa[c][ch] - wb[c][ch]).abs() < 1e-12);
            }
        }
        // A uniform sky of radiance 1 weighs only the constant term, by 2√π / E₀.
        let sky = project_lat_long(16, 8, &vec![1.0; 16 * 8 * 3], 0.0, 3);
        let w = Lights { directional: Vec::new(), sky: Some(sky) }.weights(e0, 3);
        assert!((w[0][1] - std::f64::consts::PI.sqrt()).abs() < 1e-9);
        assert!(w[1..].iter().all(|c| c.iter().all(|x| x.abs() < 1e-6)));
    }
}
