//! The gold standard's own noise, by the reference pair (`pis-diff --reference-pair`).
//!
//! A figure measured against a ray-traced set carries that set's Monte Carlo noise: for
//! values `v` and a reference `r₁ = t + n₁` about the converged image `t`,
//! E[(v − r₁)²] = (v − t)² + σ². A second trace of the same points from an independent
//! sample stream, `r₂ = t + n₂`, measures it: E[(r₁ − r₂)²] = 2σ². So beside each figure the
//! reference's own noise is printed as a PSNR (σ², the pair's squared difference halved) and
//! the figure with that noise taken out ((v − r₁)² − σ²), as pis-bench's reference pair does
//! ([`crate::metrics::PairedError`]). What the pair cannot see is what both traces share: a
//! denoiser's blur, a bias of the renderer, a set seeded per surface cell (both traces then
//! carry the same surface noise; trace gold standards with `--shading-seed sample`).

use serde::Serialize;

/// 10 log₁₀ 2: a pair's difference has twice the variance of one trace's noise.
const PAIR_DB: f64 = std::f64::consts::LN_2 * 10.0 / std::f64::consts::LN_10;

/// One figure judged by a reference whose noise the pair measured.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct Judged {
    /// What the figure is: `whole image`, `objects' covered pixels` or an object's name.
    pub name: String,
    /// The figure as measured against the reference (dB; null: an exact match).
    pub psnr_db: Option<f64>,
    /// The reference's own noise over the same pixels, as a PSNR (dB; null: the two traces
    /// agree exactly, as a set seeded per cell does with itself).
    pub noise_psnr_db: Option<f64>,
    /// The figure with the reference's noise taken out: an estimate of its PSNR against the
    /// converged image (null: the measured error is within the reference's noise).
    pub noise_removed_psnr_db: Option<f64>,
}

/// The reference's own noise, measured by a second trace.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct ReferenceNoise {
    /// The second trace's folder.
    pub pair: String,
    /// Points both traces hold.
    pub points: usize,
    pub figures: Vec<Judged>,
}

/// Mean squared error of a PSNR (peak 1); `None` (an exact match) is 0.
pub(crate) fn mse(psnr: Option<f64>) -> f64 {
    psnr.map_or(0.0, |p| 10f64.powf(-p / 10.0))
}

pub(crate) fn psnr(mse: f64) -> Option<f64> {
    (mse > 0.0).then(|| -10.0 * mse.log10())
}

/// One figure judged: `measured` against the reference, `between` the pair's own PSNR.
pub fn judge(name: &str, measured: Option<f64>, between: Option<f64>) -> Judged {
    let noise = between.map(|b| b + PAIR_DB);
    Judged {
        name: name.to_string(),
        psnr_db: measured,
        noise_psnr_db: noise,
        noise_removed_psnr_db: psnr(mse(measured) - mse(noise)),
    }
}

/// The readable lines: each figure beside its reference's noise.
pub fn render(n: &ReferenceNoise) -> String {
    use std::fmt::Write;
    let db = |v: Option<f64>, none: &str| v.map_or(none.to_string(), |v| format!("{v:.2} dB"));
    let mut s = String::new();
    let _ = writeln!(
        s,
        "  the reference's own noise, from its second trace {} ({} points):",
        n.pair, n.points
    );
    let _ = writeln!(
        s,
        "    {:<24} {:>10} {:>16} {:>18}",
        "", "measured", "reference noise", "noise taken out"
    );
    for f in &n.figures {
        let _ = writeln!(
            s,
            "    {:<24} {:>10} {:>16} {:>18}",
            f.name,
            db(f.psnr_db, "inf"),
            db(f.noise_psnr_db, "none"),
            db(f.noise_removed_psnr_db, "within noise")
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_figure_judged_by_a_noisy_reference() {
        // Measured MSE 0.002 (26.99 dB), the pair's difference 0.002 (one trace's noise
        // 0.001, 30 dB): the converged figure is 0.001, 30 dB.
        let measured = Some(-10.0 * 0.002f64.log10());
        let j = judge("Teapot", measured, measured);
        assert!((j.noise_psnr_db.unwrap() - 30.0).abs() < 1e-9, "{j:?}");
        assert!((j.noise_removed_psnr_db.unwrap() - 30.0).abs() < 1e-9, "{j:?}");
        // A figure within the reference's noise has no estimate; an exact pair no noise.
        assert_eq!(judge("x", Some(40.0), Some(30.0)).noise_removed_psnr_db, None);
        let exact = judge("x", Some(40.0), None);
        assert_eq!((exact.noise_psnr_db, exact.noise_removed_psnr_db), (None, Some(40.0)));
    }
}
