//! The least-squares most-isometric linear map (thesis eq. 3.1, after \[Mai93\]):
//!
//! ```text
//! f(R) = Σ_edges W_i · ((s_i − ‖R Δuv_i‖) / min(s_i, ‖R Δuv_i‖))²
//! ```
//!
//! with s_i an edge's screen length, Δuv_i its texture-coordinate difference and R a 2×2
//! matrix mapping texture coordinates to texels. Dividing by the shorter length penalizes
//! an edge twice too long as much as one twice too short. The gradient is analytic; the
//! minimization is Polak–Ribière conjugate gradient with a backtracking line search.
//! A rotation remains free (fixed later by the bounding rectangle).

use glam::DVec2;

/// One edge's data for eq. 3.1.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EdgeTerm {
    pub screen_length: f64,
    pub duv: DVec2,
    pub weight: f64,
}

/// f and ∇f at R = [a, b, c, d] (row-major: (a b; c d)).
pub fn objective(r: [f64; 4], edges: &[EdgeTerm]) -> (f64, [f64; 4]) {
    let mut f = 0.0;
    let mut g = [0.0; 4];
    for e in edges {
        let m = DVec2::new(r[0] * e.duv.x + r[1] * e.duv.y, r[2] * e.duv.x + r[3] * e.duv.y);
        let l = m.length();
        let s = e.screen_length;
        if l <= 1e-300 {
            // A collapsed edge: the term is unbounded; push it back out along Δuv.
            f += e.weight * 1e12;
            continue;
        }
        let (term, dterm_dl) = if l < s {
            let q = s / l - 1.0;
            (q * q, -2.0 * q * s / (l * l))
        } else {
            let q = (l - s) / s;
            (q * q, 2.0 * q / s)
        };
        f += e.weight * term;
        // ∂l/∂R = (m / l) Δuvᵀ
        let k = e.weight * dterm_dl / l;
        g[0] += k * m.x * e.duv.x;
        g[1] += k * m.x * e.duv.y;
        g[2] += k * m.y * e.duv.x;
        g[3] += k * m.y * e.duv.y;
    }
    (f, g)
}

/// Minimizes eq. 3.1 from a uniform scale. With `scale_only` (a wrapped dimension kept
/// without a branch cut) b and c stay 0.
pub fn most_isometric(edges: &[EdgeTerm], scale_only: bool) -> [f64; 4] {
    let usable: Vec<EdgeTerm> = edges
        .iter()
        .copied()
        .filter(|e| e.screen_length > 1e-6 && e.duv.length() > 1e-12 && e.weight > 0.0)
        .collect();
    if usable.is_empty() {
        return [1.0, 0.0, 0.0, 1.0];
    }
    // Start: the weighted median-free estimate Σ W s / Σ W ‖Δuv‖.
    let (num, den) = usable.iter().fold((0.0, 0.0), |(n, d), e| {
        (n + e.weight * e.screen_length, d + e.weight * e.duv.length())
    });
    let k = num / den;
    let mut r = [k, 0.0, 0.0, k];
    let mask = if scale_only { [1.0, 0.0, 0.0, 1.0] } else { [1.0; 4] };
    let (mut f, mut g) = objective(r, &usable);
    g.iter_mut().zip(mask).for_each(|(g, m)| *g *= m);
    let mut d = g.map(|v| -v);
    for _ in 0..200 {
        let slope: f64 = (0..4).map(|i| g[i] * d[i]).sum();
        if slope >= 0.0 {
            d = g.map(|v| -v);
        }
        let slope: f64 = (0..4).map(|i| g[i] * d[i]).sum();
        if slope.abs() < 1e-14 * f.max(1e-30) {
            break;
        }
        // Backtracking (Armijo) from a step that moves R by at most 10 %.
        let norm_r = r.iter().map(|v| v * v).sum::<f64>().sqrt();
        let norm_d = d.iter().map(|v| v * v).sum::<f64>().sqrt();
        let mut alpha = 0.1 * norm_r / norm_d.max(1e-300);
        let mut accepted = None;
        for _ in 0..60 {
            let trial: [f64; 4] = std::array::from_fn(|i| r[i] + alpha * d[i]);
            let (ft, gt) = objective(trial, &usable);
            if ft <= f + 1e-4 * alpha * slope {
                accepted = Some((trial, ft, gt));
                break;
            }
            alpha *= 0.5;
        }
        let Some((rn, fnew, mut gnew)) = accepted else { break };
        gnew.iter_mut().zip(mask).for_each(|(g, m)| *g *= m);
        let gg: f64 = g.iter().map(|v| v * v).sum();
        let beta =
            ((0..4).map(|i| gnew[i] * (gnew[i] - g[i])).sum::<f64>() / gg.max(1e-300)).max(0.0);
        d = std::array::from_fn(|i| -gnew[i] + beta * d[i]);
        let done = (f - fnew) <= 1e-12 * f;
        r = rn;
        f = fnew;
        g = gnew;
        if done {
            break;
        }
    }
    r
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_gradient_matches_finite_differences() {
        let edges = [
            EdgeTerm { screen_length: 3.0, duv: DVec2::new(0.1, 0.02), weight: 2.0 },
            EdgeTerm { screen_length: 5.0, duv: DVec2::new(-0.03, 0.2), weight: 1.0 },
            EdgeTerm { screen_length: 1.0, duv: DVec2::new(0.05, 0.05), weight: 0.5 },
        ];
        let r = [20.0, 3.0, -2.0, 30.0];
        let (_, g) = objective(r, &edges);
        for i in 0..4 {
            let h = 1e-5;
            let (mut p, mut m) = (r, r);
            p[i] += h;
            m[i] -= h;
            let fd = (objective(p, &edges).0 - objective(m, &edges).0) / (2.0 * h);
            assert!((fd - g[i]).abs() < 1e-5 * fd.abs().max(1e-3), "{i}: {fd} vs {}", g[i]);
        }
    }

    #[test]
    fn an_affinely_distorted_grid_is_undistorted() {
        // screen = M · uv with M = (40 10; 0 20): edges along u, v and the diagonal
        let m = [40.0, 10.0, 0.0, 20.0];
        let mut edges = vec![];
        for duv in [
            DVec2::new(0.1, 0.0),
            DVec2::new(0.0, 0.1),
            DVec2::new(0.1, 0.1),
            DVec2::new(0.1, -0.1),
        ] {
            let s = DVec2::new(m[0] * duv.x + m[1] * duv.y, m[2] * duv.x + m[3] * duv.y).length();
            edges.push(EdgeTerm { screen_length: s, duv, weight: 1.0 });
        }
        let r = most_isometric(&edges, false);
        let (f, _) = objective(r, &edges);
        assert!(f < 1e-8, "f = {f}, R = {r:?}");
    }
}
