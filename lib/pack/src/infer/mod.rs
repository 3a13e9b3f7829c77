//! `pis-bench infer`: texture inference for one object at one parameter point, compared with
//! the gold-standard layer (thesis 3.6). Least squares with bilinear and trilinear render
//! matrices, under eq. 3.4's box constraint (`ls-trilinear-bounded`, `ls-pyramidal-bounded`),
//! with pyramidal regularization (free MIP levels, and level 0 solved through the
//! player's decimated chain: `ls-decimated`), and the two baselines (forward mapping, ray
//! tracing into textures), each rendered through the hardware model.
//!
//! The gold standard b is the object's surface radiance, diffuse + specular layer (both
//! divided by coverage), at the pixels the model rasterizes and the tracer covers. PSNR is
//! measured on display values (linear radiance clamped to [0, 1], sRGB-encoded, peak 1), as
//! the thesis compares 8-bit frames.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{anyhow, bail, Result};
use glam::Vec3;
use pis_compile::baseline::forward::forward_map;
use pis_compile::baseline::traced::trace_into_texture;
use pis_compile::baseline::LayerImage;
use pis_compile::solve::Solution;
use pis_compile::{
    antialiased_render_matrix, render, render_matrix, scene_depth, solve, DisplayFilter, DrawMesh,
    Filter, MipSolve, RenderMatrix, SolveSettings, TextureLayout, TextureTransform, TexturedObject,
    Viewport,
};
use pis_play::{render_object, Gpu, TexturedPipeline};
use pis_scene::{Frame, Scene};
use pis_trace::layers::LayerKind;

use serde::Serialize;

pub use pis_codec::display::psnr_display;

mod point;

use point::{load_point, object_layer, Point};

use crate::pipeline::mesh::{atlas, place_in};
pub use crate::pipeline::mesh::{merged_mesh, sampler, Mesh};
use crate::pipeline::rows::restrict;

/// What to infer.
#[derive(Clone, Debug, Default)]
pub struct InferRequest {
    /// A ray-traced set directory or a scene.toml.
    pub input: PathBuf,
    /// scene.toml for a set (default: the set directory's scene.toml).
    pub scene: Option<PathBuf>,
    pub object: Option<String>,
    /// One value per dimension; the nearest sample is used. Default: the middle sample.
    pub at: Option<Vec<f32>>,
    /// Tracing a scene.toml: image size and samples per pixel overrides.
    pub resolution: Option<(u32, u32)>,
    pub spp: Option<u32>,
    pub preset: Option<String>,
    /// Also time the inference (A matrix + pyramidal solve) of every object.
    pub all_objects: bool,
    /// Largest used texture side (the optimal resolution is clamped to it).
    pub max_texture: u32,
    /// The solver's settings for the plain least-squares solves; `ls-pyramidal` adds ε_f.
    pub solver: SolveSettings,
    /// ε_f of the pyramidal solve.
    pub epsilon_f: f64,
    /// ε_b of the pyramidal solve (the plain solves take `solver.epsilon_b`).
    pub pyramidal_epsilon_b: f64,
    /// Also render every texture through the player's wgpu pipeline (pis-play).
    pub wgpu: bool,
    /// Inference with antialiasing (thesis 3.4.4): A built at this factor × the resolution
    /// and filtered with the set's display filter, divided by coverage. 0 or 1: A at the
    /// display resolution, pixel centres only.
    pub antialias: u32,
    /// Also measure every texture at the neighbouring view sample (same light): the texture
    /// solved at this point, drawn there, against the gold standard there.
    pub neighbour: bool,
    /// The per-object resolution reduction factor of texture-coordinate optimization
    /// (thesis 3.2; 1: the optimal resolution).
    pub reduction: f64,
    /// Texel budget per covered pixel (see `pis-pack --texels-per-pixel`); None: none.
    pub texels_per_pixel: Option<f64>,
}

/// One method's result.
#[derive(Clone, Debug, Serialize)]
pub struct MethodReport {
    pub psnr_db: f64,
    /// Rendered through wgpu: null where this build has no wgpu renderer.
    pub psnr_db_wgpu: Option<f64>,
    pub ms: f64,
    pub iterations: Option<u32>,
    /// The smallest and largest texel value (all channels, all MIP levels).
    pub texel_range: [f32; 2],
    /// With `neighbour`: PSNR of this texture drawn at the neighbouring view sample
    /// (`InferReport::neighbour_point`) against the gold standard there (model).
    pub psnr_db_neighbour: Option<f64>,
    /// Least-squares methods: whether every channel's CG met its tolerance (not stopped at
    /// the iteration limit).
    pub converged: Option<bool>,
}

