//! A sky as one more light (seed 003, 2.4, with Nimeroff's superposition): an equirectangular
//! radiance image L projected into the basis, s_c = ∫ L(ω) Y_c(ω) dω. A texel whose response
//! to a directional light of irradiance E₀ from ω is f(ω) = Σ_c Y_c(ω) x_c then shows
//! ∫ L(ω) f(ω)/E₀ dω = Σ_c s_c x_c / E₀ under the sky, by orthonormality.
//!
//! The image follows scene.toml's lat-long convention (docs/SCENE.md, `[environment]`): a
//! direction d reads column u = ½ + atan2(d.z, d.x)/2π and row v = acos(d.y)/π, and a sky
//! turned by `rotation` (radians about +Y, right-handed) shows at d what the image holds at
//! d turned back.

use glam::{Quat, Vec3};

use super::basis::{basis, coefficients};

/// The coefficients s_c, RGB, of the `width × height` RGB image `rgb` (rows from the top)
/// turned by `rotation` radians about +Y, up to band `l_max`. Each texel is a patch of
/// constant radiance over its exact solid angle, read at `SUB` azimuths and two polar
/// angles, the Gauss–Legendre nodes in cos θ (exact for the m = 0 terms of a row up to
/// degree 3 in cos θ).
pub fn project_lat_long(
    width: usize,
    height: usize,
    rgb: &[f32],
    rotation: f32,
    l_max: u32,
) -> Vec<[f64; 3]> {
    const SUB: usize = 2;
    let c = coefficients(l_max);
    let turn = Quat::from_rotation_y(rotation);
    let mut out = vec![[0.0f64; 3]; c];
    let mut y = vec![0.0; c];
    for row in 0..height {
        let c0 = (std::f64::consts::PI * row as f64 / height as f64).cos();
        let c1 = (std::f64::consts::PI * (row + 1) as f64 / height as f64).cos();
        let solid = std::f64::consts::TAU / (width * SUB) as f64 * (c0 - c1) / 2.0;
        let (mid, half) = ((c0 + c1) / 2.0, (c0 - c1) / 2.0 / 3f64.sqrt());
        for cos_t in [mid - half, mid + half] {
            let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
            for col in 0..width {
                let texel = &rgb[(row * width + col) * 3..][..3];
                if texel.iter().all(|v| *v <= 0.0) {
                    continue;
                }
                for sx in 0..SUB {
                    let u = ((col * SUB + sx) as f64 + 0.5) / (width * SUB) as f64;
                    let phi = std::f64::consts::TAU * (u - 0.5);
                    let d = Vec3::new(
                        (sin_t * phi.cos()) as f32,
                        cos_t as f32,
                        (sin_t * phi.sin()) as f32,
                    );
                    basis(l_max, turn * d, &mut y);
                    for (o, yc) in out.iter_mut().zip(&y) {
                        for ch in 0..3 {
                            o[ch] += texel[ch].max(0.0) as f64 * yc * solid;
                        }
                    }
                }
            }
        }
    }
    out
}

/// The coefficients of a sky `s` (as [`project_lat_long`] gives them) turned a further
/// `angle` radians about +Y, the pole: a turn about the pole mixes only each band's ±m pair,
/// by the angle mα, so a sky's rotation costs no new projection.
pub fn rotate_about_pole(s: &[[f64; 3]], angle: f32) -> Vec<[f64; 3]> {
    let mut out = s.to_vec();
    let mut l = 0usize;
    while coefficients(l as u32) <= s.len() {
        let base = l * l + l;
        for m in 1..=l {
            let (sin, cos) = (m as f64 * angle as f64).sin_cos();
            let (p, q) = (s[base + m], s[base - m]);
            for ch in 0..3 {
                out[base + m][ch] = cos * p[ch] + sin * q[ch];
                out[base - m][ch] = cos * q[ch] - sin * p[ch];
            }
        }
        l += 1;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_uniform_sky_has_only_the_constant_term() {
        let (w, h) = (32, 16);
        let rgb = vec![1.0f32; w * h * 3];
        let s = project_lat_long(w, h, &rgb, 0.3, 2);
        // ∫ Y_0 dω = 4π · 1/(2√π) = 2√π.
        let want = 2.0 * std::f64::consts::PI.sqrt();
        assert!((s[0][0] - want).abs() < 1e-9 && (s[0][2] - want).abs() < 1e-9);
        assert!(s[1..].iter().all(|v| v.iter().all(|x| x.abs() < 1e-6)), "{s:?}");
    }

    #[test]
    fn a_bright_patch_projects_to_the_basis_at_its_direction() {
        // One bright texel at the image centre (+X, on the horizon): s_c ≈ Y_c(+X)·power.
        let (w, h) = (64, 32);
        let mut rgb = vec![0.0f32; w * h * 3];
        let (col, row) = (w / 2, h / 2);
        rgb[(row * w + col) * 3] = 1.0;
        let s = project_lat_long(w, h, &rgb, 0.0, 2);
        let mut y = vec![0.0; 9];
        let centre_phi = std::f64::consts::TAU * ((col as f64 + 0.5) / w as f64 - 0.5);
        let centre_theta = std::f64::consts::PI * (row as f64 + 0.5) / h as f64;
        let d = Vec3::new(
            (centre_theta.sin() * centre_phi.cos()) as f32,
            centre_theta.cos() as f32,
            (centre_theta.sin() * centre_phi.sin()) as f32,
        );
        basis(2, d, &mut y);
        let solid = s[0][0] / y[0];
        for c in 0..9 {
            assert!((s[c][0] - y[c] * solid).abs() < 0.02 * solid, "coefficient {c}");
        }
        // Turned a quarter turn about +Y, the patch moves from +X to −Z.
        let turned = project_lat_long(w, h, &rgb, std::f32::consts::FRAC_PI_2, 1);
        basis(1, Vec3::NEG_Z, &mut y);
        for c in 0..4 {
            assert!((turned[c][0] - y[c] * solid).abs() < 0.05 * solid, "turned {c}");
        }
    }

    #[test]
    fn turning_the_coefficients_about_the_pole_is_turning_the_sky() {
        // A sky with structure in every band (two off-axis patches of different colours).
        let (w, h) = (48, 24);
        let mut rgb = vec![0.0f32; w * h * 3];
        rgb[(5 * w + 7) * 3] = 4.0;
        rgb[(9 * w + 30) * 3 + 2] = 2.0;
        for angle in [0.4f32, -1.3, 2.9] {
            let turned = project_lat_long(w, h, &rgb, angle, 4);
            let rotated = rotate_about_pole(&project_lat_long(w, h, &rgb, 0.0, 4), angle);
            for (a, b) in turned.iter().zip(&rotated) {
                for ch in 0..3 {
                    assert!((a[ch] - b[ch]).abs() < 2e-3, "angle {angle}: {a:?} against {b:?}");
                }
            }
        }
    }
}
