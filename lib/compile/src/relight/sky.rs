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

use super::basis::{basis, coefficients, MAX_BAND};

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

/// The largest sky image projected as it is (the projection's time grows with the texels: a
/// few seconds at this size). A larger one is averaged down to this size first
/// ([`reduce_lat_long`]): its power is kept, and a small bright source moves by at most half
/// a texel (0.18°), where the basis's finest band varies over some 20°.
pub const SKY_PROJECTED_SIZE: (usize, usize) = (1024, 512);

/// Reads an equirectangular `.exr` or `.hdr` sky and projects it into the player's basis
/// (every band the player holds), unturned; the error names the file.
pub fn load_sky(path: &std::path::Path) -> Result<Vec<[f64; 3]>, String> {
    let (w, h, texels) =
        pis_scene::read_environment_image(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let rgb: Vec<f32> = texels.iter().flatten().copied().collect();
    let (w, h, rgb) = reduce_lat_long(w as usize, h as usize, &rgb, SKY_PROJECTED_SIZE);
    Ok(project_lat_long(w, h, &rgb, 0.0, MAX_BAND))
}

/// Each output cell's source cells and their weights along one axis: the overlap of the
/// cells' spans, measured by `measure` (the weights of an output cell sum to 1).
fn overlaps(n: usize, m: usize, measure: impl Fn(f64, f64) -> f64) -> Vec<Vec<(usize, f64)>> {
    (0..m)
        .map(|j| {
            let (a, b) = (j as f64 / m as f64, (j + 1) as f64 / m as f64);
            let first = ((a * n as f64).floor() as usize).min(n - 1);
            let last = ((b * n as f64).ceil() as usize).clamp(first + 1, n);
            let whole = measure(a, b);
            (first..last)
                .filter_map(|k| {
                    let lo = a.max(k as f64 / n as f64);
                    let hi = b.min((k + 1) as f64 / n as f64);
                    (hi > lo && whole > 0.0).then(|| (k, measure(lo, hi) / whole))
                })
                .collect()
        })
        .collect()
}

/// A `width × height` lat-long RGB image (rows from the top) averaged down to at most
/// `max` (width, height): each new texel is the mean radiance over its solid angle (columns
/// by azimuth, rows by cos θ), so the image's power and its coefficients up to bands far
/// coarser than a texel are kept. An image within `max` is returned as it is.
pub fn reduce_lat_long(
    width: usize,
    height: usize,
    rgb: &[f32],
    max: (usize, usize),
) -> (usize, usize, Vec<f32>) {
    let (w, h) = (width.min(max.0.max(1)), height.min(max.1.max(1)));
    if (w, h) == (width, height) || width == 0 || height == 0 {
        return (width, height, rgb.to_vec());
    }
    let cols = overlaps(width, w, |a, b| b - a);
    let polar = |t: f64| (std::f64::consts::PI * t).cos();
    let rows = overlaps(height, h, |a, b| polar(a) - polar(b));
    let mut out = vec![0.0f32; w * h * 3];
    for (i, row) in rows.iter().enumerate() {
        for (j, col) in cols.iter().enumerate() {
            let mut sum = [0.0f64; 3];
            for &(k, wk) in row {
                for &(l, wl) in col {
                    let texel = &rgb[(k * width + l) * 3..][..3];
                    for ch in 0..3 {
                        sum[ch] += wk * wl * texel[ch] as f64;
                    }
                }
            }
            for ch in 0..3 {
                out[(i * w + j) * 3 + ch] = sum[ch] as f32;
            }
        }
    }
    (w, h, out)
}

/// A projected sky (as [`load_sky`] gives it) turned `rotation_deg` about +Y by the
/// right-hand rule (scene.toml's `[environment] rotation_deg`: 90 moves the image centre from
/// +X to −Z) and scaled by `strength`.
pub fn sky_coefficients(projected: &[[f64; 3]], rotation_deg: f32, strength: f32) -> Vec<[f64; 3]> {
    let turned = if rotation_deg == 0.0 {
        projected.to_vec()
    } else {
        rotate_about_pole(projected, rotation_deg.to_radians())
    };
    turned.into_iter().map(|c| c.map(|v| v * strength as f64)).collect()
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

    /// A small sky with structure in several bands.
    fn projected() -> Vec<[f64; 3]> {
        let (w, h) = (32, 16);
        let mut rgb = vec![0.1f32; w * h * 3];
        rgb[(4 * w + 5) * 3] = 5.0;
        rgb[(6 * w + 20) * 3 + 1] = 3.0;
        project_lat_long(w, h, &rgb, 0.0, 4)
    }

    #[test]
    fn sky_strength_scales_the_coefficients() {
        let s = projected();
        assert_eq!(sky_coefficients(&s, 0.0, 1.0), s);
        let doubled = sky_coefficients(&s, 0.0, 2.5);
        for (a, b) in doubled.iter().zip(&s) {
            for ch in 0..3 {
                assert!((a[ch] - 2.5 * b[ch]).abs() <= 1e-12 * b[ch].abs().max(1.0));
            }
        }
        assert!(sky_coefficients(&s, 30.0, 0.0).iter().flatten().all(|v| *v == 0.0));
    }

    #[test]
    fn sky_rotation_turns_the_projection_about_the_pole() {
        let s = projected();
        let (w, h) = (32, 16);
        let mut rgb = vec![0.1f32; w * h * 3];
        rgb[(4 * w + 5) * 3] = 5.0;
        rgb[(6 * w + 20) * 3 + 1] = 3.0;
        for deg in [90.0f32, -35.0] {
            let turned = sky_coefficients(&s, deg, 2.0);
            let direct = project_lat_long(w, h, &rgb, deg.to_radians(), 4);
            for (a, b) in turned.iter().zip(&direct) {
                for ch in 0..3 {
                    assert!((a[ch] - 2.0 * b[ch]).abs() < 4e-3, "{deg}°: {a:?} against {b:?}");
                }
            }
        }
    }

    #[test]
    fn a_large_sky_is_averaged_down_keeping_its_projection() {
        let (w, h) = (300, 150);
        let rgb: Vec<f32> = (0..w * h * 3)
            .map(|i| {
                let (row, col) = (i / 3 / w, i / 3 % w);
                let sun =
                    if (40..44).contains(&row) && (70..73).contains(&col) { 400.0 } else { 0.0 };
                0.2 + 0.5 * ((col as f32 / 9.0).sin() * (row as f32 / 7.0).cos()).abs() + sun
            })
            .collect();
        let (rw, rh, reduced) = reduce_lat_long(w, h, &rgb, (128, 64));
        assert_eq!((rw, rh, reduced.len()), (128, 64, 128 * 64 * 3));
        let full = project_lat_long(w, h, &rgb, 0.0, 8);
        let small = project_lat_long(rw, rh, &reduced, 0.0, 8);
        let scale = full.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
        assert!((full[0][0] - small[0][0]).abs() < 1e-4 * full[0][0], "the power is kept");
        for (c, (a, b)) in full.iter().zip(&small).enumerate() {
            for ch in 0..3 {
                assert!(
                    (a[ch] - b[ch]).abs() < 0.01 * scale,
                    "coefficient {c}: {a:?} against {b:?}"
                );
            }
        }
        // A uniform sky stays uniform; an image within the size is kept as it is.
        let (_, _, flat) = reduce_lat_long(90, 45, &vec![2.0; 90 * 45 * 3], (32, 16));
        assert!(flat.iter().all(|v| (v - 2.0).abs() < 1e-5));
        assert_eq!(reduce_lat_long(4, 2, &[1.0; 24], (8, 4)), (4, 2, vec![1.0; 24]));
    }
}
