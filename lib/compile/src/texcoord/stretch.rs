//! Sampling adequacy (thesis 3.2, steps 3–4): the largest singular value of the
//! texture→screen Jacobian over all covered pixels, and the scaling of R along the
//! direction of maximal stretch until it falls under a threshold.

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
pub fn limit_stretch(mut r: DMat2, jacobians: &[DMat2], threshold: f64, axis_aligned: bool) -> (DMat2, f64) {
    let worst = |r: DMat2| {
        jacobians
            .iter()
            .filter_map(|&j| max_stretch(r, j))
            .fold((0.0f64, DVec2::X), |a, b| if b.0 > a.0 { b } else { a })
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
}
