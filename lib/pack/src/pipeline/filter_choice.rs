//! The texture filter of an object's textures, chosen per object (thesis 3.4, figs. 3.7–3.11):
//! trilinear lookups, or bilinear ones of level 0. Trilinear filtering takes its level of
//! detail from the pixel footprint's major axis, so a face seen at a grazing angle reads
//! coarse levels and is blurred along the minor axis, whatever texture the solve finds;
//! bilinear lookups are sharp there, but textures solved for them are sharpest at the views
//! they were solved from and may alias between them. So the choice is made on views the
//! textures were not solved from: the object's radiance (diffuse and specular together,
//! view-independently) solved from the other points of the set with each filter and drawn
//! at the points between them; bilinear is kept where it predicts those at least
//! [`HELD_OUT_MARGIN_DB`] better. Only an object whose trilinear render matrices put at least
//! [`COARSE_SHARE`] of their weight on coarser levels is tried: elsewhere the two filters
//! read the same texels.

use anyhow::Result;
use pis_compile::Filter;

use super::held_out::{mean, psnr, Split};
use super::mesh::Placed;
use super::model::Views;
use super::represent::Job;

/// The least gain (dB) over the held-out views that makes bilinear lookups an object's filter.
pub const HELD_OUT_MARGIN_DB: f64 = 0.5;
/// The least share of the trilinear render matrices' weight on levels coarser than 0 for
/// which bilinear lookups are tried.
pub const COARSE_SHARE: f64 = 0.2;

/// An object's filter and the views its textures are solved from with it.
pub struct Chosen {
    pub filter: Filter,
    pub views: Views,
    /// What the choice measured, where it was made.
    pub why: Option<String>,
    /// Where it was measured, the squared errors of the held-out pixels with the filter
    /// chosen ([`Split::errors`]).
    pub held_out: Option<Vec<f64>>,
}

/// The filter of object `name` (placement `whole`) whose views with the request's filter
/// are `views`, where it is `chosen` here; `bilinear` measures its views with bilinear
/// lookups. The choice is noted.
pub fn choose(
    job: &mut Job<'_>,
    chosen: bool,
    name: &str,
    whole: &Placed,
    views: Views,
    bilinear: impl FnOnce(&mut Job<'_>) -> Result<Views>,
) -> Result<Chosen> {
    let req = job.req;
    if !chosen || !req.filter_choice || req.filter != Filter::Trilinear {
        return Ok(Chosen { filter: req.filter, views, why: None, held_out: None });
    }
    let c = measure(job, whole, views, bilinear)?;
    if let Some(why) = &c.why {
        job.note(&format!("object {name}: {why}"));
    }
    Ok(c)
}

/// [`choose`]'s measurement, for an object whose filter is chosen.
fn measure(
    job: &mut Job<'_>,
    whole: &Placed,
    views: Views,
    bilinear: impl FnOnce(&mut Job<'_>) -> Result<Views>,
) -> Result<Chosen> {
    let req = job.req;
    let keep = |views, why, held_out| Ok(Chosen { filter: req.filter, views, why, held_out });
    let level0 = whole.layout.width as usize * whole.layout.height as usize;
    let share = coarse_share(&views, level0)?;
    let split = Split::of(job, &views);
    if share < COARSE_SHARE || split.is_empty() {
        return keep(views, None, None);
    }
    let trilinear_errors = split.errors(&views, &job.settings, &job.solver)?;
    let bilinear_views = bilinear(job)?;
    let bilinear_errors = split.errors(&bilinear_views, &job.settings, &job.solver)?;
    let (train, test) = split.counts();
    let (trilinear, bilinear) = (psnr(mean(&trilinear_errors)), psnr(mean(&bilinear_errors)));
    let measured = format!(
        "{} of the views between the {} it was solved from: {bilinear:.2} dB with bilinear lookups, {trilinear:.2} dB with trilinear ones ({:.0}% of whose weight is on coarser levels)",
        test,
        train,
        share * 100.0
    );
    if bilinear >= trilinear + HELD_OUT_MARGIN_DB {
        let why = format!("filter bilinear, chosen by held-out views: {measured}");
        let held_out = Some(bilinear_errors);
        Ok(Chosen { filter: Filter::Bilinear, views: bilinear_views, why: Some(why), held_out })
    } else {
        let why = format!("filter trilinear, chosen by held-out views: {measured}");
        keep(views, Some(why), Some(trilinear_errors))
    }
}

/// The share of the render matrices' weight (every point's) on columns past `level0`, the
/// texels of the coarser levels.
pub fn coarse_share(views: &Views, level0: usize) -> Result<f64> {
    let (mut coarse, mut all) = (0.0f64, 0.0f64);
    for p in 0..views.len() {
        let v = views.get(p)?;
        let a = v.a(0);
        for (&c, &w) in a.cols.iter().zip(&a.vals) {
            all += f64::from(w.abs());
            if c as usize >= level0 {
                coarse += f64::from(w.abs());
            }
        }
    }
    Ok(if all > 0.0 { coarse / all } else { 0.0 })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pipeline::held_out::tests::views;

    #[test]
    fn the_coarse_share_is_the_weight_past_level_0() {
        let s = coarse_share(&views(&[4, 4]), 16).unwrap();
        assert!((s - 0.25).abs() < 1e-6, "{s}");
        assert_eq!(coarse_share(&views(&[4]), 21).unwrap(), 0.0);
    }
}
