//! The texel density of an object's textures, chosen per object (thesis 3.2's used
//! resolution, judged as section 3.4 judges filters: by views the textures were not solved
//! from). The texel budget (`--texels-per-pixel`: K level-0 texels per pixel of the object's
//! most covered view) reduces a texture whose optimal resolution is larger. Where the object's
//! radiance varies faster than K texels a pixel hold (a dense mesh whose charts fill little of
//! their atlas, fine shading detail) more texels predict the set's other views better; where
//! what more texels would fit is the set's noise, they predict them worse. So an object that
//! the budget reduced has its density raised [`STEP`] times at a time, up to [`MOST`] times
//! the budget, while its radiance solved from the set's points less the held-out ones (those
//! of [`Split`], within each sample of the non-view dimensions) predicts the held-out points at least
//! [`HELD_OUT_MARGIN_DB`] better, by a fall of their pixels' squared errors of at least
//! [`SIGNIFICANCE`] standard errors (a set of four views holds one view out, where a few
//! pixels or the set's noise may carry a gain). An object the budget left alone, or whose
//! held-out views gain less, keeps the budget and the same texture.

use anyhow::Result;

use super::held_out::{mean, psnr, Split};
use super::mesh::Placed;
use super::model::Views;
use super::represent::Job;

/// The least gain (dB) over the held-out views that raises an object's texel density.
pub const HELD_OUT_MARGIN_DB: f64 = 0.5;
/// The factor one step raises the density by.
pub const STEP: f64 = 2.0;
/// The most the density is raised by, as a factor on the budget.
pub const MOST: f64 = 4.0;
/// The least a step's held-out pixels' squared errors must fall by, in standard errors of
/// their pixel-by-pixel differences: a step kept by a few pixels, or by the set's noise at
/// one held-out view, is not kept.
pub const SIGNIFICANCE: f64 = 3.0;

/// An object's texel budget, its placement over every view and the views it sees.
pub struct Dense {
    pub texels_per_pixel: Option<f64>,
    pub whole: Placed,
    pub views: Views,
    /// What the choice measured, where it was made.
    pub why: Option<String>,
}

/// One density tried: its budget, texture size, held-out figure (dB) and, past the first,
/// how many standard errors its held-out pixels' squared errors lie below the last's.
struct Tried {
    k: f64,
    size: (u32, u32),
    db: f64,
    z: Option<f64>,
}

/// The texel density of object `name`, placed as `whole` under the request's budget with the
/// views `views` (whose held-out squared errors are `measured` where the filter's choice
/// measured them), where it is `chosen` here; `place` places the object under a budget and
/// measures its views. The choice is noted.
pub fn choose(
    job: &mut Job<'_>,
    chosen: bool,
    name: &str,
    (whole, views, measured): (Placed, Views, Option<Vec<f64>>),
    mut place: impl FnMut(&mut Job<'_>, f64) -> Result<(Placed, Views)>,
) -> Result<Dense> {
    let budget = job.req.texels_per_pixel;
    let keep = |whole, views| Ok(Dense { texels_per_pixel: budget, whole, views, why: None });
    let Some(k) = budget.filter(|_| chosen && job.req.density_choice) else {
        return keep(whole, views);
    };
    let split = Split::of(job, &views);
    if whole.reduction >= 1.0 || split.is_empty() {
        return keep(whole, views);
    }
    let errors = |job: &Job<'_>, views: &Views| split.errors(views, &job.settings, &job.solver);
    let size = |p: &Placed| (p.layout.width, p.layout.height);
    // A solve made twice is read once from a merge's fragments: the filter's figure is reused.
    let mut last = match measured {
        Some(e) => e,
        None => errors(job, &views)?,
    };
    let first = Tried { k, size: size(&whole), db: psnr(mean(&last)), z: None };
    let mut best = (first.k, whole, views);
    let mut tried = vec![first];
    while best.0 * STEP <= k * MOST {
        let (placed, denser) = place(job, best.0 * STEP)?;
        let prev = tried.last().expect("the budget's figure");
        if size(&placed) == prev.size {
            break;
        }
        let e = errors(job, &denser)?;
        let z = standard_errors_below(&last, &e);
        let t = Tried { k: best.0 * STEP, size: size(&placed), db: psnr(mean(&e)), z };
        let gain = t.db - prev.db;
        tried.push(t);
        if gain < HELD_OUT_MARGIN_DB || z.is_none_or(|z| z < SIGNIFICANCE) {
            break;
        }
        last = e;
        best = (best.0 * STEP, placed, denser);
        if best.1.reduction >= 1.0 {
            break;
        }
    }
    let (train, test) = split.counts();
    let why = describe(best.0, &tried, test, train);
    job.note(&format!("object {name}: {why}"));
    Ok(Dense { texels_per_pixel: Some(best.0), whole: best.1, views: best.2, why: Some(why) })
}

/// How many standard errors of the pixel-by-pixel differences the squared errors `after`
/// lie below `before` (the same pixels); `None` where they are not the same pixels or do
/// not differ.
fn standard_errors_below(before: &[f64], after: &[f64]) -> Option<f64> {
    let n = before.len();
    if n != after.len() || n < 2 {
        return None;
    }
    let d: Vec<f64> = before.iter().zip(after).map(|(b, a)| b - a).collect();
    let m = mean(&d);
    let var = d.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1) as f64;
    (var > 0.0).then(|| m / (var / n as f64).sqrt())
}

