//! A lens object's layered environment maps inferred at its view samples (thesis 6.3.3):
//! the layers and shells built from the outgoing rays of every view
//! ([`pis_compile::hybrid::choose_layers`]); per view, the frame's tessellation and, per
//! term and shell, the render matrix of hybrid rendering ([`hybrid_render_matrix`]); per
//! shell one RGBA cube map solved by least squares against both terms at once (eq. 6.1: the
//! two matrices stacked), its premultiplied colour and its alpha apart, the targets being the
//! tracer's outgoing-ray records of each pixel recombined per layer (alpha: the fraction of
//! the pixel's rays that meet the layer, colour: what they meet there, premultiplied); the
//! prediction composites each term's shells "over", nearest first, multiplies by the F·G the
//! player interpolates per vertex, and is compared with the traced term layers
//! (`reflection`, `refraction`, and for a set traced with the ray tree `refraction_1` and
//! `refraction_2`) over the lens object's pixels. The terms drawn are the set's lens
//! model's (`renderer.settings.lens_model`, [`LensInferSettings::tessellation`]); the
//! shells are built and solved from the greedy terms' records and rows alone (eq. 6.1's
//! two), and the ray tree's further terms look the same shells up: with their rows in the
//! solve, the glass teapot's shells split into one layer instead of three, chose 256² faces
//! for 64², and its refraction-first term fell 1–5 dB at the samples (the further terms'
//! exit rays, interpolated per vertex, land where their pixels' paths do not).
//!
//! A depth shell ([`LensInferSettings::depth`], SPEC.md 8.5) may stand for the layers: one
//! layer holding every object, each exit ray marched to the surface it meets, its map solved
//! per sample or over the views of every sample of a class at once
//! ([`LensInferSettings::classes`]).
//!
//! The cube-face size is chosen from the finest level the sample views read (5.8.2).
//! Simultaneous inference over nearby viewpoints ([`infer_lens_nearby`], 6.3.3.1) and the
//! confidence weights are options, off by default (measured worse on the glass sample); the
//! direct images of the environment of 6.3.3.1 are not used.

use anyhow::{anyhow, Result};
use glam::Vec3;
use pis_compile::hybrid::{
    choose_layers, hybrid_pixels, hybrid_render_matrix, term_radiance, tessellate,
    vertex_modulation, vertex_vectors, FittedShell, HybridPixels, HybridView, Layers, LensModel,
    Missing, OutgoingRay, Term, Tessellation, TessellationSettings, TERMS,
};
use pis_compile::shell::Shell;
use pis_compile::solve::View;

use crate::solutions::Solver;
use pis_compile::{RenderMatrix, SolveSettings, TextureLayout, Viewport};
use pis_scene::{Frame, Scene};
use pis_trace::camera::{projection_matrix, PerspectiveCamera};
use pis_trace::layers::{LayerKind, TermPart};
use pis_trace::{PointImages, PointRender, RayRecord};

use pis_codec::display::psnr_display;

use super::super::rows::select_rows;
use super::lens::lens_object;

/// The largest cube face the views' lookups choose (thesis 5.8.2).
pub const MAX_FACE: u32 = 256;

/// What the inference is given and how it runs.
#[derive(Clone, Debug)]
pub struct LensInferSettings {
    /// Cube-face size of every shell; `None`: the size at which the sample views' lookups
    /// read the finest level about one texel per pixel (thesis 5.8.2).
    pub face: Option<u32>,
    /// The largest face the chosen size may be: [`MAX_FACE`], or a byte budget's cap.
    pub max_face: u32,
    pub tessellation: TessellationSettings,
    pub max_layers: usize,
    pub solve: SolveSettings,
    /// Weigh each pixel's rows by the traced confidence of its exit directions (thesis 6.3.3;
    /// off by default: measured worse on the glass sample, docs/benchmarks/hybrid.md).
    pub confidence: bool,
    /// Where the cube maps' solves go (a sharded pack's store of solutions, [`Solver`]).
    pub solver: Solver,
    /// Lookups per pixel side (SPEC.md 8.2): each pixel's row is the mean of k × k lookups
    /// over its footprint ([`hybrid_render_matrix`]).
    pub lookups: u32,
    /// One depth shell (SPEC.md 8.5) as the object's one layer, every environment object
    /// in it, instead of the layers clustered from the hit distances ([`one_layer`]).
    pub depth: Option<Shell>,
    /// Per sample, its class: the samples of a class share one map per shell, solved over
    /// all their views at once (`None`: one map per sample). A depth shell's samples that
    /// differ only in the view form a class.
    pub classes: Option<Vec<usize>>,
}

