//! `--representation auto`: per object, of the representations solved for it, the one that
//! meets the target with fewer bytes. The allocation is global (thesis 4.5: every level
//! image at one slope), so an object's representation is judged by the whole file: the file
//! is encoded and predicted with the object in each representation, the others as chosen so
//! far, and the alternative is kept when it does better —
//!
//! - under a PSNR target: it meets the target and the file is at least [`BYTES_MARGIN`]
//!   smaller, or it meets the target and the other does not;
//! - under a played quality (pis-pack's default): the same, every file searched for one
//!   goal, the target below the best solved figure either representation gives, so that a
//!   representation that plays better wins unless the other meets its goal with fewer bytes;
//! - under a byte budget (a ratio) or lossless: the file's predicted PSNR is at least
//!   [`PSNR_MARGIN_DB`] higher (on the rate–distortion front, the same error for fewer bytes).
//!
//! Objects are taken in scene order, each starting from its first representation (surface
//! textures: a reflective object is stored as more than a texture only where that pays).

use anyhow::anyhow;

use super::encode::encode_all;
use super::infer_layers::Inferred;
use super::input::LoadedSet;
use super::model::ObjectModel;
use super::packed::Packed;
use super::packed::Quality;
use super::plan::{Aim, Plan};
use super::predict::{predicted_psnr, solved_error, total_psnr};
use super::{PackRequest, Stages};
use crate::error::{Exit, Failure};

/// The least PSNR gain (dB) that makes the alternative the better under a byte budget.
pub const PSNR_MARGIN_DB: f64 = 0.05;
/// The least share of the file's level-image bytes the alternative must save under a PSNR
/// target.
pub const BYTES_MARGIN: f64 = 0.01;

/// A file as encoded and predicted: its level-image bytes and predicted PSNR.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Outcome {
    pub bytes: usize,
    pub psnr_db: f64,
}

/// Whether `b` does better than `a` for a PSNR target `target_db` (`None`: a byte budget or
/// lossless).
pub fn better(b: Outcome, a: Outcome, target_db: Option<f64>) -> bool {
    match target_db {
        Some(t) => {
            let (meets_a, meets_b) = (a.psnr_db >= t - 1e-3, b.psnr_db >= t - 1e-3);
            match (meets_a, meets_b) {
                (false, true) => true,
                (true, true) => (b.bytes as f64) < a.bytes as f64 * (1.0 - BYTES_MARGIN),
                (_, false) => !meets_a && b.psnr_db > a.psnr_db + PSNR_MARGIN_DB,
            }
        }
        None => b.psnr_db > a.psnr_db + PSNR_MARGIN_DB,
    }
}

/// How the report names a model's representation.
fn label(m: &ObjectModel) -> String {
    if m.shells.is_none() {
        format!("surface textures ({})", m.representation)
    } else {
        m.representation.clone()
    }
}

/// The solved PSNR of the file `packed` encodes with object model `mi` replaced by `alt`:
/// the other objects' solved errors as measured, this one drawn again.
fn solved_with(
    set: &LoadedSet,
    packed: &Packed,
    mi: usize,
    alt: &ObjectModel,
) -> Result<f64, Failure> {
    let mut e = packed.solved_error.clone();
    e[mi] = solved_error(set, alt).map_err(|e| Failure::new(Exit::Runtime, e))?;
    Ok(total_psnr(&e))
}

fn encoded(
    set: &LoadedSet,
    models: &[ObjectModel],
    plan: &Plan,
    req: &PackRequest,
) -> Result<(Packed, Quality, Outcome), Failure> {
    let mut stages = Stages::quiet();
    let packed = encode_all(set, models, plan, req, &mut stages)?;
    let quality =
        predicted_psnr(set, models, &packed).map_err(|e| Failure::new(Exit::Runtime, e))?;
    let bytes = packed.layer_bytes.iter().flatten().sum();
    let outcome = Outcome { bytes, psnr_db: quality.overall };
    Ok((packed, quality, outcome))
}

/// The models chosen, and, where alternatives were weighed, the chosen file as encoded and
/// predicted.
pub type Choice = (Vec<ObjectModel>, Option<(Packed, Quality)>);

