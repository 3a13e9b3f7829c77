//! Hybrid rendering of lens objects (thesis ch. 6) as a representation: a refractive
//! object's layered environment map, inferred from the set's outgoing-ray records at every
//! parameter sample ([`lens_infer`]: the layers clustered from the records' hit
//! distances, one shell fitted per layer, each shell's RGBA cube map solved against both
//! greedy terms at once, eq. 6.1). The file stores each shell as an `env_shell` layer of the
//! refraction term, every MIP level inferred and stored (SPEC.md 7.1, 8.3); the player
//! traces the object's vertex rays each frame and looks up the same shells in both terms
//! (SPEC.md 9). A diffuse surface layer is added when the object has one
//! ([`super::surface`]). The prediction and the storage allocation draw the object as the
//! player does, through the per-point render matrices of hybrid rendering ([`LensPoint`]).

use anyhow::Result;
use glam::Vec3;
use pis_compile::hybrid::{HybridPixels, LensModel};
use pis_compile::shell::Shell;
use pis_compile::TextureLayout;
use pis_scene::ObjectRole;

pub mod lens;
pub mod lens_infer;

use super::input::LoadedSet;
use super::model::{key, InferredLayer, ObjectModel, ShellTerms};
use super::pem::form::ShellForm;
use super::represent::{Job, Planned, Representation, Surveyed};
use super::settings::LensShell;
use super::surface::survey_surface;
use lens_infer::{
    infer_lens_views, lens_terms, term_pixels, LensInferSettings, LensViewModel, TracedView,
};

/// Hybrid rendering: refractive objects whose set has outgoing-ray records of them.
pub struct HybridRendering;

impl Representation for HybridRendering {
    fn name(&self) -> &'static str {
        "hybrid rendering"
    }

    fn shells(&self) -> bool {
        true
    }

    fn applies(&self, role: ObjectRole) -> bool {
        role == ObjectRole::Refractive
    }

    /// The object's surface part (its diffuse layer, if any, and every point's rows and gold
    /// standard); an object whose set has no ray records of it is stored as surface textures.
    fn survey(&self, job: &mut Job<'_>, o: usize) -> Result<Option<Box<dyn Surveyed>>> {
        let set = job.set;
        let name = &set.scene.objects[o].name;
        if !set.records.iter().any(|r| r.iter().any(|r| r.object == o as u32)) {
            job.note(&format!("object {name}: the set has no outgoing-ray records of it (RAYSET.md 6); stored as surface textures"));
            return survey_surface(job, o, true);
        }
        if let Some(why) = unreproducible(job, o)? {
            if job.req.representation == super::RepresentationMode::Auto {
                return Err(anyhow::anyhow!("{why}"));
            }
            job.note(&format!(
                "object {name}: not drawn by hybrid rendering: {why}; stored as surface textures"
            ));
            return survey_surface(job, o, true);
        }
        let Some(surface) = survey_surface(job, o, false)? else { return Ok(None) };
        Ok(Some(Box::new(HybridSurveyed { o, surface })))
    }
}

struct HybridSurveyed {
    o: usize,
    surface: Box<dyn Surveyed>,
}

impl Surveyed for HybridSurveyed {
    fn plan(self: Box<Self>, job: &mut Job<'_>, stagger: Vec<u32>) -> Result<Box<dyn Planned>> {
        let HybridSurveyed { o, surface } = *self;
        Ok(Box::new(HybridPlanned { o, surface: surface.plan(job, stagger)? }))
    }
}

struct HybridPlanned {
    o: usize,
    surface: Box<dyn Planned>,
}

