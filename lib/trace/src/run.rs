//! Rendering a whole ray-traced set: every parameter point of a scene, written as it is done.

use crate::error::TraceError;
use crate::render::{object_channels, render_point, PointRender};
use crate::set::{Begin, SetWriter, Shard};
use crate::settings::TraceSettings;
use pis_scene::Scene;
use serde::Serialize;
use std::path::Path;
use std::time::Instant;

/// What a set render reports.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct SetReport {
    pub scene: String,
    /// Parameter points this process rendered (its shard's, less those resumed).
    pub points: usize,
    /// Parameter points the scene's space has.
    pub points_in_space: usize,
    pub resolution: [u32; 2],
    pub spp: u32,
    /// What seeded the shading: `cell` (the surface point) or `sample` (each camera
    /// sample).
    pub shading_seed: String,
    /// The camera samples' stream (`pis-trace --seed`; 0 the default).
    pub seed: u64,
    /// Worker threads.
    pub threads: usize,
    /// Largest number of world triangles of any point.
    pub triangles: u64,
    pub camera_rays: u64,
    pub total_rays: u64,
    /// Total rays per second of tracing (BVH builds and file writing excluded).
    pub rays_per_second: f64,
    /// Camera rays per second of tracing.
    pub camera_rays_per_second: f64,
    /// Wall-clock milliseconds per point, everything included.
    pub ms_per_point: f64,
    /// Milliseconds per point spent tracing.
    pub trace_ms_per_point: f64,
    pub seconds: f64,
    /// Bytes written (EXRs, ray records, set.json).
    pub output_bytes: u64,
    /// The shard this process rendered (`I/N`), when the trace is split over processes.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub shard: Option<String>,
    /// Points of the set (the whole space, or the first `--points`).
    pub set_points: usize,
    /// Points of this process skipped because an earlier run of the same trace recorded
    /// them (`resume`).
    pub resumed: usize,
    /// Whether the set is complete (set.json written, by this process or before it).
    pub complete: bool,
    /// What the trace found wrong with the scene without failing (also told to
    /// [`Progress::note`] as found).
    pub warnings: Vec<String>,
    /// Adaptive sampling's noise threshold (0: every pixel took `spp` samples).
    pub noise_threshold: f32,
    /// Adaptive sampling's fewest samples per pixel.
    pub min_spp: u32,
    /// Camera samples per pixel, averaged over the points this process rendered.
    pub mean_spp: f64,
    /// The denoiser of the `denoised.` layers; absent when the set is not denoised.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub denoiser: Option<String>,
    /// Layers given a denoised twin, summed over the points this process rendered.
    pub denoised_layers: usize,
    /// Layers kept raw at a point because denoising was estimated to move them further
    /// from the converged image (`point 3: object.TeapotLid.specular`).
    pub kept_raw: Vec<String>,
    /// Milliseconds per point spent denoising (included in `ms_per_point`).
    pub denoise_ms_per_point: f64,
}

/// Progress notifications from [`render_set`], called from worker threads.
pub trait Progress: Sync {
    /// The work is known: `points` points to render (of `rows` rows each).
    fn start(&self, _points: usize, _rows: u32) {}
    /// A point starts (`index` in rendering order, of `count`).
    fn point(&self, _index: usize, _count: usize) {}
    /// One image row of the current point is done.
    fn row(&self) {}
    /// A warning on the scene, before the work (e.g. nothing emits light, a glTF extension
    /// PIS does not implement).
    fn note(&self, _text: &str) {}
}

/// The warning when nothing in `scene` emits light.
pub fn darkness_warning(scene: &Scene) -> Option<String> {
    (!scene.emits()).then(|| format!(
        "nothing in scene {} emits light (no light in the glTF or in scene.toml, no [environment], no emissive material): every image will be black; add a [[light]] or an [environment] to scene.toml (docs/SCENE.md)",
        scene.name
    ))
}

/// `settings`, with denoising turned off where it was asked for and Open Image Denoise
/// cannot be loaded, and then the warning that says why.
fn denoise_or_not(settings: &TraceSettings) -> (TraceSettings, Option<String>) {
    let mut settings = settings.clone();
    let mut note = None;
    if settings.denoise {
        if let Err(why) = crate::oidn::shared() {
            note = Some(format!("the layers are not denoised: {why}"));
            settings.denoise = false;
        }
    }
    (settings, note)
}

