//! Adaptive sampling: a pixel takes camera samples in rounds and stops once its estimated
//! error is below the render's noise threshold.
//!
//! The estimate compares two independent half buffers, the pixel's even and odd samples
//! (Cycles' adaptive sampling compares a half with the whole): for every value the inference
//! reads (the combined image, and per object its coverage and its premultiplied diffuse,
//! specular, local, distant, reflection and refraction layers), clamped to the display range
//! [0, 1] first (a highlight far above white is converged once both halves are above it),
//!
//! ```text
//! error = Σ_c |A_c − B_c| / 2 / (10⁻⁴ + √(Σ_c F_c))
//! ```
//!
//! with A, B the halves' means and F the whole pixel's, and the pixel's error the largest of
//! them. Relative to the square root of the value it is display-referred in the way noise is
//! seen: an error of 0.01 is about 1 % in a mid-grey pixel.
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
