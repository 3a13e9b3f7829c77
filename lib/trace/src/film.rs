//! The reconstruction filter: a truncated, radially symmetric Gaussian.
//!
//! The tracer importance-samples the filter: each pixel's camera samples are placed around
//! the pixel centre with density proportional to the filter weight, so the plain mean of the
//! samples is the filtered value. Coverage (the filtered object mask) and every layer are
//! estimated from the same samples, i.e. filtered with the same Gaussian (thesis 3.1).

use glam::Vec2;
use serde::{Deserialize, Serialize};
use std::f32::consts::PI;

/// A Gaussian reconstruction filter w(r) ∝ exp(−r² / 2σ²) for r ≤ radius (pixels).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct GaussianFilter {
    /// Standard deviation in pixels.
    pub sigma_px: f32,
    /// Truncation radius in pixels.
    pub radius_px: f32,
}

impl Default for GaussianFilter {
    fn default() -> Self {
        GaussianFilter { sigma_px: 0.5, radius_px: 1.5 }
    }
}

impl GaussianFilter {
    /// Maps a point of the unit square to an offset from the pixel centre distributed with
    /// density proportional to the truncated Gaussian (exact inverse of its radial CDF).
    pub fn sample_offset(&self, u: Vec2) -> Vec2 {
        let s2 = 2.0 * self.sigma_px * self.sigma_px;
        let tail = 1.0 - (-self.radius_px * self.radius_px / s2).exp();
        let r = (-s2 * (1.0 - u.x * tail).max(1e-30).ln()).max(0.0).sqrt();
        let phi = 2.0 * PI * u.y;
        Vec2::new(r * phi.cos(), r * phi.sin())
    }

    /// The (unnormalised) filter weight at offset `d`.
    pub fn weight(&self, d: Vec2) -> f32 {
        let r2 = d.length_squared();
        if r2 > self.radius_px * self.radius_px {
            0.0
        } else {
            (-r2 / (2.0 * self.sigma_px * self.sigma_px)).exp()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::r2_point;

    #[test]
    fn offsets_follow_the_truncated_gaussian() {
        let f = GaussianFilter::default();
        let n = 40_000;
        let (mut m2, mut inside_half) = (0.0f64, 0usize);
        for i in 0..n {
            let d = f.sample_offset(r2_point(i, Vec2::ZERO));
            assert!(d.length() <= f.radius_px + 1e-4);
            m2 += d.length_squared() as f64;
            if d.length() <= 0.5 {
                inside_half += 1;
            }
        }
        // Expected fraction within r: (1 − e^{−r²/2σ²}) / (1 − e^{−R²/2σ²}).
        let cdf = |r: f32| 1.0 - (-r * r / (2.0 * f.sigma_px * f.sigma_px)).exp();
        let expect = cdf(0.5) / cdf(f.radius_px);
        assert!((inside_half as f32 / n as f32 - expect).abs() < 0.01);
        assert!(m2 / (n as f64) < 2.0 * (f.sigma_px * f.sigma_px) as f64);
    }
}
