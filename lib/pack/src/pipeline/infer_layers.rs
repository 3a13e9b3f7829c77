//! Inference of every object (thesis 3.5, 4.8): each object's representation chosen
//! ([`super::represent`]), then surveyed, planned and solved, object by object and step by
//! step, with the block origins staggered across the objects that are stored (4.7).

use anyhow::{anyhow, Result};

use super::input::LoadedSet;
use super::matrices::Matrices;
use super::model::ObjectModel;
use super::plan::Plan;
use super::registry::{alternative, choose};
use super::represent::Job;
use super::{PackRequest, Stages};

pub use super::model::{key, InferredLayer, PointView};
pub use super::surface::{BLACK, DISPLAY_STEP};

/// Every object that covers a pixel somewhere in the set, inferred; and, for the objects
/// that have an alternative representation to choose from (`--representation auto`), that
/// alternative, by index into the models.
pub struct Inferred {
    pub models: Vec<ObjectModel>,
    pub alternatives: Vec<(usize, ObjectModel)>,
}

/// Infers every object that covers a pixel somewhere in the set, in its representation and
/// in its alternative, if any.
pub fn infer_all(
    set: &LoadedSet,
    req: &PackRequest,
    plan: &Plan,
    matrices: &mut Matrices,
    stages: &mut Stages,
) -> Result<Inferred> {
    let scene = &set.scene;
    let mut job = Job::new(set, req, plan, matrices, stages.progress());
    let mut surveyed = Vec::new();
    for (o, object) in scene.objects.iter().enumerate() {
        let rep = choose(object.role, req.representation).ok_or_else(|| {
            anyhow!("object {}: no representation stores a {:?} object", object.name, object.role)
        })?;
        if let Some(s) = rep.survey(&mut job, o)? {
            let other = match alternative(object.role, req.representation).filter(|_| {
                super::pem::layered(set, o) || object.role == pis_scene::ObjectRole::Refractive
            }) {
                Some(alt) => alt.survey(&mut job, o)?,
                None => None,
            };
            surveyed.push((s, other));
        }
    }
    if surveyed.is_empty() {
        return Err(anyhow!("no object covers a pixel of the set"));
    }
    let n = surveyed.len();
    let mut planned = Vec::with_capacity(n);
    for (mi, (s, other)) in surveyed.into_iter().enumerate() {
        let st = plan.stagger(mi, n);
        let other = match other {
            Some(a) => Some(a.plan(&mut job, st.clone())?),
            None => None,
        };
        planned.push((s.plan(&mut job, st)?, other));
    }
    let (made, extra) = (job.placements, job.extra_matrices);
    let matrices_text = format!(
        "texture coordinates of {} objects ({made} placements, per {}) and render matrices at {} points ({}; {extra} for block placements)",
        scene.objects.len(), req.placement.name(), set.frames.len(), job.matrices.describe(),
    );
    let progress = job.progress;
    stages.done("matrices", &matrices_text);
    let mut models = Vec::with_capacity(n);
    let mut alternatives = Vec::new();
    let note = |m: &ObjectModel| {
        let sizes_text: Vec<String> = m
            .used_placements()
            .iter()
            .map(|&p| format!("{}x{}", m.placements[p].layout.width, m.placements[p].layout.height))
            .collect();
        progress.note(&format!(
            "object {}: {} texels, {} ({})",
            m.name,
            sizes_text.join(", "),
            m.representation,
            m.why
        ));
    };
    for (mi, (p, other)) in planned.into_iter().enumerate() {
        // A solve shard solves its objects only (pis-pack solve --shard).
        if req.shard.is_some_and(|s| !s.has(mi)) {
            continue;
        }
        // A pack that streams keeps the solved textures in its scratch file.
        let spill = |mut m: ObjectModel| -> Result<ObjectModel> {
            if let Some(scratch) = &set.scratch {
                m.spill_textures(scratch)?;
            }
            Ok(m)
        };
        let m = spill(p.solve(&job)?)?;
        note(&m);
        models.push(m);
        if let Some(a) = other {
            let m = spill(a.solve(&job)?)?;
            note(&m);
            alternatives.push((mi, m));
        }
    }
    let also = if alternatives.is_empty() {
        String::new()
    } else {
        format!(", {} of them also as the alternative", alternatives.len())
    };
    stages.done("infer", &format!("{} objects solved{also}", models.len()));
    Ok(Inferred { models, alternatives })
}