impl Default for LensInferSettings {
    fn default() -> Self {
        LensInferSettings {
            face: None,
            max_face: MAX_FACE,
            tessellation: TessellationSettings::default(),
            max_layers: 4,
            solve: SolveSettings::pyramidal(),
            confidence: false,
            solver: Solver::default(),
            lookups: 1,
            depth: None,
            classes: None,
        }
    }
}

/// One term's prediction at one view, over the lens object's pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TermFit {
    pub psnr_db: f64,
    pub pixels: usize,
}

/// The inference's result at one view.
#[derive(Clone, Debug)]
pub struct LensView {
    pub reflection: TermFit,
    pub refraction: TermFit,
    /// Every term of the lens model summed, against the traced terms summed.
    pub both: TermFit,
    /// The greedy model's two terms summed, against the traced terms summed (`both` for
    /// the greedy model).
    pub greedy: TermFit,
    /// Per shell, its RGBA cube map (texels × 4, premultiplied colour then alpha).
    pub cubes: Vec<Vec<f32>>,
}

#[derive(Clone, Debug)]
pub struct LensInference {
    /// The shells' cube-face size.
    pub face: u32,
    pub layers: Layers,
    pub shells: Vec<FittedShell>,
    pub views: Vec<LensView>,
    /// Per view sample, its own view as the model draws it.
    pub models: Vec<LensViewModel>,
    /// For a set traced with the ray tree, what its further terms added at the samples (mean
    /// PSNR of every term against the greedy two): the tree is drawn where at least
    /// [`MIN_TREE_GAIN_DB`], else the greedy model.
    pub tree_gain_db: Option<f64>,
}

/// One traced view of a lens object: its frame, the traced images and the outgoing-ray
/// records.
#[derive(Clone, Copy)]
pub struct TracedView<'a> {
    pub frame: &'a Frame,
    pub images: &'a PointImages,
    pub records: &'a [RayRecord],
}

impl<'a> From<&'a (Frame, PointRender)> for TracedView<'a> {
    fn from(v: &'a (Frame, PointRender)) -> Self {
        TracedView { frame: &v.0, images: &v.1.images, records: &v.1.records }
    }
}

/// Object `o`'s outgoing rays in `render`'s records of the greedy terms (the shells are
/// built from them: [`infer_lens_views`]).
fn outgoing_rays(render: &TracedView, o: usize) -> Vec<OutgoingRay> {
    render
        .records
        .iter()
        .filter(|r| r.object == o as u32 && (r.term as usize) < TERMS.len())
        .map(|r| OutgoingRay {
            origin: Vec3::from(r.exit_origin).as_dvec3(),
            direction: Vec3::from(r.exit_direction).as_dvec3(),
            hits: r.hits.iter().map(|h| (h.t as f64, h.object)).collect(),
        })
        .collect()
}