/// Inference time of one object.
#[derive(Clone, Debug, Serialize)]
pub struct ObjectTiming {
    pub object: String,
    pub n_s: usize,
    pub n_t: usize,
    pub texture: [u32; 2],
    pub texcoord_ms: f64,
    pub matrix_ms: f64,
    pub solve_ms: f64,
    pub iterations: u32,
    pub total_ms: f64,
}

/// The report (`--json` prints it).
#[derive(Clone, Debug, Serialize)]
pub struct InferReport {
    pub object: String,
    pub point: Vec<u32>,
    pub values: Vec<f32>,
    pub resolution: [u32; 2],
    pub texture: [u32; 2],
    pub repeat: [bool; 2],
    pub methods: BTreeMap<String, MethodReport>,
    /// The LS-trilinear solve.
    pub solve_ms: f64,
    pub iterations: u32,
    pub n_s: usize,
    pub n_t: usize,
    pub trace_ms: f64,
    pub texcoord_ms: f64,
    pub matrix_ms: f64,
    pub objects: Vec<ObjectTiming>,
    /// With `neighbour`: the parameter point the textures were also drawn at.
    pub neighbour_point: Option<Vec<u32>>,
    pub notes: Vec<String>,
}

pub struct Prepared {
    pub mesh_uvs: Vec<[f32; 2]>,
    pub transform: TextureTransform,
    pub layout: TextureLayout,
    pub repeat: [bool; 2],
    pub texcoord_ms: f64,
}

fn prepare(
    pt: &Point,
    o: usize,
    mesh: &Mesh,
    req: &InferRequest,
    reduction: f64,
) -> Result<Prepared> {
    place(
        &pt.scene,
        &[&pt.frame],
        pt.settings.resolution,
        o,
        mesh,
        req.max_texture,
        reduction,
        req.texels_per_pixel,
    )
}

/// Texture-coordinate optimization (thesis 3.2) of object `o` over the views of `frames`,
/// with the per-object resolution reduction factor `reduction`: the texture coordinates of
/// [`atlas`] and the placement of [`place_in`] over the same views.
#[allow(clippy::too_many_arguments)]
pub fn place(
    scene: &Scene,
    frames: &[&Frame],
    res: (u32, u32),
    o: usize,
    mesh: &Mesh,
    max_texture: u32,
    reduction: f64,
    texels_per_pixel: Option<f64>,
) -> Result<Prepared> {
    let t = Instant::now();
    let at = atlas(frames, res, o, mesh);
    let pl = place_in(scene, frames, res, o, mesh, &at, max_texture, reduction, texels_per_pixel)?;
    Ok(Prepared {
        mesh_uvs: at.uvs,
        transform: pl.transform,
        layout: pl.layout,
        repeat: pl.repeat,
        texcoord_ms: t.elapsed().as_secs_f64() * 1e3,
    })
}

/// The object compared: `req.object` by name, or the most specular (largest specular share
/// of its radiance at the point).
fn chosen_object(req: &InferRequest, pt: &Point, names: &[String]) -> Result<usize> {
    let scene = &pt.scene;
    let w = pt.settings.resolution.0;
    Ok(match &req.object {
        Some(n) => scene
            .objects
            .iter()
            .position(|x| &x.name == n)
            .or_else(|| names.iter().position(|x| x == n))
            .ok_or_else(|| anyhow!("no object {n:?}; the scene has {}", names.join(", ")))?,
        None => {
            let mut best = (f64::NEG_INFINITY, 0);
            for (k, n) in names.iter().enumerate() {
                let (Some(c), Some(d), Some(s)) = (
                    pt.images.object_layer(n, LayerKind::Coverage).and_then(|l| l.channel("A")),
                    pt.images.object_layer(n, LayerKind::Diffuse),
                    pt.images.object_layer(n, LayerKind::Specular),
                ) else {
                    continue;
                };
                let (mut sd, mut ss) = (0.0f64, 0.0f64);
                for (i, &cv) in c.iter().enumerate() {
                    let (x, y) = (i as u32 % w, i as u32 / w);
                    sd += cv as f64 * d.rgb(x, y).element_sum() as f64;
                    ss += cv as f64 * s.rgb(x, y).element_sum() as f64;
                }
                let share = if sd + ss > 0.0 { ss / (sd + ss) } else { f64::NEG_INFINITY };
                if share > best.0 {
                    best = (share, k);
                }
            }
            best.1
        }
    })
}