/// The report's words for the density `k` chosen among `tried`.
fn describe(k: f64, tried: &[Tried], test: usize, train: usize) -> String {
    let figures: Vec<String> = tried
        .iter()
        .map(|t| {
            let z = t.z.map(|z| format!(", {z:.1} standard errors below")).unwrap_or_default();
            format!("{:.2} dB at {} ({} × {} texels{z})", t.db, t.k, t.size.0, t.size.1)
        })
        .collect();
    let texels = if k == 1.0 { "texel" } else { "texels" };
    format!(
        "{k} {texels} per pixel, chosen by held-out views: {test} of the views between the {train} it was solved from, {}",
        figures.join(", ")
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_words_give_every_density_tried() {
        let tried = [
            Tried { k: 1.0, size: (10, 8), db: 30.0, z: None },
            Tried { k: 2.0, size: (14, 11), db: 31.25, z: Some(4.25) },
            Tried { k: 4.0, size: (20, 16), db: 31.5, z: Some(1.0) },
        ];
        assert_eq!(
            describe(1.0, &tried[..2], 2, 3),
            "1 texel per pixel, chosen by held-out views: 2 of the views between the 3 it was solved from, 30.00 dB at 1 (10 × 8 texels), 31.25 dB at 2 (14 × 11 texels, 4.2 standard errors below)"
        );
        assert_eq!(
            describe(2.0, &tried, 2, 3),
            "2 texels per pixel, chosen by held-out views: 2 of the views between the 3 it was solved from, 30.00 dB at 1 (10 × 8 texels), 31.25 dB at 2 (14 × 11 texels, 4.2 standard errors below), 31.50 dB at 4 (20 × 16 texels, 1.0 standard errors below)"
        );
    }

    #[test]
    fn a_fall_carried_by_every_pixel_counts_and_one_carried_by_a_few_does_not() {
        // Every pixel's error falls by about 1 (± 0.1): many standard errors.
        let before: Vec<f64> = (0..100).map(|i| 2.0 + (i % 3) as f64 * 0.1).collect();
        let after: Vec<f64> =
            before.iter().enumerate().map(|(i, b)| b - 1.0 + (i % 2) as f64 * 0.1).collect();
        assert!(standard_errors_below(&before, &after).unwrap() > 50.0);
        // The same mean fall from two pixels of a hundred: under the threshold.
        let mut few = before.clone();
        few[3] -= 50.0;
        few[7] -= 50.0;
        let z = standard_errors_below(&before, &few).unwrap();
        assert!((0.0..SIGNIFICANCE).contains(&z), "{z}");
        // A rise is below zero; other pixels or no difference give none.
        assert!(standard_errors_below(&after, &before).unwrap() < -50.0);
        assert_eq!(standard_errors_below(&before, &before[1..]), None);
        assert_eq!(standard_errors_below(&before, &before), None);
    }
}