/// Per pixel, for `term`'s records splatted with the display filter (a Gaussian of σ 0.5
/// pixel, radius 1.5, as the tracer's film): their weight, and per layer the weight of
/// those meeting it and of the colour they meet there (each record's frontmost hit in the
/// layer). A record's first hit takes the radiance the traced term holds along the pixel's
/// outgoing rays (the term over its F·G, the tracer's many-sample estimate) where that is
/// defined; hidden hits keep the record's own one-sample colour.
fn layer_targets(
    render: &TracedView,
    o: usize,
    term: Term,
    layers: &Layers,
    size: (u32, u32),
    radiance: &[Option<Vec3>],
) -> (Vec<f32>, Vec<Vec<(f32, Vec3)>>) {
    const SIGMA: f32 = 0.5;
    const RADIUS: f32 = 1.5;
    let n = (size.0 * size.1) as usize;
    let mut weight = vec![0.0f32; n];
    let mut per = vec![vec![(0.0f32, Vec3::ZERO); n]; layers.distances.len()];
    for r in render.records.iter().filter(|r| r.object == o as u32 && r.term == term as u8) {
        let (x, y) = (r.pixel[0], r.pixel[1]);
        let own = (
            x.floor().clamp(0.0, size.0 as f32 - 1.0) as usize,
            y.floor().clamp(0.0, size.1 as f32 - 1.0) as usize,
        );
        let first = radiance[own.1 * size.0 as usize + own.0];
        let mut colours: Vec<Option<Vec3>> = vec![None; layers.distances.len()];
        for (k, h) in r.hits.iter().enumerate() {
            if let Some(&l) = layers.layer_of.get(&h.object) {
                if colours[l].is_none() {
                    colours[l] = Some(if k == 0 {
                        first.unwrap_or(Vec3::from(h.colour))
                    } else {
                        Vec3::from(h.colour)
                    });
                }
            }
        }
        let (x0, x1) = (
            (x - RADIUS - 0.5).ceil().max(0.0) as i64,
            ((x + RADIUS - 0.5).floor() as i64).min(size.0 as i64 - 1),
        );
        let (y0, y1) = (
            (y - RADIUS - 0.5).ceil().max(0.0) as i64,
            ((y + RADIUS - 0.5).floor() as i64).min(size.1 as i64 - 1),
        );
        for py in y0..=y1 {
            for px in x0..=x1 {
                let (dx, dy) = (px as f32 + 0.5 - x, py as f32 + 0.5 - y);
                let d2 = dx * dx + dy * dy;
                if d2 > RADIUS * RADIUS {
                    continue;
                }
                let w = (-d2 / (2.0 * SIGMA * SIGMA)).exp();
                let p = py as usize * size.0 as usize + px as usize;
                weight[p] += w;
                for (l, c) in colours.iter().enumerate() {
                    if let Some(c) = c {
                        per[l][p].0 += w;
                        per[l][p].1 += *c * w;
                    }
                }
            }
        }
    }
    (weight, per)
}

/// A traced image's RGB at every pixel (zeros where the layer is missing).
fn traced_rgb(
    scene: &Scene,
    images: &PointImages,
    o: usize,
    kind: LayerKind,
    n: usize,
) -> Vec<f32> {
    let mut out = vec![0.0f32; n * 3];
    if let Some(l) = images.object_layer(&scene.objects[o].name, kind) {
        for (c, name) in ["R", "G", "B"].iter().enumerate() {
            if let Some(p) = l.channel(name) {
                (0..n).for_each(|k| out[k * 3 + c] = p[k]);
            }
        }
    }
    out
}

/// A view as the model draws it: the frame's tessellation of the lens object (its vertex
/// rays) and, once the face size is known, per term of the lens model and shell the render
/// matrix.
#[derive(Clone, Debug)]
pub struct LensViewModel {
    pub viewport: Viewport,
    pub clip: glam::Mat4,
    pub tess: Tessellation,
    /// The lens model whose terms the vertices carry.
    pub model: LensModel,
    /// Per term, per shell.
    pub a: Vec<Vec<RenderMatrix>>,
}

type ViewModel = LensViewModel;