/// Every object's mesh as the point's camera draws it.
fn draw_meshes<'m>(pt: &Point, meshes: &'m [Mesh]) -> Vec<DrawMesh<'m>> {
    let clip_from = |o: usize| {
        pis_trace::camera::projection_matrix(&pt.frame.camera, pt.settings.resolution)
            * pt.frame.camera.world_from_camera.inverse()
            * pt.frame.instances[o].world_from_object
    };
    meshes
        .iter()
        .enumerate()
        .map(|(o, m)| DrawMesh {
            positions: &m.positions,
            uvs: &m.uvs,
            indices: &m.indices,
            clip_from_object: clip_from(o),
        })
        .collect()
}

/// The render matrix A of `obj`, object `k` of `draw`: antialiased (thesis 3.4.4) or at
/// pixel centres, occluded by `occ`.
fn object_matrix(
    req: &InferRequest,
    pt: &Point,
    draw: &[DrawMesh],
    obj: &TexturedObject,
    k: usize,
    occ: &pis_compile::DepthBuffer,
) -> Result<RenderMatrix> {
    let (w, h) = pt.settings.resolution;
    let viewport = Viewport { width: w, height: h };
    Ok(if req.antialias > 1 {
        let display_filter = DisplayFilter {
            sigma_px: pt.settings.filter.sigma_px,
            radius_px: pt.settings.filter.radius_px,
        };
        let others: Vec<DrawMesh> =
            draw.iter().enumerate().filter(|(j, _)| *j != k).map(|(_, m)| *m).collect();
        antialiased_render_matrix(viewport, req.antialias, display_filter, obj, &others)?
    } else {
        render_matrix(viewport, obj, Some(occ))?
    })
}

/// The player's pipeline, where an adapter exists (Mesa's lavapipe on a machine without a
/// GPU), and the report's note on it.
fn player_pipeline(req: &InferRequest) -> (Result<(Gpu, TexturedPipeline), String>, String) {
    let state: Result<(Gpu, TexturedPipeline), String> = if req.wgpu {
        Gpu::new()
            .map(|g| {
                let p = TexturedPipeline::new(&g);
                (g, p)
            })
            .map_err(|e| e.to_string())
    } else {
        Err("not asked for (--no-wgpu)".into())
    };
    let note = match &state {
        Ok((g, _)) => format!("psnr_db_wgpu: rendered by pis-play on {}", g.describe()),
        Err(e) => format!("psnr_db_wgpu is null: no wgpu rendering ({e})"),
    };
    (state, note)
}

/// The compared object drawn with each method's texture and scored against the gold
/// standard `b`: through its render matrix, and through the player's pipeline where there is
/// one.
struct Scores<'a> {
    b: &'a [f32],
    gpu: &'a Result<(Gpu, TexturedPipeline), String>,
    viewport: Viewport,
    mesh: DrawMesh<'a>,
    prep: &'a Prepared,
    occluders: Vec<DrawMesh<'a>>,
    methods: BTreeMap<String, MethodReport>,
    kept: Vec<Kept>,
    notes: Vec<String>,
}