impl Planned for HybridPlanned {
    fn solve(self: Box<Self>, job: &Job<'_>) -> Result<ObjectModel> {
        let HybridPlanned { o, surface } = *self;
        let mut model = surface.solve(job)?;
        let set = job.set;
        let scene = &set.scene;
        // A lens object's views read every point's images at once (held in memory, also for a
        // pack that streams).
        let images =
            (0..set.frames.len()).map(|p| set.images.object(p, o)).collect::<Result<Vec<_>>>()?;
        let views: Vec<Vec<TracedView>> = (0..set.frames.len())
            .map(|p| {
                vec![TracedView {
                    frame: &set.frames[p],
                    images: &images[p],
                    records: &set.records[p],
                }]
            })
            .collect();
        let mut settings = LensInferSettings::default();
        settings.tessellation.model = set.trace.lens_model;
        settings.solve.cg = job.settings.cg;
        settings.solver = job.solver.clone();
        settings.lookups = job.req.shell_lookups;
        let cap = super::pem::budget::face_cap(job.plan, job.req.codec);
        if let Some(c) = cap {
            settings.max_face = c.face.min(settings.max_face);
        }
        // The single-shell baseline (thesis 6.5's comparison): one layer, one shell.
        let one = job.req.representation == super::RepresentationMode::PemInfinity;
        if one {
            settings.max_layers = 1;
        } else if job.req.lens_shell != LensShell::Layered {
            settings.depth = lens_depth_shell(set, &job.meshes, o);
            if settings.depth.is_some() && job.req.lens_shell == LensShell::Depth {
                settings.classes = Some(classes(&set.samples, job.non_view));
            }
        }
        // A map shared over the views depends on no view.
        let shared = settings.classes.is_some();
        let mask = if shared { job.non_view } else { job.all };
        let inference = infer_lens_views(scene, o, &views, &settings)?;
        let layout = TextureLayout::cube(inference.face);
        for (l, fitted) in inference.shells.iter().enumerate() {
            let textures: std::collections::BTreeMap<Vec<u32>, Vec<f32>> = set
                .samples
                .iter()
                .zip(&inference.views)
                .map(|(s, v)| (key(s, mask), v.cubes[l].clone()))
                .collect();
            let form = Box::new(ShellForm {
                shell: fitted.shell.clone(),
                layout,
                lookups: settings.lookups,
                channels: 4,
                order: l as u8,
                term: pis_format::Term::Refraction,
            });
            model.layers.push(InferredLayer::shell(
                pis_format::LayerKind::EnvShell,
                (&job.plan.space, mask),
                &model.stagger,
                textures,
                0,
                form,
                l,
            ));
        }
        let layers: Vec<String> = (0..inference.shells.len())
            .map(|l| {
                let names: Vec<&str> = inference
                    .layers
                    .layer_of
                    .iter()
                    .filter(|(_, &k)| k == l)
                    .filter_map(|(&obj, _)| {
                        scene.objects.get(obj as usize).map(|x| x.name.as_str())
                    })
                    .collect();
                format!("{} {{{}}}", inference.shells[l].shell.shape.name(), names.join(", "))
            })
            .collect();
        let both: Vec<f64> = inference.views.iter().map(|v| v.both.psnr_db).collect();
        let (lo, hi) =
            both.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |a, &x| (a.0.min(x), a.1.max(x)));
        let terms = lens_model_words(&inference);
        model.shells =
            Some(Box::new(LensPoints(inference.models.into_iter().map(LensPoint::new).collect())));
        model.representation =
            if one { "hybrid rendering, one shell" } else { "hybrid rendering" }.to_string();
        let shells = match (&settings.depth, shared) {
            (Some(_), true) => format!(
                "a depth shell about its centroid, one map over the views ({})",
                layers.join(", ")
            ),
            (Some(_), false) => format!(
                "a depth shell about its centroid, a map per sample ({})",
                layers.join(", ")
            ),
            (None, _) => format!(
                "{} shell(s) from the ray records' hit distances ({}){}",
                layers.len(),
                layers.join(", "),
                if one || job.req.lens_shell == LensShell::Layered {
                    ""
                } else {
                    "; no depth shell: no other object or recorded hit to cast it from"
                }
            ),
        };
        model.why = format!(
            "refractive: {shells}, cube faces {}², {}, {lo:.1}–{hi:.1} dB at the samples as solved; vertex rays traced per frame (τ {} px)",
            inference.face,
            terms,
            settings.tessellation.tau_px
        );
        if inference.face == settings.max_face {
            if let Some(note) = cap.and_then(|c| c.note(lens_infer::MAX_FACE)) {
                model.why.push_str(&note);
            }
        }
        Ok(model)
    }
}

