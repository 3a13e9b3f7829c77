//! Inference of every object (thesis 3.5, 4.8): each object's representation chosen
//! ([`super::represent`]), then surveyed, planned and solved, object by object and step by
//! step, with the block origins staggered across the objects that are stored (4.7).

use anyhow::{anyhow, Result};

use super::input::LoadedSet;
use super::matrices::Matrices;
use super::model::{AutoChoice, ObjectModel};
use super::plan::Plan;
use super::predict::{psnr, solved_error};
use super::registry::{alternative, choose};
use super::represent::Job;
use super::screen;
use super::{PackRequest, RepresentationMode, Stages};

pub use super::model::{key, InferredLayer, PointView};
pub use super::surface::{BLACK, DISPLAY_STEP};

/// Every object that covers a pixel somewhere in the set, inferred; and, for the objects
/// that have an alternative representation to choose from (`--representation auto`), that
/// alternative, by index into the models.
pub struct Inferred {
    pub models: Vec<ObjectModel>,
    pub alternatives: Vec<(usize, ObjectModel)>,
}

/// Infers every object that covers a pixel somewhere in the set, in its representation and,
/// where [`super::screen`] finds its textures fall short (or, in a solve shard, wherever
/// there is one), in its alternative.
pub fn infer_all(
    set: &LoadedSet,
    req: &PackRequest,
    plan: &Plan,
    matrices: &mut Matrices,
    stages: &mut Stages,
) -> Result<Inferred> {
    let scene = &set.scene;
    // A solve shard holds some objects only, not the other objects' solved figures the screen
    // reads: it solves every alternative, and the merge screens them as one process would.
    let screened = req.shard.is_none();
    let mut job = Job::new(set, req, plan, matrices, stages.progress());
    let mut surveyed = Vec::new();
    for (o, object) in scene.objects.iter().enumerate() {
        // A translucent object is stored as surface textures with its opacity, whatever the
        // representation asked for (shells are composited over an opaque surface).
        let mode = if job.meshes[o].translucent {
            if !matches!(req.representation, RepresentationMode::Texture | RepresentationMode::Auto)
            {
                job.note(&format!(
                    "object {}: translucent (glTF alpha mode MASK or BLEND): stored as surface textures with its opacity",
                    object.name
                ));
            }
            RepresentationMode::Texture
        } else {
            req.representation
        };
        let rep = choose(object.role, mode).ok_or_else(|| {
            anyhow!("object {}: no representation stores a {:?} object", object.name, object.role)
        })?;
        if let Some(s) = rep.survey(&mut job, o)? {
            surveyed.push((o, s));
        }
    }
    if surveyed.is_empty() {
        return Err(anyhow!("no object covers a pixel of the set"));
    }
    let n = surveyed.len();
    let mut planned = Vec::with_capacity(n);
    for (mi, (o, s)) in surveyed.into_iter().enumerate() {
        planned.push((o, s.plan(&mut job, plan.stagger(mi, n))?));
    }
    let (made, extra) = (job.placements, job.extra_matrices);
    let matrices_text = format!(
        "texture coordinates of {} objects ({made} placements, per {}) and render matrices at {} points ({}; {extra} for block placements)",
        scene.objects.len(), req.placement.name(), set.frames.len(), job.matrices.describe(),
    );
    stages.done("matrices", &matrices_text);
    let mut models = Vec::with_capacity(n);
    let mut alternatives = Vec::new();
    let mut objects = Vec::with_capacity(n);
    for (mi, (o, p)) in planned.into_iter().enumerate() {
        // A solve shard solves its objects only (pis-pack solve --shard).
        if req.shard.is_some_and(|s| !s.has(mi)) {
            continue;
        }
        models.push(solved(&job, p)?);
        objects.push(o);
        let alt = alternative_of(set, req, o).filter(|_| !screened);
        if let Some(Ok(Some(m))) = alt.map(|a| alternative_model(&mut job, a, o, mi, n)) {
            alternatives.push((models.len() - 1, m));
        }
    }
    if screened {
        alternatives = screen(&mut job, &mut models, &objects)?;
    }
    let also = if alternatives.is_empty() {
        String::new()
    } else {
        format!(", {} of them also as the alternative", alternatives.len())
    };
    stages.done("infer", &format!("{} objects solved{also}", models.len()));
    Ok(Inferred { models, alternatives })
}

/// The alternative representation of object `o` under `req`, where it has the layers it
/// needs (the reflective layers for layered shells; a refractive object's hybrid rendering
/// says itself when the set has no ray records).
fn alternative_of(
    set: &LoadedSet,
    req: &PackRequest,
    o: usize,
) -> Option<&'static dyn super::represent::Representation> {
    let role = set.scene.objects[o].role;
    if super::mesh::is_translucent(&set.scene, o) {
        return None;
    }
    alternative(role, req.representation)
        .filter(|_| super::pem::layered(set, o) || role == pis_scene::ObjectRole::Refractive)
}