/// The models chosen from `inferred` for `req`, each alternative's decision added to its
/// object's `why`; with alternatives, also the chosen file as encoded and predicted.
pub fn choose(
    set: &LoadedSet,
    inferred: Inferred,
    plan: &Plan,
    req: &PackRequest,
    stages: &mut Stages,
) -> Result<Choice, Failure> {
    let Inferred { mut models, alternatives } = inferred;
    if alternatives.is_empty() {
        return Ok((models, None));
    }
    let (mut packed, mut quality, mut current) = encoded(set, &models, plan, req)?;
    // Under a played quality, every file is weighed at one goal: within the target of the
    // best solved figure met so far, so that a representation that plays better raises it.
    let within = match plan.target {
        Aim::Played { within_db, goal_db: None } if req.codec.is_lossy() => Some(within_db),
        _ => None,
    };
    let mut goal = within.map(|d| quality.overall_solved - d);
    let budget = |goal: Option<f64>| match (goal, req.target.psnr()) {
        (Some(g), _) => format!("for {g:.2} dB played"),
        (None, Some(t)) => format!("for {t} dB"),
        (None, None) if req.codec == pis_codec::CodecId::Lossless => "lossless".to_string(),
        (None, None) => "at the same budget".to_string(),
    };
    let mut kept = 0;
    for (mi, mut alt) in alternatives {
        if mi >= models.len() {
            return Err(Failure::new(
                Exit::Runtime,
                anyhow!("an alternative names object model {mi} of {}", models.len()),
            ));
        }
        // A better solved figure raises the goal: the current file is searched again for it.
        if let (Some(d), Some(g)) = (within, goal) {
            let raised = solved_with(set, &packed, mi, &alt)? - d;
            if raised > g {
                goal = Some(raised);
                (packed, quality, current) = encoded(set, &models, &plan.played_at(raised), req)?;
            }
        }
        std::mem::swap(&mut models[mi], &mut alt);
        let (first, second) = (label(&alt), label(&models[mi]));
        let at = goal.map_or_else(|| plan.clone(), |g| plan.played_at(g));
        let trial = encoded(set, &models, &at, req);
        let target = goal.or(req.target.psnr());
        let budget = budget(goal);
        let said = |o: Outcome| format!("{:.2} dB with {} bytes", o.psnr_db, o.bytes);
        let why = match trial {
            Ok((p, q, o)) if better(o, current, target) => {
                let why = format!(
                    "auto: {second}, the file {} {budget} against {} as {first}",
                    said(o),
                    said(current)
                );
                (packed, quality, current) = (p, q, o);
                kept += 1;
                if let Some(a) = models[mi].auto.as_mut() {
                    a.kept = true;
                }
                why
            }
            Ok((_, _, o)) => {
                std::mem::swap(&mut models[mi], &mut alt);
                format!(
                    "auto: {first}, the file {} {budget} against {} as {second}",
                    said(current),
                    said(o)
                )
            }
            Err(e) => {
                std::mem::swap(&mut models[mi], &mut alt);
                format!("auto: {first}; as {second} the file could not be encoded: {}", e.error)
            }
        };
        let m = &mut models[mi];
        m.why = format!("{}; {why}", m.why);
        stages.note(&format!("object {}: {why}", m.name));
    }
    stages.done(
        "choose",
        &format!("{kept} object(s) in their alternative representation, by whole-file encodes"),
    );
    Ok((models, Some((packed, quality))))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn o(bytes: usize, psnr_db: f64) -> Outcome {
        Outcome { bytes, psnr_db }
    }

    #[test]
    fn under_a_budget_the_higher_psnr_wins_by_a_margin() {
        assert!(better(o(1000, 25.0), o(1000, 24.0), None));
        assert!(
            !better(o(900, 24.02), o(1000, 24.0), None),
            "within the margin the first representation stays"
        );
        assert!(!better(o(1000, 23.0), o(500, 24.0), None));
    }

    #[test]
    fn under_a_psnr_target_fewer_bytes_win_among_those_that_meet_it() {
        let t = Some(30.0);
        assert!(better(o(900, 30.0), o(1000, 31.0), t), "both meet it: fewer bytes");
        assert!(!better(o(995, 30.5), o(1000, 30.0), t), "both meet it, within the margin");
        assert!(better(o(2000, 30.1), o(1000, 29.0), t), "only the alternative meets it");
        assert!(!better(o(500, 29.0), o(1000, 30.2), t), "only the first meets it");
        assert!(better(o(1000, 29.5), o(1000, 28.0), t), "neither meets it: the closer");
    }
}