/// Per sample, the index of its class: the samples equal on `mask`, numbered in order of
/// their first sample.
fn classes(samples: &[Vec<u32>], mask: pis_format::DepMask) -> Vec<usize> {
    let mut seen: Vec<Vec<u32>> = Vec::new();
    samples
        .iter()
        .map(|s| {
            let k = key(s, mask);
            seen.iter().position(|x| *x == k).unwrap_or_else(|| {
                seen.push(k);
                seen.len() - 1
            })
        })
        .collect()
}

/// Lens object `o`'s depth shell (`--lens-shell depth`): about the centroid of the object at
/// the set's first point (the layered shells' origin), its depth cube cast from the other
/// objects, the far sphere at most [`super::pem::fit::DEPTH_FAR_SPREAD`] times the mean
/// distance of the records' first hits from it. `None` without other objects or hits.
fn lens_depth_shell(set: &LoadedSet, meshes: &[super::mesh::Mesh], o: usize) -> Option<Shell> {
    let centre = lens::lens_object(&set.scene, set.frames.first()?, o).centroid();
    let (mut sum, mut n) = (0.0f64, 0usize);
    for r in set.records.iter().flatten().filter(|r| r.object == o as u32) {
        if let Some(h) = r.hits.first() {
            let hit = Vec3::from(r.exit_origin) + Vec3::from(r.exit_direction) * h.t;
            sum += hit.distance(centre) as f64;
            n += 1;
        }
    }
    let mean = (n > 0).then(|| (sum / n as f64) as f32)?;
    super::pem::fit::depth_shell(set, meshes, o, centre, mean)
}

/// Cube-face size of the probe solve ([`unreproducible`]).
const PROBE_FACE: u32 = 32;
/// How far (dB) the probe's shells may fall below the lens model's own ceiling.
const PROBE_BELOW_CEILING_DB: f64 = 15.0;

/// Why hybrid rendering cannot reproduce lens object `o`, if it cannot: its shells, solved at
/// the first point alone with faces of [`PROBE_FACE`] (a second's solve), fit the traced
/// lens terms more than [`PROBE_BELOW_CEILING_DB`] below the lens model's ceiling, the
/// set's own terms against the traced image (so the shells, not the model's dropped
/// branches, would bound it: the player's paths through the object do not carry the light
/// the tracer's did). Measured at CI size: a glass vase with flowers in it 6.7 against
/// 27.3 dB (refused; solved whole it reaches 6.6 dB in 98 s), the glass ball of
/// samples/wild/glass-shelf 24.8 against 35.3 dB and the glass teapot 23.5 against 21.0 dB
/// (both drawn: they solve to 18.6 and 20.6 dB).
fn unreproducible(job: &Job<'_>, o: usize) -> Result<Option<String>> {
    let set = job.set;
    let images = set.images.object(0, o)?;
    let views =
        [vec![TracedView { frame: &set.frames[0], images: &images, records: &set.records[0] }]];
    let ceiling = model_ceiling(&images, &set.channels[o]);
    let mut settings = LensInferSettings {
        face: Some(PROBE_FACE),
        max_face: PROBE_FACE,
        ..LensInferSettings::default()
    };
    settings.tessellation.model = set.trace.lens_model;
    settings.solve.cg = job.settings.cg;
    let inference = infer_lens_views(&set.scene, o, &views, &settings)?;
    let fit = inference.views.first().map_or(f64::INFINITY, |v| v.both.psnr_db);
    Ok(match ceiling {
        Some(c) if fit < c - PROBE_BELOW_CEILING_DB => Some(format!(
            "its shells fit the traced lens terms at {fit:.1} dB at the first point, more than {PROBE_BELOW_CEILING_DB} dB below its lens model's own ceiling ({c:.1} dB: the set's terms against the traced image)"
        )),
        _ => None,
    })
}