impl LensViewModel {
    /// The tessellation of `frame` at `size`, no matrices yet.
    fn new(
        scene: &Scene,
        o: usize,
        frame: &Frame,
        size: (u32, u32),
        settings: &LensInferSettings,
    ) -> ViewModel {
        let lens = lens_object(scene, frame, o);
        let camera = PerspectiveCamera::new(&frame.camera, size);
        let clip =
            projection_matrix(&frame.camera, size) * frame.camera.world_from_camera.inverse();
        let tess = tessellate(
            &lens,
            &HybridView { eye: camera.origin, clip_from_world: clip, size },
            &settings.tessellation,
        );
        ViewModel {
            viewport: Viewport { width: size.0, height: size.1 },
            clip,
            tess,
            model: settings.tessellation.model,
            a: Vec::new(),
        }
    }

    /// Per term and shell, the render matrix of cube faces of `face` texels.
    fn with_matrices(mut self, shells: &[FittedShell], face: u32, lookups: u32) -> ViewModel {
        let layout = TextureLayout::cube(face);
        self.a = Term::of(self.model)
            .iter()
            .map(|&term| {
                shells
                    .iter()
                    .map(|s| {
                        hybrid_render_matrix(
                            self.viewport,
                            &self.tess,
                            self.clip,
                            &vertex_vectors(&self.tess, term, &s.shell),
                            layout,
                            lookups,
                            None,
                        )
                    })
                    .collect()
            })
            .collect();
        self
    }
}

/// Infers lens object `o`'s shells at every view of `views` (each its frame and the render
/// traced there, with records).
pub fn infer_lens(
    scene: &Scene,
    o: usize,
    views: &[(Frame, PointRender)],
    settings: &LensInferSettings,
) -> Result<LensInference> {
    let samples: Vec<Vec<TracedView>> = views.iter().map(|v| vec![TracedView::from(v)]).collect();
    infer_lens_views(scene, o, &samples, settings)
}

/// [`infer_lens`] with each view sample's shells solved simultaneously over several views
/// near it (thesis 6.3.3.1: "a single EM layer inferred as a least-squares simultaneous match
/// at all viewpoints"), so that parts of the environment the sample's own view does not see
/// are filled from the others; the first view of each sample is the sample's, where the
/// prediction is made. The layers are built from the outgoing rays of every view.
pub fn infer_lens_nearby(
    scene: &Scene,
    o: usize,
    samples: &[Vec<&(Frame, PointRender)>],
    settings: &LensInferSettings,
) -> Result<LensInference> {
    let samples: Vec<Vec<TracedView>> =
        samples.iter().map(|s| s.iter().map(|&v| TracedView::from(v)).collect()).collect();
    infer_lens_views(scene, o, &samples, settings)
}