impl Scores<'_> {
    /// PSNR of texture `x` drawn by the player with `filter` over the rows of `a`.
    fn wgpu_psnr(
        &self,
        a: &RenderMatrix,
        filter: Filter,
        x: &[f32],
    ) -> Result<Option<f64>, String> {
        let Ok((gpu, pipeline)) = self.gpu.as_ref() else { return Ok(None) };
        let obj = TexturedObject {
            mesh: self.mesh,
            transform: self.prep.transform,
            layout: self.prep.layout,
            sampler: sampler(filter, self.prep.repeat),
        };
        let rgba: Vec<f32> = x.chunks_exact(3).flat_map(|c| [c[0], c[1], c[2], 1.0]).collect();
        let img = render_object(gpu, pipeline, self.viewport, &self.occluders, &obj, &rgba)
            .map_err(|e| e.to_string())?;
        let got: Vec<f32> = a
            .pixels
            .iter()
            .flat_map(|&p| {
                let v = img.pixel(p as usize);
                [v[0], v[1], v[2]]
            })
            .collect();
        Ok(Some(psnr_display(&got, self.b)))
    }

    /// Method `name`'s texture `x`, drawn through `a` with `filter`, made in `ms`
    /// milliseconds (in `it` iterations, converged or not, for a solve).
    fn add(
        &mut self,
        name: &str,
        a: &RenderMatrix,
        filter: Filter,
        x: &[f32],
        ms: f64,
        it: Option<(u32, bool)>,
    ) {
        let (it, converged) = (it.map(|i| i.0), it.map(|i| i.1));
        let p = psnr_display(&render(a, x), self.b);
        let w = self.wgpu_psnr(a, filter, x).unwrap_or_else(|e| {
            self.notes.push(format!("{name}: wgpu rendering failed: {e}"));
            None
        });
        self.methods.insert(
            name.to_string(),
            MethodReport {
                psnr_db: p,
                psnr_db_wgpu: w,
                ms,
                iterations: it,
                texel_range: x
                    .iter()
                    .fold([f32::INFINITY, f32::NEG_INFINITY], |r, &v| [r[0].min(v), r[1].max(v)]),
                psnr_db_neighbour: None,
                converged,
            },
        );
        self.kept.push((name.to_string(), filter, x.to_vec()));
    }

    /// A solve's texture as method `name`.
    fn add_solution(&mut self, name: &str, a: &RenderMatrix, filter: Filter, s: &Solution) {
        self.add(name, a, filter, &s.texels, s.solve_ms, Some((s.iterations, s.converged)));
    }
}

/// The pyramidal settings of `req` (ε_F and the pyramidal ε_B).
fn pyramidal(req: &InferRequest) -> SolveSettings {
    SolveSettings { epsilon_f: req.epsilon_f, epsilon_b: req.pyramidal_epsilon_b, ..req.solver }
}

/// The least-squares methods (thesis 3.4–3.6) through the bilinear and trilinear matrices;
/// returns the trilinear solve, whose counts the report gives.
fn least_squares(
    req: &InferRequest,
    scores: &mut Scores,
    a_bil: &RenderMatrix,
    a_tri: &RenderMatrix,
) -> Result<Solution> {
    let b = scores.b;
    let plain = req.solver;
    let pyramidal = pyramidal(req);
    let unconstrained = SolveSettings { epsilon_b: 0.0, epsilon_f: 0.0, ..req.solver };
    let bil = solve(a_bil, b, None, &plain)?;
    scores.add_solution("ls-bilinear", a_bil, Filter::Bilinear, &bil);
    let tri = solve(a_tri, b, None, &plain)?;
    scores.add_solution("ls-trilinear", a_tri, Filter::Trilinear, &tri);
    if plain.epsilon_b > 0.0 {
        // Plain least squares without the constraint 0 ≤ x ≤ R of eq. 3.4: a diagnostic.
        let u = solve(a_tri, b, None, &unconstrained)?;
        scores.add_solution("ls-trilinear-unconstrained", a_tri, Filter::Trilinear, &u);
    }
    if plain.epsilon_b == 0.0 {
        // Eq. 3.4 as written: plain least squares under the box 0 ≤ x ≤ 1.1 · max(b), and
        // the same box with the pyramidal term.
        let bounded = SolveSettings { bounded: true, ..plain };
        let t = solve(a_tri, b, None, &bounded)?;
        scores.add_solution("ls-trilinear-bounded", a_tri, Filter::Trilinear, &t);
        if pyramidal.epsilon_b == 0.0 {
            let t = solve(a_tri, b, None, &SolveSettings { bounded: true, ..pyramidal })?;
            scores.add_solution("ls-pyramidal-bounded", a_tri, Filter::Trilinear, &t);
        }
    }
    let pyr = solve(a_tri, b, None, &pyramidal)?;
    scores.add_solution("ls-pyramidal", a_tri, Filter::Trilinear, &pyr);
    // The same in the decimated parameterization (what pis-pack solves): level 0 through the
    // MIP chain the player decimates from it.
    let dec = solve(a_tri, b, None, &SolveSettings { mip: MipSolve::Decimated, ..pyramidal })?;
    scores.add_solution("ls-decimated", a_tri, Filter::Trilinear, &dec);
    Ok(tri)
}

