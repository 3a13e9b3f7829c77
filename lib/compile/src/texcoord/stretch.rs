//! Sampling adequacy (thesis 3.2, steps 3–4): the largest singular value of the
//! texture→screen Jacobian over all covered pixels, and the scaling of R along the
//! direction of maximal stretch until it falls under a threshold.
//!
//! The search rescales R until no pixel of any view is stretched past the threshold, so it
//! needs every covered pixel's Jacobian, or every one that can be the worst for some R: the
//! [`envelope`] of a view's Jacobians, a few dozen of its hundred thousand pixels.

use glam::{DMat2, DVec2};

/// The largest stretch σ = σ_max((R·J)⁻¹) at one pixel, with its texture-space direction
/// (unit). J = ∂(u, v)/∂(x, y); R·J maps screen to texels. `None` for a singular R·J.
pub fn max_stretch(r: DMat2, j: DMat2) -> Option<(f64, DVec2)> {
    let a = r * j;
    // Right singular vectors of A⁻¹ are the eigenvectors of (A Aᵀ)⁻¹, i.e. of A Aᵀ; the
    // largest stretch belongs to A Aᵀ's smallest eigenvalue μ: σ = 1/√μ.
    let m = a * a.transpose();
    let (p, q, s) = (m.x_axis.x, m.y_axis.x, m.y_axis.y); // symmetric (p q; q s)
    let tr = p + s;
    let disc = ((p - s) * (p - s) + 4.0 * q * q).sqrt();
    let mu = 0.5 * (tr - disc);
    if !(mu.is_finite() && mu > 1e-300) {
        return None;
    }
    // eigenvector of (p q; q s) for μ
    let v = if q.abs() > 1e-300 {
        DVec2::new(mu - s, q)
    } else if p <= s {
        DVec2::X
    } else {
        DVec2::Y
    };
    Some((1.0 / mu.sqrt(), v.normalize()))
}

/// Scales R along the direction of maximal stretch by that stretch, repeatedly, until the
/// largest stretch over all `jacobians` is at most `threshold`. Returns the new R and the
/// final largest stretch. With `axis_aligned` (a scale-only map, thesis 3.2) the scaling
/// keeps R diagonal: diag(1 + (σ − 1)v_x², 1 + (σ − 1)v_y²).
pub fn limit_stretch(
    mut r: DMat2,
    jacobians: &[DMat2],
    threshold: f64,
    axis_aligned: bool,
) -> (DMat2, f64) {
    let worst = |r: DMat2| {
        jacobians.iter().filter_map(|&j| max_stretch(r, j)).fold((0.0f64, DVec2::X), |a, b| {
            if b.0 > a.0 {
                b
            } else {
                a
            }
        })
    };
    let mut w = worst(r);
    for _ in 0..200 {
        if w.0 <= threshold {
            break;
        }
        let (sigma, v) = w;
        // T' = (I + (σ − 1) v vᵀ) T
        let mut outer = DMat2::from_cols(v * v.x, v * v.y);
        if axis_aligned {
            outer = DMat2::from_diagonal(DVec2::new(v.x * v.x, v.y * v.y));
        }
        r = (DMat2::IDENTITY + outer * (sigma - 1.0)) * r;
        w = worst(r);
    }
    (r, w.0)
}