/// [`infer_lens_nearby`] over traced views held anywhere (a set's images and records).
pub fn infer_lens_views(
    scene: &Scene,
    o: usize,
    samples: &[Vec<TracedView>],
    settings: &LensInferSettings,
) -> Result<LensInference> {
    if o >= scene.objects.len() {
        return Err(anyhow!("object {o}: the scene has {} objects", scene.objects.len()));
    }
    let first = samples.first().and_then(|s| s.first()).ok_or_else(|| anyhow!("no views"))?;
    let (w, h) = (first.images.width, first.images.height);
    if samples.iter().flatten().any(|r| (r.images.width, r.images.height) != (w, h)) {
        return Err(anyhow!("the views are traced at different sizes"));
    }
    let lens0 = lens_object(scene, first.frame, o);
    let origin = lens0.centroid().as_dvec3();
    let scale =
        lens0.positions.iter().map(|p| (p.as_dvec3() - origin).length()).fold(0.0, f64::max);
    let rays: Vec<OutgoingRay> =
        samples.iter().flatten().flat_map(|r| outgoing_rays(r, o)).collect();
    if rays.is_empty() {
        return Err(anyhow!(
            "{}: the traced views hold no outgoing-ray records of the lens object",
            scene.objects[o].name
        ));
    }
    let (layers, shells) = match &settings.depth {
        Some(shell) => one_layer(&rays, shell),
        None => choose_layers(&rays, origin, settings.max_layers, scale),
    };
    // Every view's tessellation, once: it serves the face size, the rows and the prediction.
    let mut models: Vec<Vec<ViewModel>> = samples
        .iter()
        .map(|s| s.iter().map(|v| ViewModel::new(scene, o, v.frame, (w, h), settings)).collect())
        .collect();
    let face = match settings.face {
        Some(f) => f,
        None => face_size(&models.iter().map(|m| &m[0]).collect::<Vec<_>>(), &shells)
            .min(settings.max_face.max(8)),
    };
    models = models
        .into_iter()
        .map(|m| m.into_iter().map(|v| v.with_matrices(&shells, face, settings.lookups)).collect())
        .collect();
    let layout = TextureLayout::cube(face);
    let rows = |sample: &[TracedView], models: &[ViewModel], sub_all: &mut Vec<Vec<ShellRow>>| {
        for (render, model) in sample.iter().zip(models) {
            for (l, sub) in
                view_rows(scene, o, model, render, &layers, settings).into_iter().enumerate()
            {
                sub_all[l].extend(sub);
            }
        }
    };
    // A class's map: every view of its samples in one solve.
    let mut shared: std::collections::BTreeMap<usize, Vec<Vec<f32>>> = Default::default();
    if let Some(classes) = &settings.classes {
        if classes.len() != samples.len() {
            return Err(anyhow!("{} sample classes for {} samples", classes.len(), samples.len()));
        }
        // Class by class, so that one class's rows are held at a time.
        let distinct: std::collections::BTreeSet<usize> = classes.iter().copied().collect();
        for c in distinct {
            let mut sub_all: Vec<Vec<ShellRow>> = vec![Vec::new(); shells.len()];
            for ((sample, models), _) in
                samples.iter().zip(&models).zip(classes).filter(|(_, &k)| k == c)
            {
                rows(sample, models, &mut sub_all);
            }
            shared.insert(c, solve_cubes(&sub_all, layout, settings)?);
        }
    }
    let mut out = Vec::with_capacity(samples.len());
    for (k, (sample, models)) in samples.iter().zip(&models).enumerate() {
        let class = settings.classes.as_ref().map(|c| c[k]);
        let cubes = match class.and_then(|c| shared.get(&c)) {
            Some(cubes) => cubes.clone(),
            None => {
                let mut sub_all: Vec<Vec<ShellRow>> = vec![Vec::new(); shells.len()];
                rows(sample, models, &mut sub_all);
                solve_cubes(&sub_all, layout, settings)?
            }
        };
        let (reflection, refraction, both, greedy) =
            predict_with(scene, o, &models[0], sample[0].images, face, &[(&cubes, 1.0)]);
        out.push(LensView { reflection, refraction, both, greedy, cubes });
    }
    let models =
        models.into_iter().map(|m| m.into_iter().next().expect("a sample's own view")).collect();
    let mut inference =
        LensInference { face, layers, shells, views: out, models, tree_gain_db: None };
    if !settings.tessellation.model.is_greedy() {
        // The tree's further terms are drawn where they bring the samples nearer the traced
        // image than the greedy two do; else the greedy model, its vertices traced and its
        // triangles split for two terms.
        let mean = |f: fn(&LensView) -> f64| {
            inference.views.iter().map(f).sum::<f64>() / inference.views.len().max(1) as f64
        };
        let gain = mean(|v| v.both.psnr_db) - mean(|v| v.greedy.psnr_db);
        if gain.is_nan() || gain < MIN_TREE_GAIN_DB {
            let mut greedy = settings.clone();
            greedy.tessellation.model = LensModel::Greedy;
            inference = infer_lens_views(scene, o, samples, &greedy)?;
        }
        inference.tree_gain_db = Some(gain);
    }
    Ok(inference)
}