/// The lens model's ceiling at one point (dB, display values): the set's diffuse +
/// reflection + refraction layers against its diffuse + specular (the traced image), over
/// the pixels the object covers; `None` where a layer is missing or no pixel is covered.
fn model_ceiling(images: &pis_trace::PointImages, channel: &str) -> Option<f64> {
    use pis_trace::layers::LayerKind as L;
    let get = |k: L, c: &str| images.object_layer(channel, k).and_then(|l| l.channel(c));
    let coverage = get(L::Coverage, "A")?;
    let (mut model, mut traced) = (Vec::new(), Vec::new());
    for c in ["R", "G", "B"] {
        let [d, s, r, t] =
            [L::Diffuse, L::Specular, L::Reflection, L::Refraction].map(|k| get(k, c));
        let (d, s, r, t) = (d?, s?, r?, t?);
        for k in (0..coverage.len()).filter(|&k| coverage[k] > 0.0) {
            model.push(d[k] + r[k] + t[k]);
            traced.push(d[k] + s[k]);
        }
    }
    (!model.is_empty()).then(|| pis_codec::display::psnr_display(&model, &traced))
}

/// What the report says of the lens model drawn: which, how many terms, and why.
fn lens_model_words(inference: &lens_infer::LensInference) -> String {
    let model = inference.models.first().map_or(LensModel::Greedy, |m| m.model);
    let gain = inference.tree_gain_db;
    match (model, gain) {
        (LensModel::Tree { min_weight, .. }, Some(g)) => format!(
            "the ray tree's {} terms down to weight {min_weight}, {g:+.2} dB over its greedy two at the samples",
            model.terms()
        ),
        (_, Some(g)) => format!(
            "the greedy model's two terms: the set's ray tree drew its further terms at {g:+.2} dB at the samples"
        ),
        _ => "the greedy model's two terms (the set's lens model)".to_string(),
    }
}

/// The colour lens object `o` gives the light it transmits: its material's base colour,
/// clamped to [0, 1], which the file records (SPEC.md 6.6 `transmission_tint`) and the
/// player's paths multiply in as the tracer's do.
pub fn transmission_tint(set: &LoadedSet, o: usize) -> [f32; 3] {
    let base = set
        .frames
        .first()
        .map_or(glam::Vec3::ONE, |f| lens::lens_object(&set.scene, f, o).material.base);
    base.clamp(glam::Vec3::ZERO, glam::Vec3::ONE).to_array()
}

/// A lens object at one point of the set as hybrid rendering draws it: the point's
/// tessellation and render matrices, and per term the pixels that draw it with their F·G.
pub struct LensPoint {
    pub model: LensViewModel,
    pub fg: Vec<HybridPixels>,
}

impl LensPoint {
    pub fn new(model: LensViewModel) -> LensPoint {
        LensPoint { fg: term_pixels(&model), model }
    }

    /// The lens model's terms summed at `rows` (pixels, increasing), RGB per row, drawn
    /// from the shells' RGBA cube maps `maps` (each with its channel count, 4).
    pub fn render(&self, rows: &[u32], maps: &[(&[f32], usize)]) -> Vec<f32> {
        let cubes: Vec<&[f32]> = maps.iter().map(|(m, _)| *m).collect();
        let terms = lens_terms(&self.model, &self.fg, &cubes);
        rows.iter()
            .flat_map(|&p| {
                let k = p as usize * 3;
                [0, 1, 2].map(|c| terms.iter().map(|t| t[k + c]).sum::<f32>())
            })
            .collect()
    }
}

/// A lens object at every point of the set, its terms drawn from the same shells.
pub struct LensPoints(pub Vec<LensPoint>);

impl ShellTerms for LensPoints {
    fn render(&self, p: usize, rows: &[u32], maps: &[(&[f32], usize)]) -> Vec<f32> {
        self.0[p].render(rows, maps)
    }

