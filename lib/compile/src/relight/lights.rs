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

/// The unit direction towards a light at `azimuth_deg` (from +X towards +Z) and
/// `elevation_deg` (above the horizon).
pub fn direction_at(azimuth_deg: f32, elevation_deg: f32) -> Vec3 {
    let (sin_az, cos_az) = azimuth_deg.to_radians().sin_cos();
    let (sin_el, cos_el) = elevation_deg.to_radians().sin_cos();
    Vec3::new(cos_el * cos_az, sin_el, cos_el * sin_az)
}

/// A direction's azimuth (degrees from +X towards +Z, −180 to 180) and elevation (degrees
/// above the horizon); a direction straight up or down has azimuth 0.
pub fn azimuth_elevation(d: Vec3) -> (f32, f32) {
    let d = d.normalize_or(Vec3::Y);
    let elevation = d.y.clamp(-1.0, 1.0).asin().to_degrees();
    let azimuth = if d.x.hypot(d.z) < 1e-6 { 0.0 } else { d.z.atan2(d.x).to_degrees() };
    (azimuth, elevation)
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

    fn close(a: Vec3, b: Vec3) -> bool {
        (a - b).length() < 1e-6
    }

    #[test]
    fn azimuth_runs_from_x_towards_z_and_elevation_from_the_horizon() {
        assert!(close(direction_at(0.0, 0.0), Vec3::X));
        assert!(close(direction_at(90.0, 0.0), Vec3::Z));
        assert!(close(direction_at(180.0, 0.0), Vec3::NEG_X));
        assert!(close(direction_at(-90.0, 0.0), Vec3::NEG_Z));
        assert!(close(direction_at(123.0, 90.0), Vec3::Y));
        let d = direction_at(40.0, 50.0);
        assert!((d.length() - 1.0).abs() < 1e-6 && (d.y - 50f32.to_radians().sin()).abs() < 1e-6);
        let (az, el) = azimuth_elevation(d);
        assert!((az - 40.0).abs() < 1e-4 && (el - 50.0).abs() < 1e-4, "{az} {el}");
        let (az, el) = azimuth_elevation(direction_at(-120.0, -30.0));
        assert!((az + 120.0).abs() < 1e-4 && (el + 30.0).abs() < 1e-4, "{az} {el}");
        assert_eq!(azimuth_elevation(Vec3::Y), (0.0, 90.0));
    }
}