/// Per shell, its RGBA cube map: colour and alpha solved over both terms' rows `sub_all` of
/// every view.
fn solve_cubes(
    sub_all: &[Vec<ShellRow>],
    layout: TextureLayout,
    settings: &LensInferSettings,
) -> Result<Vec<Vec<f32>>> {
    let mut cubes = Vec::with_capacity(sub_all.len());
    for sub in sub_all {
        let colour = settings.solver.solve_view_independent(
            &sub.iter().map(|(m, rgb, _)| View { a: m, b: rgb }).collect::<Vec<_>>(),
            None,
            &settings.solve,
        )?;
        let alpha = settings.solver.solve_view_independent(
            &sub.iter().map(|(m, _, al)| View { a: m, b: al }).collect::<Vec<_>>(),
            None,
            &settings.solve,
        )?;
        let texels = layout.texel_count();
        let mut cube = vec![0.0f32; texels * 4];
        for k in 0..texels {
            cube[k * 4..k * 4 + 3].copy_from_slice(&colour.texels[k * 3..k * 3 + 3]);
            cube[k * 4 + 3] = alpha.texels[k * 3].clamp(0.0, 1.0);
        }
        cubes.push(cube);
    }
    Ok(cubes)
}

/// `shell` as the one layer of every object the rays meet, at their first hits' mean
/// distance from its origin: each exit ray's first hit is what the depth shell's march
/// finds, so no object stands behind another in a layer of its own. Its fit to the hits is
/// not measured (`mse` NaN).
fn one_layer(rays: &[OutgoingRay], shell: &Shell) -> (Layers, Vec<FittedShell>) {
    let first: Vec<f64> = rays
        .iter()
        .filter_map(|r| {
            r.hits.first().map(|h| (r.origin + r.direction * h.0 - shell.origin).length())
        })
        .collect();
    let layers = Layers {
        distances: vec![first.iter().sum::<f64>() / first.len().max(1) as f64],
        layer_of: rays.iter().flat_map(|r| r.hits.iter().map(|h| (h.1, 0))).collect(),
        counted: rays.iter().map(|r| r.hits.len()).sum(),
    };
    (layers, vec![FittedShell { shell: shell.clone(), mse: f64::NAN }])
}

/// The least the ray tree's further terms must add at the samples (mean PSNR of every term
/// against the greedy two, both against the traced terms) to be drawn: each costs a draw
/// and its vertex paths per frame.
pub const MIN_TREE_GAIN_DB: f64 = 0.1;

/// A term's rows of one shell: the render matrix's rows of the pixels the records reach,
/// with their colour and alpha targets.
type ShellRow = (RenderMatrix, Vec<f32>, Vec<f32>);

/// One view's rows for each shell: per greedy term, the render matrix's rows of the pixels
/// the records reach, with their colour and alpha targets.
fn view_rows(
    scene: &Scene,
    o: usize,
    model: &ViewModel,
    render: &TracedView,
    layers: &Layers,
    settings: &LensInferSettings,
) -> Vec<Vec<ShellRow>> {
    let (w, h) = (render.images.width, render.images.height);
    let n = (w * h) as usize;
    // Per term, the records' targets.
    let mut targets = Vec::new();
    for term in TERMS {
        let [kind, modulation, _] = term_layers(term);
        let (value, fg) = (
            traced_rgb(scene, render.images, o, kind, n),
            traced_rgb(scene, render.images, o, modulation, n),
        );
        let radiance: Vec<Option<Vec3>> = (0..n)
            .map(|p| {
                let f = Vec3::from_slice(&fg[p * 3..p * 3 + 3]);
                (f.min_element() > 1e-3).then(|| Vec3::from_slice(&value[p * 3..p * 3 + 3]) / f)
            })
            .collect();
        targets.push(layer_targets(render, o, term, layers, (w, h), &radiance));
    }
    // Confidence (thesis 6.3.3): 1 − min(θm², θc²)/θc² from the spread of each pixel's exit
    // directions, multiplied into both sides of each row.
    let confidence: Vec<Vec<f32>> = TERMS
        .iter()
        .map(|&term| {
            let plane = render
                .images
                .object_layer(&scene.objects[o].name, term_layers(term)[2])
                .and_then(|l| l.channel("Y"))
                .map(|c| c.to_vec());
            plane.filter(|_| settings.confidence).unwrap_or_else(|| vec![1.0; n])
        })
        .collect();
    (0..layers.distances.len())
        .map(|l| {
            (0..TERMS.len())
                .map(|t| {
                    let (weight, per) = &targets[t];
                    let c = &confidence[t];
                    let mut m = select_rows(&model.a[t][l], |p| {
                        weight[p as usize] > 0.0 && c[p as usize] > 0.0
                    });
                    for r in 0..m.rows() {
                        let k = c[m.pixels[r] as usize];
                        let (lo, hi) = (m.row_start[r] as usize, m.row_start[r + 1] as usize);
                        m.vals[lo..hi].iter_mut().for_each(|v| *v *= k);
                    }
                    let rgb: Vec<f32> = m
                        .pixels
                        .iter()
                        .flat_map(|&p| {
                            (per[l][p as usize].1 / weight[p as usize] * c[p as usize]).to_array()
                        })
                        .collect();
                    let alpha: Vec<f32> = m
                        .pixels
                        .iter()
                        .flat_map(|&p| {
                            [per[l][p as usize].0 / weight[p as usize] * c[p as usize], 0.0, 0.0]
                        })
                        .collect();
                    (m, rgb, alpha)
                })
                .collect()
        })
        .collect()
}