/// The baselines, forward mapping and ray tracing into the texture, rendered with trilinear
/// filtering as the player would draw them.
fn baselines(
    pt: &Point,
    o: usize,
    (cov, rgb): (&[f32], &[f32]),
    scores: &mut Scores,
    a_tri: &RenderMatrix,
) -> Result<()> {
    let (w, h) = pt.settings.resolution;
    let (mesh_o, prep) = (scores.mesh, scores.prep);
    let t = Instant::now();
    let layer = LayerImage {
        width: w,
        height: h,
        rgb: rgb.to_vec(),
        covered: cov.iter().map(|&c| c > 0.0).collect(),
    };
    let fwd = forward_map(&mesh_o, &prep.transform, &layer, &prep.layout)?;
    scores.add("forward", a_tri, Filter::Trilinear, &fwd, t.elapsed().as_secs_f64() * 1e3, None);
    let t = Instant::now();
    let eye = pt.frame.camera.world_from_camera.w_axis.truncate();
    let mut trace_err = None;
    let traced = trace_into_texture(
        &mesh_o,
        &prep.transform,
        pt.frame.instances[o].world_from_object,
        eye,
        &prep.layout,
        |rays| {
            // Start just before the object point, so the object's own surface is what is seen
            // (thesis 3.6: front- or back-facing, occluded or not).
            let r: Vec<(Vec3, Vec3)> = rays
                .iter()
                .map(|r| (r.origin + r.direction * (r.distance * 0.999), r.direction))
                .collect();
            match pis_trace::rays::trace_rays(
                &pt.scene,
                &pt.frame,
                &pt.settings,
                &r,
                pt.settings.spp.max(1),
            ) {
                Ok(v) => v.iter().map(|x| (x.diffuse + x.specular).to_array()).collect(),
                Err(e) => {
                    trace_err = Some(e);
                    vec![[0.0; 3]; rays.len()]
                }
            }
        },
    )?;
    if let Some(e) = trace_err {
        return Err(e.into());
    }
    scores.add("traced", a_tri, Filter::Trilinear, &traced, t.elapsed().as_secs_f64() * 1e3, None);
    Ok(())
}

/// With `--all-objects`: every object's placement, render matrix and pyramidal solve timed.
fn object_timings(
    req: &InferRequest,
    pt: &Point,
    names: &[String],
    meshes: &[Mesh],
    draw: &[DrawMesh],
    reduction: f64,
) -> Result<Vec<ObjectTiming>> {
    let (w, h) = pt.settings.resolution;
    let viewport = Viewport { width: w, height: h };
    let mut objects = Vec::new();
    for k in 0..pt.scene.objects.len() {
        let t0 = Instant::now();
        let Ok((cov_k, rgb_k)) = object_layer(&pt.images, &names[k]) else { continue };
        let prep_k = prepare(pt, k, &meshes[k], req, reduction)?;
        let t1 = Instant::now();
        let occ = scene_depth(viewport, draw, Some(k))?;
        let mut m = draw[k];
        m.uvs = &prep_k.mesh_uvs;
        let obj = TexturedObject {
            mesh: m,
            transform: prep_k.transform,
            layout: prep_k.layout,
            sampler: sampler(Filter::Trilinear, prep_k.repeat),
        };
        let (a, bk) = restrict(&object_matrix(req, pt, draw, &obj, k, &occ)?, &cov_k, &rgb_k);
        let matrix_ms = t1.elapsed().as_secs_f64() * 1e3;
        if a.rows() == 0 {
            continue;
        }
        let s = solve(&a, &bk, None, &pyramidal(req))?;
        objects.push(ObjectTiming {
            object: pt.scene.objects[k].name.clone(),
            n_s: s.n_s,
            n_t: s.n_t,
            texture: [prep_k.layout.width, prep_k.layout.height],
            texcoord_ms: prep_k.texcoord_ms,
            matrix_ms,
            solve_ms: s.solve_ms,
            iterations: s.iterations,
            total_ms: t0.elapsed().as_secs_f64() * 1e3,
        });
    }
    Ok(objects)
}