/// Adds to a rendered point's images the layers the set stores beside the segmented ones:
/// adaptive sampling's `samples` and `error`, and with denoising the guides and the
/// `denoised.` twins (RAYSET.md 5.4).
fn add_set_layers(
    render: &mut PointRender,
    objects: &[(String, pis_scene::ObjectRole)],
) -> Result<(), TraceError> {
    render.images.layers.extend(render.sampling.take().into_iter().flatten());
    let Some(input) = render.denoise_input.take() else { return Ok(()) };
    let oidn = crate::oidn::shared().map_err(|e| TraceError::Denoise(e.to_string()))?;
    let denoised = crate::denoise::denoise_point(oidn, &render.images, &input, objects)?;
    render.images.layers.extend(denoised.images);
    render.images.layers.extend(input.guides);
    render.denoised = Some(denoised.summary);
    Ok(())
}

/// No progress display.
pub struct NoProgress;
impl Progress for NoProgress {}

/// Renders the first `limit` points (all when `None`) of `scene` into the set directory
/// `out`, one EXR (and ray-record file) per point as each finishes, then set.json.
/// Runs on the current rayon pool.
pub fn render_set(
    scene: &Scene,
    out: &Path,
    settings: &TraceSettings,
    limit: Option<usize>,
    progress: &dyn Progress,
) -> Result<SetReport, TraceError> {
    render_shard(scene, out, settings, &TraceRun { limit, ..TraceRun::default() }, progress)
}

/// Which points of a set a process renders (RAYSET.md 9).
#[derive(Clone, Copy, Debug)]
pub struct TraceRun {
    /// The set is the first `limit` points of the space (all when `None`).
    pub limit: Option<usize>,
    /// The points this process renders: [`Shard::WHOLE`], or one shard of a trace split
    /// over processes sharing the set directory.
    pub shard: Shard,
    /// Skip the points an earlier run of the same trace recorded.
    pub resume: bool,
}

impl Default for TraceRun {
    fn default() -> Self {
        TraceRun { limit: None, shard: Shard::WHOLE, resume: false }
    }
}

