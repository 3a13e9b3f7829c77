//! The real spherical harmonics of Wong et al. (seed 003, section 2.3), in world space with
//! the pole along +Y (θ from +Y, φ from +X towards +Z):
//!
//! ```text
//! Y_l,m = N_l,m P_l,m(cos θ) cos(mφ)          m > 0
//!         N_l,0 P_l,0(cos θ) / √2             m = 0
//!         N_l,m P_l,|m|(cos θ) sin(|m|φ)      m < 0
//! N_l,m = √((2l + 1)/2π · (l − |m|)!/(l + |m|)!)
//! ```
//!
//! orthonormal over the sphere. Coefficient c = l² + l + m. P is evaluated as P̃ · sinᵐθ with
//! the polynomial P̃ of the paper's recurrences less their √(1 − x²) factors, and
//! sinᵐθ·cos(mφ), sinᵐθ·sin(mφ) as the real and imaginary parts of (ω_x + i·ω_z)ᵐ: no
//! angle is taken, so the basis is exact at the poles. The player weighs its coefficient
//! layers with this same function ([`super::lights`]), once per frame.

use glam::Vec3;

/// The highest band the file and the player hold: (8 + 1)² = 81 coefficients.
pub const MAX_BAND: u32 = 8;

/// The number of coefficients up to band `l_max`: (l_max + 1)².
pub fn coefficients(l_max: u32) -> usize {
    ((l_max + 1) * (l_max + 1)) as usize
}

/// The normalisations N_l,m of every coefficient up to band `l_max`, with the m = 0 terms'
/// 1/√2 folded in.
fn norms(l_max: u32) -> Vec<f64> {
    let mut n = Vec::with_capacity(coefficients(l_max));
    for l in 0..=l_max as i64 {
        for m in -l..=l {
            let am = m.unsigned_abs();
            // (l − |m|)! / (l + |m|)!
            let ratio: f64 =
                ((l as u64 - am + 1)..=(l as u64 + am)).map(|k| 1.0 / k as f64).product();
            let v = ((2 * l + 1) as f64 / std::f64::consts::TAU * ratio).sqrt();
            n.push(if m == 0 { v / std::f64::consts::SQRT_2 } else { v });
        }
    }
    n
}

/// Y_c(ω) for every coefficient up to `l_max` into `out` (length [`coefficients`]); `w` is a
/// unit direction.
pub fn basis(l_max: u32, w: Vec3, out: &mut [f64]) {
    let (x, y, z) = (w.x as f64, w.y as f64, w.z as f64);
    let l_max = l_max as usize;
    let n = norms(l_max as u32);
    // (x + iz)^m: sinᵐθ·cos(mφ) and sinᵐθ·sin(mφ).
    let mut cs = vec![(1.0f64, 0.0f64); l_max + 1];
    for m in 1..=l_max {
        let (c, s) = cs[m - 1];
        cs[m] = (c * x - s * z, c * z + s * x);
    }
    for m in 0..=l_max {
        // P̃_m,m = (−1)ᵐ (2m − 1)!!, then the recurrences up the band.
        let mut p_mm = 1.0;
        for k in 1..=m {
            p_mm *= -((2 * k - 1) as f64);
        }
        let (mut p2, mut p1) = (0.0, p_mm);
        for l in m..=l_max {
            let p = match l - m {
                0 => p_mm,
                1 => y * (2 * m + 1) as f64 * p_mm,
                _ => (y * (2 * l - 1) as f64 * p1 - (l + m - 1) as f64 * p2) / (l - m) as f64,
            };
            if l > m {
                (p2, p1) = (p1, p);
            }
            let (c, s) = cs[m];
            let base = l * l + l;
            if m == 0 {
                out[base] = n[base] * p;
            } else {
                out[base + m] = n[base + m] * p * c;
                out[base - m] = n[base - m] * p * s;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use pis_scene::light_direction::{light_directions, Cover};

    /// A spherical Fibonacci set of `n` directions over the sphere (equal area).
    fn sphere(n: u32) -> Vec<Vec3> {
        light_directions(n, Cover::Sphere, Vec3::Y)
    }

    #[test]
    fn the_basis_is_orthonormal_over_the_sphere() {
        let l_max = 6;
        let c = coefficients(l_max);
        let dirs = sphere(20_000);
        let mut gram = vec![0.0f64; c * c];
        let mut y = vec![0.0; c];
        for w in &dirs {
            basis(l_max, *w, &mut y);
            for i in 0..c {
                for j in 0..c {
                    gram[i * c + j] += y[i] * y[j];
                }
            }
        }
        let area = 4.0 * std::f64::consts::PI / dirs.len() as f64;
        for i in 0..c {
            for j in 0..c {
                let want = if i == j { 1.0 } else { 0.0 };
                assert!((gram[i * c + j] * area - want).abs() < 2e-3, "({i}, {j})");
            }
        }
    }

    #[test]
    fn low_bands_match_their_closed_forms() {
        let w = Vec3::new(0.36, 0.48, 0.8);
        let mut y = vec![0.0; coefficients(2)];
        basis(2, w, &mut y);
        let pi = std::f64::consts::PI;
        let (x, yy, z) = (w.x as f64, w.y as f64, w.z as f64);
        // With the pole along +Y: Y_1,0 ∝ y, Y_1,1 ∝ −x, Y_1,−1 ∝ −z (Condon–Shortley phase).
        let want = [
            0.5 / pi.sqrt(),
            -(3.0 / (4.0 * pi)).sqrt() * z,
            (3.0 / (4.0 * pi)).sqrt() * yy,
            -(3.0 / (4.0 * pi)).sqrt() * x,
            0.5 * (15.0 / pi).sqrt() * x * z,
            -0.5 * (15.0 / pi).sqrt() * z * yy,
            0.25 * (5.0 / pi).sqrt() * (3.0 * yy * yy - 1.0),
            -0.5 * (15.0 / pi).sqrt() * x * yy,
            0.25 * (15.0 / pi).sqrt() * (x * x - z * z),
        ];
        for (c, (a, b)) in y.iter().zip(want).enumerate() {
            assert!((a - b).abs() < 1e-6, "coefficient {c}: {a} against {b}");
        }
    }
}