/// Runs the comparison.
pub fn infer(req: &InferRequest) -> Result<InferReport> {
    let pt = load_point(req)?;
    let scene = &pt.scene;
    let names = pis_trace::channel_names(scene);
    let (w, h) = pt.settings.resolution;
    let viewport = Viewport { width: w, height: h };
    let meshes: Vec<Mesh> = (0..scene.objects.len()).map(|o| merged_mesh(scene, o)).collect();
    let draw = draw_meshes(&pt, &meshes);
    let o = chosen_object(req, &pt, &names)?;
    let (cov, rgb) = object_layer(&pt.images, &names[o])?;
    let reduction = if req.reduction > 0.0 { req.reduction } else { 1.0 };
    let prep = prepare(&pt, o, &meshes[o], req, reduction)?;
    let t = Instant::now();
    let occluders = scene_depth(viewport, &draw, Some(o))?;
    let mut mesh_o = draw[o];
    mesh_o.uvs = &prep.mesh_uvs;
    let matrix = |filter| -> Result<RenderMatrix> {
        let obj = TexturedObject {
            mesh: mesh_o,
            transform: prep.transform,
            layout: prep.layout,
            sampler: sampler(filter, prep.repeat),
        };
        object_matrix(req, &pt, &draw, &obj, o, &occluders)
    };
    let (a_bil, b) = restrict(&matrix(Filter::Bilinear)?, &cov, &rgb);
    let (a_tri, _) = restrict(&matrix(Filter::Trilinear)?, &cov, &rgb);
    let matrix_ms = t.elapsed().as_secs_f64() * 1e3;
    if a_tri.rows() == 0 {
        bail!("object {} covers no pixel at this point", names[o]);
    }
    let (gpu, gpu_note) = player_pipeline(req);
    let mut scores = Scores {
        b: &b,
        gpu: &gpu,
        viewport,
        mesh: mesh_o,
        prep: &prep,
        occluders: draw.iter().enumerate().filter(|(k, _)| *k != o).map(|(_, m)| *m).collect(),
        methods: BTreeMap::new(),
        kept: Vec::new(),
        notes: vec![gpu_note],
    };
    let tri = least_squares(req, &mut scores, &a_bil, &a_tri)?;
    baselines(&pt, o, (&cov, &rgb), &mut scores, &a_tri)?;
    let Scores { mut methods, kept, notes, .. } = scores;

    let mut neighbour_point = None;
    if req.neighbour {
        let (np, psnrs) = neighbour_psnr(req, &pt, o, &prep, &kept)?;
        for (name, p) in psnrs {
            if let Some(m) = methods.get_mut(&name) {
                m.psnr_db_neighbour = Some(p);
            }
        }
        neighbour_point = Some(np);
    }
    let objects = if req.all_objects {
        object_timings(req, &pt, &names, &meshes, &draw, reduction)?
    } else {
        Vec::new()
    };
    Ok(InferReport {
        object: scene.objects[o].name.clone(),
        point: pt.samples.clone(),
        values: pt.values.clone(),
        resolution: [w, h],
        texture: [prep.layout.width, prep.layout.height],
        repeat: prep.repeat,
        methods,
        solve_ms: tri.solve_ms,
        iterations: tri.iterations,
        n_s: tri.n_s,
        n_t: tri.n_t,
        trace_ms: pt.trace_ms,
        texcoord_ms: prep.texcoord_ms,
        matrix_ms,
        objects,
        neighbour_point,
        notes: [notes, vec![
            "PSNR on display values: linear radiance clamped to [0, 1], sRGB-encoded, peak 1, over the object's covered pixels".into(),
            "baselines are rendered with trilinear filtering".into(),
        ]].concat(),
    })
}

/// A solved texture: method name, the filter it is drawn with, n_t × 3 texels.
type Kept = (String, Filter, Vec<f32>);

/// The neighbouring point's samples and, per method, its PSNR there.
type NeighbourPsnr = (Vec<u32>, Vec<(String, f64)>);