/// `p` solved, its textures kept in the scratch file of a pack that streams, and noted.
fn solved(job: &Job<'_>, p: Box<dyn super::represent::Planned>) -> Result<ObjectModel> {
    let mut m = p.solve(job)?;
    if let Some(scratch) = &job.set.scratch {
        m.spill_textures(scratch)?;
    }
    let sizes_text: Vec<String> = m
        .used_placements()
        .iter()
        .map(|&p| format!("{}x{}", m.placements[p].layout.width, m.placements[p].layout.height))
        .collect();
    job.note(&format!(
        "object {}: {} texels, {} ({})",
        m.name,
        sizes_text.join(", "),
        m.representation,
        m.why
    ));
    Ok(m)
}

/// Object `o` (object model `mi` of `n`) in its alternative `alt`: surveyed, planned and
/// solved; `Ok(None)` where the alternative does not apply, `Err` with the reason where it
/// cannot be made (a mirror that reflects nothing has no distant shell): the object is then
/// stored as textures and the pack goes on.
fn alternative_model(
    job: &mut Job<'_>,
    alt: &dyn super::represent::Representation,
    o: usize,
    mi: usize,
    n: usize,
) -> std::result::Result<Option<ObjectModel>, String> {
    let made = (|| -> Result<Option<ObjectModel>> {
        let Some(s) = alt.survey(job, o)? else { return Ok(None) };
        let p = s.plan(job, job.plan.stagger(mi, n))?;
        Ok(Some(solved(job, p)?))
    })();
    made.map_err(|e| {
        let e = format!("{e:#}");
        job.note(&format!("object {}: as {}: {e}", job.set.scene.objects[o].name, alt.name()));
        e
    })
}

/// [`super::screen`]: the alternatives worth weighing, solved for the objects whose textures
/// solved far below the other objects; each object with an alternative is told why in `why`.
fn screen(
    job: &mut Job<'_>,
    models: &mut [ObjectModel],
    objects: &[usize],
) -> Result<Vec<(usize, ObjectModel)>> {
    let set = job.set;
    let n = models.len();
    let with_alternative: Vec<(usize, &'static dyn super::represent::Representation)> = (0..n)
        .filter_map(|mi| alternative_of(set, job.req, objects[mi]).map(|alt| (mi, alt)))
        .collect();
    if with_alternative.is_empty() {
        return Ok(Vec::new());
    }
    let errors: Vec<(f64, usize)> =
        models.iter().map(|m| solved_error(set, m)).collect::<Result<_>>()?;
    let (sse, count) = errors.iter().fold((0.0, 0), |t, e| (t.0 + e.0, t.1 + e.1));
    let mut kept = Vec::new();
    for (mi, alt) in with_alternative {
        let (e, c) = errors[mi];
        let object_db = psnr(e, c);
        let others_db = (count > c).then(|| psnr(sse - e, count - c));
        let mut auto = AutoChoice {
            alternative: alt.name().to_string(),
            textures_solved_db: object_db,
            others_solved_db: others_db,
            alternative_solved_db: None,
            weighed: false,
            kept: false,
        };
        let why = match screen::solve_alternative(object_db, others_db) {
            Err(why) => format!("auto: surface textures: {why}"),
            Ok(why) => match weighed_alternative(job, alt, objects[mi], mi, n, &mut auto)? {
                Ok((mut m, weighed)) => {
                    m.why = format!("{}; {why}; {weighed}", m.why);
                    m.auto = Some(auto.clone());
                    kept.push((mi, m));
                    format!("{why}; {weighed}")
                }
                Err(not) => format!("auto: surface textures: {why}; {not}"),
            },
        };
        let m = &mut models[mi];
        m.why = format!("{}; {why}", m.why);
        m.auto = Some(auto);
    }
    Ok(kept)
}

/// Object `o`'s alternative `alt`, made and solved, with why it is weighed (`Ok`), or why not
/// (`Err`: it does not apply, cannot be made, or solves more than
/// [`screen::KEEP_BELOW_DB`] below the textures); `auto` records its figure and the outcome.
fn weighed_alternative(
    job: &mut Job<'_>,
    alt: &dyn super::represent::Representation,
    o: usize,
    mi: usize,
    n: usize,
    auto: &mut AutoChoice,
) -> Result<std::result::Result<(ObjectModel, String), String>> {
    let name = alt.name();
    let m = match alternative_model(job, alt, o, mi, n) {
        Ok(Some(m)) => m,
        Ok(None) => return Ok(Err(format!("{name} does not apply"))),
        Err(e) => return Ok(Err(format!("as {name} it could not be made: {e}"))),
    };
    let (e, c) = solved_error(job.set, &m)?;
    let alt_db = psnr(e, c);
    auto.alternative_solved_db = Some(alt_db);
    let weighed = screen::weigh_alternative(alt_db, auto.textures_solved_db, name);
    auto.weighed = weighed.is_ok();
    Ok(weighed.map(|w| (m, w)))
}
