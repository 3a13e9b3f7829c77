//! Adaptive sampling: a pixel takes camera samples in rounds and stops once its estimated
//! error is below the render's noise threshold.
//!
//! The estimate compares two half buffers of the pixel's samples, the stopping rule's halves
//! ([`check_half`]; Cycles' adaptive sampling compares a half with the whole): for every
//! value the inference reads (the combined image, and per object its coverage and its
//! premultiplied diffuse, specular, local, distant, reflection and refraction layers), clamped
//! to the display range [0, 1] first (a highlight far above white is converged once both
//! halves are above it),
//!
//! ```text
//! error = Σ_c |A_c − B_c| / 2 / (10⁻⁴ + √(Σ_c F_c))
//! ```
//!
//! with A, B the halves' means and F the whole pixel's, and the pixel's error the largest of
//! them. Relative to the square root of the value it is display-referred in the way noise is
//! seen: an error of 0.01 is about 1 % in a mid-grey pixel.
//!
//! **Halves apart from the denoiser's.** The denoiser's estimate of its own error
//! (`denoise.rs`) reads the pixel's even and odd samples, two independently rotated sequences.
//! A rule that stopped a pixel when those two happened to agree would stop it on a small
//! |even − odd| and leave the estimate a noise smaller than the pixel's: with Gaussian pixels
//! (the test below) a half's variance read 19 times below the truth, and on teapot-pem's
//! paper preset (threshold 0.05, 60 samples a pixel on average) the mirror's specular and
//! distant layers were kept raw and its body read 28.9 dB from converged, against 30.1 dB at a
//! fixed 16 samples (docs/benchmarks/clean-sets.md). The rule reads another split instead,
//! sample s in half bit 0 ⊕ bit 1 of s ([`check_half`]): over every four samples each of its
//! halves holds one even and one odd sample, so its difference (+ − − +) is orthogonal to the
//! even-minus-odd one (+ − + −), and with independent samples of equal variance the two
//! differences are uncorrelated: what the rule selects on says nothing of the denoiser's
//! halves. (With `--min-spp 2` the first round's two samples are split as the denoiser's.)
//!
//! Rounds double the pixel's samples, from `min_spp` to `spp`. A pixel's samples are always
//! the first N of its fixed sequence and its decision reads its own samples only, so an
//! adaptive render is the same on any thread count (the band's first-hit irradiance cache,
//! whose cells keep the estimate of the first sample that reaches them, is filled in the
//! same order too).

use crate::layers::{ObjectAccum, PixelAccum};
use glam::Vec3;

/// Regularizes the relative error of near-black values.
const ERROR_EPSILON: f32 = 1e-4;

/// The samples of the first round: `min_spp` (at least 2, even, at most `spp`), or every
/// sample when the render is not adaptive.
pub fn first_round(spp: u32, min_spp: u32, adaptive: bool) -> u32 {
    if !adaptive {
        return spp;
    }
    let min = min_spp.max(2).next_multiple_of(2);
    min.min(spp)
}

/// The samples every pixel takes before its error is first estimated, unless told otherwise
/// (`pis-trace --min-spp`). The denoiser judges its own error from halves of the samples a
/// pixel stopped at: from 4, halves of 2 read so noisy that it keeps most layers raw (five
/// scenes measured, docs/benchmarks/clean-sets.md).
pub const MIN_SPP: u32 = 16;

/// Which of the stopping rule's halves sample `s` of a pixel goes to: bit 0 ⊕ bit 1 of `s`
/// (samples 0 and 3 of every four in half 0, 1 and 2 in half 1).
pub fn check_half(s: u32) -> usize {
    ((s ^ (s >> 1)) & 1) as usize
}

/// The samples after the round that follows one ending at `done`: twice as many, at most
/// `spp`.
pub fn next_round(done: u32, spp: u32) -> u32 {
    done.saturating_mul(2).min(spp)
}

/// The estimated relative error of a pixel from its even (`halves[0]`) and odd
/// (`halves[1]`) samples; 0 while either half is empty.
pub fn pixel_error(halves: &[PixelAccum; 2]) -> f32 {
    let [a, b] = halves;
    if a.samples == 0 || b.samples == 0 {
        return 0.0;
    }
    let (na, nb) = (a.samples as f32, b.samples as f32);
    let mut worst = group_error(a.combined, na, b.combined, nb);
    for oa in &a.objects {
        let ob = b.objects.iter().find(|o| o.object == oa.object);
        worst = worst.max(object_error(Some(oa), na, ob, nb));
    }
    for ob in b.objects.iter().filter(|o| !a.objects.iter().any(|x| x.object == o.object)) {
        worst = worst.max(object_error(None, na, Some(ob), nb));
    }
    worst
}

/// The largest error among one object's values in the two halves (absent: it hit nothing
/// there).
fn object_error(a: Option<&ObjectAccum>, na: f32, b: Option<&ObjectAccum>, nb: f32) -> f32 {
    let va = a.map(object_values).unwrap_or_default();
    let vb = b.map(object_values).unwrap_or_default();
    va.iter().zip(&vb).map(|(&x, &y)| group_error(x, na, y, nb)).fold(0.0, f32::max)
}

/// An object's sums the inference reads, each premultiplied by its coverage: coverage (as
/// grey), diffuse, specular, local, distant, and the lens terms.
fn object_values(o: &ObjectAccum) -> [Vec3; 9] {
    [
        Vec3::splat(o.count as f32),
        o.diffuse,
        o.specular,
        o.local,
        o.distant,
        o.term_value[0],
        o.term_value[1],
        o.term_value[2],
        o.term_value[3],
    ]
}