/// The textures solved at `pt` drawn at the neighbouring view sample (the last parameter
/// dimension one sample on, or back at the end; the placement and layout stay those of
/// `pt`, as within a parameter block), each against the gold standard there.
fn neighbour_psnr(
    req: &InferRequest,
    pt: &Point,
    o: usize,
    prep: &Prepared,
    textures: &[Kept],
) -> Result<NeighbourPsnr> {
    let dims = &pt.scene.space.dims;
    let mut samples = pt.samples.clone();
    let last =
        dims.len().checked_sub(1).ok_or_else(|| anyhow!("the parameter space has no dimension"))?;
    let n = dims[last].samples();
    if n < 2 {
        bail!("the last parameter dimension has one sample: no neighbouring view");
    }
    samples[last] = if samples[last] + 1 < n { samples[last] + 1 } else { samples[last] - 1 };
    let at: Vec<f32> = dims.iter().zip(&samples).map(|(d, &s)| d.values[s as usize]).collect();
    let q = load_point(&InferRequest { at: Some(at), ..req.clone() })?;
    let names = pis_trace::channel_names(&q.scene);
    let (w, h) = q.settings.resolution;
    let viewport = Viewport { width: w, height: h };
    let meshes: Vec<Mesh> = (0..q.scene.objects.len()).map(|k| merged_mesh(&q.scene, k)).collect();
    let proj = pis_trace::camera::projection_matrix(&q.frame.camera, (w, h));
    let view_from_world = q.frame.camera.world_from_camera.inverse();
    let mut draw: Vec<DrawMesh> = meshes
        .iter()
        .enumerate()
        .map(|(k, m)| DrawMesh {
            positions: &m.positions,
            uvs: &m.uvs,
            indices: &m.indices,
            clip_from_object: proj * view_from_world * q.frame.instances[k].world_from_object,
        })
        .collect();
    draw[o].uvs = &prep.mesh_uvs;
    let (cov, rgb) = object_layer(&q.images, &names[o])?;
    let occ = scene_depth(viewport, &draw, Some(o))?;
    let mut out = Vec::new();
    for (name, filter, x) in textures {
        let obj = TexturedObject {
            mesh: draw[o],
            transform: prep.transform,
            layout: prep.layout,
            sampler: sampler(*filter, prep.repeat),
        };
        let (a, b) = restrict(&render_matrix(viewport, &obj, Some(&occ))?, &cov, &rgb);
        if a.rows() == 0 {
            bail!("object {} covers no pixel at the neighbouring point {samples:?}", names[o]);
        }
        out.push((name.clone(), psnr_display(&render(&a, x), &b)));
    }
    Ok((samples, out))
}

/// Human-readable lines of the report (stderr).
pub fn print_report(r: &InferReport, out: &mut impl std::io::Write) -> std::io::Result<()> {
    writeln!(
        out,
        "object {} at point {:?} (values {:?}), {}x{}",
        r.object, r.point, r.values, r.resolution[0], r.resolution[1]
    )?;
    writeln!(
        out,
        "  texture {}x{} (repeat {:?}), n_s {}, n_t {}",
        r.texture[0], r.texture[1], r.repeat, r.n_s, r.n_t
    )?;
    for (name, m) in &r.methods {
        let it = m.iterations.map_or(String::new(), |i| {
            format!(
                ", {i} iterations{}",
                if m.converged == Some(false) { ", not converged" } else { "" }
            )
        });
        let w = m.psnr_db_wgpu.map_or("     -".to_string(), |p| format!("{p:6.2}"));
        let nb = m.psnr_db_neighbour.map_or(String::new(), |p| format!(", neighbour {p:6.2} dB"));
        writeln!(out, "  {name:<13} model {:6.2} dB, wgpu {w} dB{nb}   ({:.0} ms{it}; texels in [{:.3}, {:.3}])",
                 m.psnr_db, m.ms, m.texel_range[0], m.texel_range[1])?;
    }
    for n in &r.notes {
        writeln!(out, "  note: {n}")?;
    }
    if let Some(p) = &r.neighbour_point {
        writeln!(
            out,
            "  neighbour: the textures drawn at point {p:?} (placement of this point), model"
        )?;
    }
    writeln!(out, "  trace {:.0} ms, texcoord {:.0} ms, matrices {:.0} ms, LS-trilinear solve {:.0} ms ({} iterations)",
             r.trace_ms, r.texcoord_ms, r.matrix_ms, r.solve_ms, r.iterations)?;
    for t in &r.objects {
        writeln!(out, "  {:<10} {}x{} n_s {:6} n_t {:7}: texcoord {:5.0} ms, A {:5.0} ms, solve {:6.0} ms ({} it), total {:6.0} ms",
                 t.object, t.texture[0], t.texture[1], t.n_s, t.n_t, t.texcoord_ms, t.matrix_ms, t.solve_ms, t.iterations, t.total_ms)?;
    }
    Ok(())
}

/// Used by the CLI to check paths before working.
pub fn input_exists(p: &Path) -> bool {
    p.exists()
}