    fn weights(&self, s: usize, texels: usize, points: &[usize]) -> Vec<f32> {
        shell_weights(&self.0, s, texels, points)
    }

    fn transmits(&self) -> bool {
        true
    }

    fn lens_model(&self) -> LensModel {
        self.0.first().map_or(LensModel::Greedy, |p| p.model.model)
    }
}

/// The screen weights of shell `s`'s sample at `points` (`texels` texels, every level
/// stored): each texel's column sums over every term's rows, each row weighed by its squared
/// F·G (the term reaches the screen multiplied by it); scaled as the reflection shells'
/// weights are.
fn shell_weights(lens: &[LensPoint], s: usize, texels: usize, points: &[usize]) -> Vec<f32> {
    let (mut weighed, mut plain) = (vec![0.0f64; texels], 0.0f64);
    for &p in points {
        let lp = &lens[p];
        for (t, fg) in lp.fg.iter().enumerate() {
            let a = &lp.model.a[t][s];
            let mut k = 0;
            for r in 0..a.rows() {
                while k < fg.pixels.len() && fg.pixels[k] < a.pixels[r] {
                    k += 1;
                }
                let f2 = fg
                    .vectors
                    .get(k)
                    .filter(|_| fg.pixels.get(k) == Some(&a.pixels[r]))
                    .map_or(0.0, |v| ((v[0].x + v[0].y + v[0].z) / 3.0).powi(2));
                let (cols, vals) = a.row(r);
                for (&c, &w) in cols.iter().zip(vals) {
                    if let Some(x) = weighed.get_mut(c as usize) {
                        *x += w as f64 * f2;
                    }
                    plain += w as f64;
                }
            }
        }
    }
    let scale = if plain > 0.0 { texels as f64 / plain } else { 0.0 };
    weighed.iter().map(|w| (w * scale) as f32).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use pis_trace::layers::{LayerImage, LayerKind as L};

    /// A 2 × 1 point of lens object `g`: diffuse 0.1, specular 0.5; its reflection and
    /// refraction terms summing to `terms` at each pixel; the second pixel uncovered.
    fn point(terms: [f32; 2]) -> pis_trace::PointImages {
        let layer = |kind: L, channels: &[&str], v: [f32; 2]| {
            let mut l = LayerImage::new(format!("object.g.{}", kind.name()), channels, 2, 1);
            l.planes.iter_mut().for_each(|p| p.copy_from_slice(&v));
            l
        };
        let rgb = ["R", "G", "B"];
        pis_trace::PointImages {
            width: 2,
            height: 1,
            layers: vec![
                layer(L::Coverage, &["A"], [1.0, 0.0]),
                layer(L::Diffuse, &rgb, [0.1, 0.1]),
                layer(L::Specular, &rgb, [0.5, 0.9]),
                layer(L::Reflection, &rgb, [0.1, 0.0]),
                layer(L::Refraction, &rgb, [terms[0] - 0.1, terms[1]]),
            ],
        }
    }

    #[test]
    fn samples_equal_off_the_view_share_a_class() {
        // Light × view, the view the second dimension: the class follows the light.
        let samples = [[0, 0], [0, 1], [1, 0], [1, 1], [0, 2]].map(|s| s.to_vec());
        assert_eq!(classes(&samples, pis_format::DepMask(0b01)), [0, 0, 1, 1, 0]);
        assert_eq!(classes(&samples, pis_format::DepMask(0)), [0; 5]);
    }

    #[test]
    fn the_model_ceiling_compares_the_set_terms_with_the_traced_image_where_covered() {
        // Exact where covered (the uncovered pixel's mismatch does not count).
        assert!(model_ceiling(&point([0.5, 0.0]), "g").unwrap() > 90.0);
        let off = model_ceiling(&point([0.4, 0.0]), "g").unwrap();
        assert!(off > 10.0 && off < 40.0, "{off}");
        assert_eq!(model_ceiling(&point([0.5, 0.0]), "other"), None, "no such object");
    }
}