/// Renders `run`'s points of `scene` into the set directory `out`, one EXR (and
/// ray-record file) per point as each finishes, each recorded once written; the process
/// that finds every point of the set recorded writes set.json. Runs on the current rayon
/// pool.
pub fn render_shard(
    scene: &Scene,
    out: &Path,
    settings: &TraceSettings,
    run: &TraceRun,
    progress: &dyn Progress,
) -> Result<SetReport, TraceError> {
    // A point's samples, images and EXR in memory at once: refused before any work when
    // the machine has not that much.
    let (w, h) = settings.resolution;
    let need = crate::memory::image_bytes(
        w,
        h,
        crate::memory::point_channels(
            scene.objects.iter().map(|o| o.role),
            settings.lens_model.terms(),
        ),
        3,
    );
    if let Some(have) = crate::memory::available_memory().filter(|&have| need > have) {
        return Err(TraceError::Memory(format!(
            "a point of {w}x{h} pixels needs about {} of memory, {} are available: trace at a smaller resolution",
            crate::memory::gib(need),
            crate::memory::gib(have)
        )));
    }
    let start = Instant::now();
    let (settings, denoise_note) = denoise_or_not(settings);
    let settings = &settings;
    let objects = object_channels(scene);
    let total_points = scene.space.point_count();
    let count = run.limit.map_or(total_points, |l| l.min(total_points));
    let mine: Vec<usize> = run.shard.points(count).collect();
    let mut report = SetReport {
        scene: scene.name.clone(),
        points: 0,
        points_in_space: total_points,
        shard: (run.shard != Shard::WHOLE).then(|| run.shard.to_string()),
        set_points: count,
        resolution: [settings.resolution.0, settings.resolution.1],
        spp: settings.spp,
        shading_seed: settings.shading_seed().name().into(),
        seed: settings.seed,
        threads: rayon::current_num_threads(),
        noise_threshold: settings.noise_threshold,
        min_spp: settings.min_spp,
        denoiser: crate::denoise::denoiser(settings),
        ..Default::default()
    };
    for w in scene.warnings.iter().cloned().chain(darkness_warning(scene)).chain(denoise_note) {
        progress.note(&w);
        report.warnings.push(w);
    }
    // A resumed trace of a set that is complete already has nothing to do.
    if run.resume && crate::set::is_complete(out, &SetWriter::meta(out, scene, settings), count) {
        report.resumed = mine.len();
        report.complete = true;
        report.seconds = start.elapsed().as_secs_f64();
        return Ok(report);
    }
    let joins = run.resume || run.shard != Shard::WHOLE;
    let mut writer = SetWriter::begin(
        out,
        scene,
        settings,
        count,
        if joins { Begin::Join } else { Begin::Fresh },
    )?;
    let todo: Vec<usize> =
        mine.iter().copied().filter(|&i| !(run.resume && writer.done(i).is_some())).collect();
    report.resumed = mine.len() - todo.len();
    report.points = todo.len();
    progress.start(todo.len(), settings.resolution.1);
    let mut trace_seconds = 0.0;
    let mut denoise_seconds = 0.0;
    for (k, &index) in todo.iter().enumerate() {
        progress.point(k, todo.len());
        let point = scene.space.point(index);
        let frame = scene.frame(&point)?;
        let mut render = render_point(scene, &frame, settings, &|| progress.row())?;
        let t = Instant::now();
        add_set_layers(&mut render, &objects)?;
        denoise_seconds += t.elapsed().as_secs_f64();
        report.denoised_layers += render.denoised.iter().map(|d| d.layers.len()).sum::<usize>();
        let kept = render.denoised.iter().flat_map(|d| &d.kept_raw);
        report.kept_raw.extend(kept.map(|o| format!("point {index}: {o}")));
        report.output_bytes += writer.write_point(scene, index, &frame, &render)?;
        report.camera_rays += render.stats.camera_rays;
        report.total_rays += render.stats.total_rays;
        report.triangles = report.triangles.max(render.stats.triangles);
        trace_seconds += render.stats.trace_seconds;
    }
    if let Some(bytes) = writer.finish_if_complete()? {
        report.output_bytes += bytes;
        report.complete = true;
    }
    report.seconds = start.elapsed().as_secs_f64();
    if trace_seconds > 0.0 {
        report.rays_per_second = report.total_rays as f64 / trace_seconds;
        report.camera_rays_per_second = report.camera_rays as f64 / trace_seconds;
    }
    if !todo.is_empty() {
        report.ms_per_point = report.seconds * 1000.0 / todo.len() as f64;
        report.trace_ms_per_point = trace_seconds * 1000.0 / todo.len() as f64;
        report.denoise_ms_per_point = denoise_seconds * 1000.0 / todo.len() as f64;
        let pixels = settings.resolution.0 as f64 * settings.resolution.1 as f64;
        report.mean_spp = report.camera_rays as f64 / pixels / todo.len() as f64;
    }
    Ok(report)
}

#[cfg(test)]
mod darkness_tests {
    use super::darkness_warning;
    use pis_scene::rig::LightRig;
    use pis_scene::{Environment, EnvironmentRadiance, LightKind, Material, Scene};

    #[test]
    fn a_scene_that_nothing_lights_is_warned_of() {
        let mut s = Scene {
            name: "dark".into(),
            materials: vec![Material::default()],
            ..Default::default()
        };
        let w = darkness_warning(&s).expect("a warning");
        assert!(w.contains("dark") && w.contains("[[light]]"), "{w}");
        s.materials[0].emissive = [0.0, 0.2, 0.0];
        assert_eq!(darkness_warning(&s), None, "an emissive material lights it");
        s.materials[0].emissive = [0.0; 3];
        s.rig.lights.push(LightRig {
            name: "Key".into(),
            node: 0,
            kind: LightKind::Point,
            radiance: [1.0; 3],
            radius: 0.0,
            visible_camera: true,
        });
        assert_eq!(darkness_warning(&s), None, "a light lights it");
    }

    #[test]
    fn an_environment_alone_lights_a_scene_unless_it_is_black() {
        let sky = |c: [f32; 3]| {
            Some(Environment {
                radiance: EnvironmentRadiance::Uniform(c),
                rotation: 0.0,
                background: false,
            })
        };
        let mut s = Scene {
            name: "sky".into(),
            materials: vec![Material::default()],
            environment: sky([0.0; 3]),
            ..Default::default()
        };
        assert!(
            darkness_warning(&s).is_some_and(|w| w.contains("[environment]")),
            "a black environment lights nothing"
        );
        s.environment = sky([0.2, 0.3, 0.4]);
        assert_eq!(darkness_warning(&s), None);
    }
}