/// The relative error of one RGB value whose halves sum to `sa` over `na` samples and `sb`
/// over `nb`.
fn group_error(sa: Vec3, na: f32, sb: Vec3, nb: f32) -> f32 {
    let display = |v: Vec3| v.clamp(Vec3::ZERO, Vec3::ONE);
    let (a, b) = (display(sa / na), display(sb / nb));
    let whole = display((sa + sb) / (na + nb));
    (a - b).abs().element_sum() * 0.5 / (ERROR_EPSILON + whole.element_sum().sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pixel(samples: u32, combined: Vec3) -> PixelAccum {
        PixelAccum { samples, combined: combined * samples as f32, ..Default::default() }
    }

    #[test]
    fn rounds_double_from_the_minimum_to_the_maximum() {
        assert_eq!(first_round(64, 4, true), 4);
        assert_eq!(first_round(64, 3, true), 4);
        assert_eq!(first_round(64, 0, true), 2);
        assert_eq!(first_round(3, 8, true), 3);
        assert_eq!(first_round(64, 4, false), 64);
        let mut n = first_round(40, 4, true);
        let mut seen = vec![n];
        while n < 40 {
            n = next_round(n, 40);
            seen.push(n);
        }
        assert_eq!(seen, [4, 8, 16, 32, 40]);
    }

    #[test]
    fn the_rules_halves_are_orthogonal_to_the_even_and_odd_samples() {
        for block in 0..8u32 {
            let s0 = block * 4;
            let dot: i32 = (s0..s0 + 4)
                .map(|s| {
                    let parity = if s % 2 == 0 { 1 } else { -1 };
                    let check = if check_half(s) == 0 { 1 } else { -1 };
                    parity * check
                })
                .sum();
            assert_eq!(dot, 0, "block {block}");
            let evens = (s0..s0 + 4).filter(|&s| check_half(s) == 0 && s % 2 == 0).count();
            assert_eq!(evens, 1, "half 0 holds one even and one odd sample of every four");
        }
    }

    /// Pixels of independent Gaussian samples (mean 0.5, σ 0.2), stopped by the rule at
    /// threshold 0.03 from 4 to 256 samples: over the pixels that stopped before the most,
    /// the mean ½|even − odd|² (a half's variance) against the true one, σ² over half the
    /// samples. Stopped on the even and odd halves themselves, the estimate reads far low.
    #[test]
    fn what_stops_a_pixel_does_not_bias_the_denoisers_halves() {
        let sigma = 0.2f32;
        let run = |split: fn(u32) -> usize| {
            let mut rng = crate::sampling::Rng::new(7);
            let (mut ratio, mut stopped) = (0.0f64, 0);
            for _ in 0..4000 {
                let (mut halves, mut checks) =
                    (<[PixelAccum; 2]>::default(), <[PixelAccum; 2]>::default());
                let (mut s, mut end) = (0, first_round(256, 4, true));
                loop {
                    while s < end {
                        // Box–Muller from two uniforms.
                        let [u, v] = rng.next_2d().to_array();
                        let g = (-2.0 * (1.0 - u).ln()).sqrt() * (std::f32::consts::TAU * v).cos();
                        let value = Vec3::splat(0.5 + sigma * g);
                        for (acc, k) in [(&mut halves, (s % 2) as usize), (&mut checks, split(s))] {
                            acc[k].samples += 1;
                            acc[k].combined += value;
                        }
                        s += 1;
                    }
                    if end >= 256 || pixel_error(&checks) < 0.03 {
                        break;
                    }
                    end = next_round(end, 256);
                }
                if s < 256 {
                    let half = (s / 2) as f32;
                    let d = halves[0].combined.x / half - halves[1].combined.x / half;
                    ratio += (0.5 * d * d / (sigma * sigma / half)) as f64;
                    stopped += 1;
                }
            }
            ratio / stopped.max(1) as f64
        };
        let apart = run(check_half);
        let same = run(|s| (s % 2) as usize);
        eprintln!(
            "a half's variance over the truth: {apart:.3} apart, {same:.3} on the same halves"
        );
        assert!((0.85..1.15).contains(&apart), "stopped on the rule's halves: {apart}");
        assert!(same < 0.6, "stopped on the even and odd halves: {same}");
    }

    #[test]
    fn equal_halves_have_no_error_and_differing_ones_do() {
        let grey = Vec3::splat(0.5);
        assert_eq!(pixel_error(&[pixel(4, grey), pixel(4, grey)]), 0.0);
        let e = pixel_error(&[pixel(4, grey), pixel(4, grey * 1.02)]);
        // |0.5 − 0.51| · 3 / 2 / √1.515.
        assert!((e - 0.0122).abs() < 2e-4, "{e}");
        assert_eq!(pixel_error(&[pixel(0, grey), pixel(4, grey)]), 0.0);
    }

    #[test]
    fn values_above_white_are_converged_once_both_halves_are() {
        let e = pixel_error(&[pixel(4, Vec3::splat(40.0)), pixel(4, Vec3::splat(400.0))]);
        assert_eq!(e, 0.0);
        let e = pixel_error(&[pixel(4, Vec3::splat(0.2)), pixel(4, Vec3::splat(400.0))]);
        assert!(e > 0.5, "{e}");
    }

    #[test]
    fn an_object_seen_by_one_half_only_is_an_error() {
        let grey = Vec3::splat(0.5);
        let mut a = pixel(4, grey);
        let b = pixel(4, grey);
        a.objects.push(ObjectAccum { object: 3, count: 2, ..Default::default() });
        // Coverage 0.5 against 0: |0.5| · 3 / 2 / √(0.75).
        let e = pixel_error(&[a.clone(), b.clone()]);
        assert!((e - 0.866).abs() < 1e-3, "{e}");
        assert_eq!(pixel_error(&[b, a]), e);
    }
}