/// The cube-face size (a power of two, 8 to [`MAX_FACE`]) at which the views' lookups of every shell
/// and term read level 0 at about one texel per pixel: 2^(−λ₁), λ₁ the 10th percentile of
/// the lookups' LOD on a one-texel face (thesis 5.8.2: "the most detailed MIPMAP level
/// actually accessed").
fn face_size(views: &[&ViewModel], shells: &[FittedShell]) -> u32 {
    const BIG: f64 = 1048576.0;
    let mut lods = Vec::new();
    for v in views {
        for term in TERMS {
            for s in shells {
                let px = hybrid_pixels(
                    v.viewport,
                    &v.tess,
                    v.clip,
                    &vertex_vectors(&v.tess, term, &s.shell),
                    Missing::Mean,
                    None,
                );
                lods.extend(px.vectors.iter().map(|&[d, dx, dy]| {
                    pis_compile::shell::cube::cube_lod(d, dx, dy, BIG, 64.0) - BIG.log2()
                }));
            }
        }
    }
    if lods.is_empty() {
        return 32;
    }
    lods.sort_by(f64::total_cmp);
    let p10 = lods[lods.len() / 10];
    2f64.powf((-p10).round().clamp(3.0, MAX_FACE.ilog2() as f64)) as u32
}

/// The lens object's terms drawn at `frame` by hybrid rendering (the frame's own
/// tessellation and vertex rays) from `inference`'s cube maps at view samples `samples`
/// (sample index and blending weight), against `render` traced at that frame: the
/// reflection-first and refraction-first terms, and every term of `settings`' lens model
/// summed, over the pixels the traced object covers.
pub fn predict_view(
    scene: &Scene,
    o: usize,
    frame: &Frame,
    render: &PointRender,
    inference: &LensInference,
    samples: &[(usize, f32)],
    settings: &LensInferSettings,
) -> (TermFit, TermFit, TermFit) {
    let cubes: Vec<(&Vec<Vec<f32>>, f32)> = samples
        .iter()
        .filter_map(|&(k, w)| inference.views.get(k).map(|v| (&v.cubes, w)))
        .collect();
    let model =
        ViewModel::new(scene, o, frame, (render.images.width, render.images.height), settings)
            .with_matrices(&inference.shells, inference.face, settings.lookups);
    let (reflection, refraction, both, _) =
        predict_with(scene, o, &model, &render.images, inference.face, &cubes);
    (reflection, refraction, both)
}

/// The lens object's terms as the player draws them at a view of `model` from the
/// per-shell RGBA cube maps `cubes` (each shell's cube already blended over the view
/// samples): per term, [`term_radiance`] at the pixels that draw it. Returns per term of the
/// lens model the RGB image (`width · height · 3`, zero where the term is not drawn).
pub fn lens_image(model: &LensViewModel, cubes: &[&[f32]]) -> Vec<Vec<f32>> {
    lens_terms(model, &term_pixels(model), cubes)
}