/// The Jacobians among `jacobians` that can be the most stretched for some R, in their
/// order: for every other, at every R, one of these is stretched as much or more.
///
/// The stretch at R is σ² = λ_max(R⁻ᵀ Q R⁻¹) with Q = (J Jᵀ)⁻¹, the maximum over
/// w = R⁻¹y (|y| = 1) of wᵀQw = |w|² f_Q(φ), φ the angle of w. So the most stretched pixel is
/// one that maximizes f_Q(φ) for some φ: the upper envelope of the curves
/// f_Q = m + p·cos 2φ + q·sin 2φ (m = (Q₁₁ + Q₂₂)/2, p = (Q₁₁ − Q₂₂)/2, q = Q₁₂), the same for
/// every R. The envelope is sampled at [`ENVELOPE_ANGLES`] angles; a Jacobian is left out
/// only when its curve's maximum is under the envelope's lowest possible value, or when, on
/// each interval between two angles, it is nowhere above the maximizer at one end: exact
/// bounds on sinusoids, so nothing that reaches the envelope is lost. Singular
/// Jacobians, which no R makes stretched ([`max_stretch`] is `None`), are left out.
pub fn envelope(jacobians: &[DMat2]) -> Vec<DMat2> {
    const N: usize = ENVELOPE_ANGLES;
    let curves: Vec<Option<[f64; 3]>> = jacobians.iter().map(|&j| curve(j)).collect();
    let angles: Vec<f64> = (0..=N).map(|k| std::f64::consts::TAU * k as f64 / N as f64).collect();
    let trig: Vec<(f64, f64)> = angles.iter().map(|t| (t.cos(), t.sin())).collect();
    let values = |c: &[f64; 3]| -> [f64; N + 1] {
        let mut v = [0.0; N + 1];
        v.iter_mut().zip(&trig).for_each(|(v, (cos, sin))| *v = c[0] + c[1] * cos + c[2] * sin);
        v
    };
    let amplitude = |c: &[f64; 3]| c[1].hypot(c[2]);
    // The maximizer at each sampled angle (the first, on a tie).
    let mut best: Vec<Option<(f64, usize)>> = vec![None; N];
    for (i, c) in curves.iter().enumerate() {
        let Some(c) = c else { continue };
        for (b, v) in best.iter_mut().zip(values(c)) {
            if b.is_none_or(|(w, _)| v > w) {
                *b = Some((v, i));
            }
        }
    }
    let Some(best) = best.into_iter().collect::<Option<Vec<(f64, usize)>>>() else {
        return Vec::new();
    };
    let of = |k: usize| curves[best[k % N].1].expect("a maximizer has a curve");
    let at_best: Vec<[f64; N + 1]> = (0..N).map(|k| values(&of(k))).collect();
    // Between two samples Δ apart a sinusoid of amplitude A rises at most A(1 − cos Δ/2) above
    // its higher end, and falls at most AΔ below either end (it is A-Lipschitz), so the
    // envelope is nowhere under `floor`.
    let delta = angles[1];
    let rise = 1.0 - (0.5 * delta).cos();
    let floor = (0..N).map(|k| best[k].0 - amplitude(&of(k)) * delta).fold(f64::INFINITY, f64::min);
    let keep = |i: usize, c: &[f64; 3]| {
        if c[0] + amplitude(c) <= floor {
            return false;
        }
        let fc = values(c);
        (0..N).any(|k| {
            let ends = [k, (k + 1) % N];
            ends.iter().any(|&e| best[e].1 == i)
                || ends.iter().all(|&e| {
                    let (d, v) = (of(e), &at_best[e]);
                    let (g0, g1) = (fc[k] - v[k], fc[k + 1] - v[k + 1]);
                    // Under this end's maximizer on the interval: at once when even the largest
                    // rise keeps the difference under zero, else by the exact test.
                    let under = g0.max(g1) + rise * (amplitude(c) + amplitude(&d)) <= 0.0
                        || nowhere_above(
                            [c[0] - d[0], c[1] - d[1], c[2] - d[2]],
                            angles[k],
                            angles[k + 1],
                        );
                    !under
                })
        })
    };
    jacobians
        .iter()
        .zip(&curves)
        .enumerate()
        .filter(|(i, (_, c))| c.as_ref().is_some_and(|c| keep(*i, c)))
        .map(|(_, (&j, _))| j)
        .collect()
}

/// The number of angles 2φ ∈ [0, 2π) at which [`envelope`] samples the upper envelope.
pub const ENVELOPE_ANGLES: usize = 16;

/// (m, p, q) of f_Q(2φ) = m + p·cos 2φ + q·sin 2φ for Q = (J Jᵀ)⁻¹; `None` for a singular J.
fn curve(j: DMat2) -> Option<[f64; 3]> {
    let q = (j * j.transpose()).inverse();
    let (a, b, c) = (q.x_axis.x, q.y_axis.x, q.y_axis.y);
    let out = [0.5 * (a + c), 0.5 * (a - c), b];
    out.iter().all(|v| v.is_finite()).then_some(out)
}