/// Per term, the pixels of `model` that draw it with their interpolated F·G
/// ([`hybrid_pixels`] of the modulation, [`Missing::Zero`]).
pub fn term_pixels(model: &LensViewModel) -> Vec<HybridPixels> {
    Term::of(model.model)
        .iter()
        .map(|&term| {
            hybrid_pixels(
                model.viewport,
                &model.tess,
                model.clip,
                &vertex_modulation(&model.tess, term),
                Missing::Zero,
                None,
            )
        })
        .collect()
}

/// [`lens_image`] with each term's pixels and F·G ([`term_pixels`]) made.
pub fn lens_terms(model: &LensViewModel, fg: &[HybridPixels], cubes: &[&[f32]]) -> Vec<Vec<f32>> {
    let n = (model.viewport.width * model.viewport.height) as usize;
    let mut out = vec![vec![0.0f32; n * 3]; fg.len()];
    for (t, fg) in fg.iter().enumerate() {
        let a: Vec<&RenderMatrix> = model.a[t].iter().collect();
        for (&p, c) in fg.pixels.iter().zip(term_radiance(fg, &a, cubes)) {
            out[t][p as usize * 3..p as usize * 3 + 3].copy_from_slice(&c);
        }
    }
    out
}

/// [`predict_view`] with the view's model made.
fn predict_with(
    scene: &Scene,
    o: usize,
    model: &ViewModel,
    images: &PointImages,
    face: u32,
    samples: &[(&Vec<Vec<f32>>, f32)],
) -> (TermFit, TermFit, TermFit, TermFit) {
    let (w, h) = (images.width, images.height);
    let n = (w * h) as usize;
    let layout = TextureLayout::cube(face);
    let cubes: Vec<Vec<f32>> = (0..model.a.first().map_or(0, Vec::len))
        .map(|l| {
            let mut c = vec![0.0f32; layout.texel_count() * 4];
            for (s, weight) in samples {
                c.iter_mut().zip(&s[l]).for_each(|(x, v)| *x += weight * v);
            }
            c
        })
        .collect();
    let cover = images
        .object_layer(&scene.objects[o].name, LayerKind::Coverage)
        .and_then(|l| l.channel("A"))
        .map(|c| c.to_vec())
        .unwrap_or_else(|| vec![0.0; n]);
    let predicted = lens_image(model, &cubes.iter().map(Vec::as_slice).collect::<Vec<_>>());
    let traced: Vec<Vec<f32>> = Term::of(model.model)
        .iter()
        .map(|&t| traced_rgb(scene, images, o, term_layers(t)[0], n))
        .collect();
    let fit = |pred: &[f32], truth: &[f32]| {
        let pixels: Vec<usize> = (0..n).filter(|&p| cover[p] > 0.5).collect();
        let gather = |v: &[f32]| {
            pixels
                .iter()
                .flat_map(|&p| [v[p * 3], v[p * 3 + 1], v[p * 3 + 2]])
                .collect::<Vec<f32>>()
        };
        TermFit { psnr_db: psnr_display(&gather(pred), &gather(truth)), pixels: pixels.len() }
    };
    let sum = |terms: &[Vec<f32>]| {
        let mut all = vec![0.0f32; n * 3];
        terms.iter().for_each(|t| all.iter_mut().zip(t).for_each(|(a, x)| *a += x));
        all
    };
    let all = sum(&traced);
    (
        fit(&predicted[0], &traced[0]),
        fit(&predicted[1], &traced[1]),
        fit(&sum(&predicted), &all),
        fit(&sum(&predicted[..TERMS.len()]), &all),
    )
}

/// The traced layers of `term`: its value, its F·G modulation and its confidence.
fn term_layers(term: Term) -> [LayerKind; 3] {
    [TermPart::Value, TermPart::Modulation, TermPart::Confidence]
        .map(|part| LayerKind::of_term(term as usize, part))
}