/// Whether g(t) = m + p·cos t + q·sin t is ≤ 0 on all of [t0, t1] (0 ≤ t0 < t1 ≤ 2π).
fn nowhere_above(g: [f64; 3], t0: f64, t1: f64) -> bool {
    let at = |t: f64| g[0] + g[1] * t.cos() + g[2] * t.sin();
    let peak = g[2].atan2(g[1]).rem_euclid(std::f64::consts::TAU);
    let inside = peak >= t0 && peak <= t1;
    at(t0) <= 0.0 && at(t1) <= 0.0 && (!inside || g[0] + g[1].hypot(g[2]) <= 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stretch_of_a_scaled_map() {
        // screen→uv: 1 pixel = 0.01 in u, 0.02 in v; R = 50·I → 1 px = 0.5 texel in u, 1 in v
        let j = DMat2::from_cols(DVec2::new(0.01, 0.0), DVec2::new(0.0, 0.02));
        let (s, v) = max_stretch(DMat2::from_diagonal(DVec2::splat(50.0)), j).unwrap();
        assert!((s - 2.0).abs() < 1e-12 && v.x.abs() > 0.999);
        let (r, s) = limit_stretch(DMat2::from_diagonal(DVec2::splat(50.0)), &[j], 1.25, false);
        assert!(s <= 1.25);
        assert!((r.x_axis.x - 100.0).abs() < 1e-9 && (r.y_axis.y - 50.0).abs() < 1e-9);
    }

    /// The Jacobians of a plane seen in perspective, as a view's pixels give them: they vary
    /// smoothly with depth and screen position, a continuum of a hundred thousand.
    fn plane_in_perspective(n: usize, tilt: f64) -> Vec<DMat2> {
        (0..n * n)
            .map(|k| {
                let (x, y) = ((k % n) as f64 / n as f64 - 0.5, (k / n) as f64 / n as f64 - 0.5);
                let depth = 1.0 + tilt * (y + 0.5);
                let shear = 0.3 * x * y;
                DMat2::from_cols(
                    DVec2::new(depth * 0.01, shear * 0.004),
                    DVec2::new(x * 0.002, depth * depth * 0.013),
                )
            })
            .collect()
    }

    #[test]
    fn the_envelope_is_as_stretched_as_every_jacobian_at_any_r() {
        let mut all = plane_in_perspective(200, 3.0);
        all.extend(plane_in_perspective(60, 0.5).iter().map(|&j| DMat2::from_angle(0.7) * j * 1.7));
        all.push(DMat2::ZERO); // singular: never the worst
        all.push(all[5]); // a duplicate
        let kept = envelope(&all);
        assert!(kept.len() * 100 < all.len(), "kept {} of {}", kept.len(), all.len());
        let worst = |js: &[DMat2], r: DMat2| {
            js.iter().filter_map(|&j| max_stretch(r, j)).map(|s| s.0).fold(0.0f64, f64::max)
        };
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        for _ in 0..500 {
            let r = DMat2::from_cols(DVec2::new(next(), next()), DVec2::new(next(), next())) * 80.0;
            if r.determinant().abs() < 1.0 {
                continue;
            }
            let (a, b) = (worst(&all, r), worst(&kept, r));
            assert!((a - b).abs() <= 1e-9 * a, "R {r}: every pixel {a}, envelope {b}");
        }
        for axis_aligned in [false, true] {
            let r0 = DMat2::from_diagonal(DVec2::splat(30.0));
            assert_eq!(
                limit_stretch(r0, &all, 1.1, axis_aligned),
                limit_stretch(r0, &kept, 1.1, axis_aligned)
            );
        }
    }

    #[test]
    fn every_curve_that_reaches_the_envelope_is_kept_and_no_other() {
        // Two axis-aligned pixels stretched along u and v, and a third, less stretched along
        // either axis, that is the most stretched along the diagonal.
        let along = |su: f64, sv: f64, angle: f64| {
            DMat2::from_angle(angle)
                * DMat2::from_diagonal(DVec2::new(su, sv))
                * DMat2::from_angle(-angle)
        };
        let js = [
            along(0.5, 1.0, 0.0),
            along(1.0, 0.5, 0.0),
            along(0.45, 1.0, std::f64::consts::FRAC_PI_4 + 0.01),
        ];
        assert_eq!(envelope(&js).len(), 3);
        assert_eq!(envelope(&[js[0], js[0] * 1.5]), vec![js[0]]);
    }
}
