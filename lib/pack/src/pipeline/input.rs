//! The pack's input: a ray-traced set (traced first when given a scene.toml), its scene,
//! and every point's images, checked before any work is done.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use anyhow::anyhow;
use pis_scene::{Frame, LoadOptions, Scene};
use pis_trace::set::RaySet;
use pis_trace::settings::DenoiseMode;
use pis_trace::{TraceError, TraceSettings};

use super::memory::MemoryPlan;
use super::scratch::Scratch;
use super::set_images::{spill_point, SetImages};
use super::{PackRequest, Stages};
use crate::error::{Exit, Failure};

/// A set in memory with the scene it was traced from.
pub struct LoadedSet {
    pub dir: PathBuf,
    pub scene: Scene,
    pub resolution: (u32, u32),
    /// Sample indices per point, in the set's (linear-index) order.
    pub samples: Vec<Vec<u32>>,
    pub frames: Vec<Frame>,
    /// Every point's images, held or spilled to the scratch file ([`super::memory`]).
    pub images: SetImages,
    /// The scratch file of a pack that streams.
    pub scratch: Option<Arc<Scratch>>,
    /// How the pack holds the set, and why.
    pub memory: MemoryPlan,
    /// Per object, the set's channel name (`object.<name>` prefix of its layers).
    pub channels: Vec<String>,
    /// The set's display filter (`set.json` `filter`, RAYSET.md section 4).
    pub display_filter: pis_trace::film::GaussianFilter,
    /// The tracer's settings the set was rendered with (`set.json` `renderer.settings`;
    /// else the defaults at its resolution and samples per pixel): what anything traced
    /// for the set afterwards, such as a static environment map, is traced with.
    pub trace: TraceSettings,
    /// Per point, the outgoing-ray records of the lens objects (RAYSET.md 6; empty where the
    /// set has none).
    pub records: Vec<Vec<pis_trace::RayRecord>>,
    /// Whether the solves weigh each pixel's rows by the set's confidence in it
    /// (`--confidence`, [`super::confidence`]).
    pub weigh_rows: bool,
    /// Per point, the layers read from their denoised twins (RAYSET.md 5.4).
    pub denoised: Vec<Vec<String>>,
}

impl LoadedSet {
    /// Raw image bytes of the set at 3 bytes per pixel (thesis 4.8).
    pub fn raw_image_bytes(&self) -> u64 {
        self.samples.len() as u64 * self.resolution.0 as u64 * self.resolution.1 as u64 * 3
    }
}

fn trace_failure(e: TraceError) -> Failure {
    Failure::from(e)
}

fn invalid(msg: String) -> Failure {
    Failure::new(Exit::Invalid, anyhow!(msg))
}

/// The tracer's settings a scene.toml given to the pack (or the player) is traced with:
/// pis-trace's defaults at the scene's size and samples per pixel, denoised as `denoise`
/// says (`On` without the library is an error naming why).
pub fn scene_trace_settings(scene: &Scene, denoise: DenoiseMode) -> Result<TraceSettings, Failure> {
    denoise.apply(TraceSettings::new(scene.resolution, scene.spp)).map_err(trace_failure)
}

/// The cache directory a scene.toml is traced into with `settings`: beside it, named by size
/// and spp, and `-denoised` where the trace denoises (a raw set traced before, or where the
/// library is missing, is not taken for a denoised one).
pub fn cache_dir(scene_toml: &Path, scene: &Scene, settings: &TraceSettings) -> PathBuf {
    let dir = scene_toml.parent().unwrap_or(Path::new("."));
    let denoised = if pis_trace::denoise::denoiser(settings).is_some() { "-denoised" } else { "" };
    dir.join(".pis-cache").join(format!(
        "{}-{}x{}-spp{}{denoised}",
        scene.name, scene.resolution.0, scene.resolution.1, scene.spp
    ))
}

/// True when a scene's parameter space is the one a set was traced over: the same
/// dimensions (names, kinds) with the same sample values.
fn same_space(scene: &Scene, set: &RaySet) -> bool {
    scene.space.dims.len() == set.meta.space.len()
        && scene.space.dims.iter().zip(&set.meta.space).all(|(d, m)| {
            d.name == m.name
                && d.kind.name() == m.kind
                && d.values.len() == m.values.len()
                && d.values
                    .iter()
                    .zip(&m.values)
                    .all(|(a, b)| (a - b).abs() <= 1e-4 * a.abs().max(b.abs()).max(1.0))
        })
}

/// Loads the scene a set was traced from at the set's resolution: scene.toml as written, or,
/// when the set's parameter space is that of one of its `[preset.NAME]`s (a set traced with
/// `pis-trace --preset NAME`), with that preset. A preset named by the caller is used as is.
pub fn set_scene(
    set: &RaySet,
    scene_path: &Path,
    res: (u32, u32),
    preset: Option<&str>,
) -> Result<Scene, Failure> {
    let load = |preset: Option<String>| {
        let options = LoadOptions { preset, resolution: Some(res), ..LoadOptions::default() };
        pis_scene::load_with(scene_path, &options).map_err(|e| {
            Failure::new(
                crate::error::scene_exit(&e),
                anyhow!("loading {} (the set's scene; pass --scene): {e}", scene_path.display()),
            )
        })
    };
    if let Some(p) = preset {
        return load(Some(p.to_string()));
    }
    let scene = load(None)?;
    if same_space(&scene, set) {
        return Ok(scene);
    }
    let presets = pis_scene::manifest::Manifest::read(scene_path)
        .map(|m| m.presets.into_keys().collect::<Vec<_>>())
        .unwrap_or_default();
    for name in presets {
        if let Ok(s) = load(Some(name)) {
            if same_space(&s, set) {
                return Ok(s);
            }
        }
    }
    Ok(scene)
}

/// Whether the pack reads layer `kind` of an object under `mode`: surface textures read an
/// object's coverage, diffuse and specular layers; environment maps and hybrid rendering
/// also its Fresnel, local/distant and lens-object layers (and the ray records).
pub fn reads_layer(mode: super::RepresentationMode, kind: pis_trace::LayerKind) -> bool {
    use pis_trace::LayerKind::*;
    mode != super::RepresentationMode::Texture || matches!(kind, Coverage | Diffuse | Specular)
}

/// Whether the pack reads the layer named `name` (`combined`, `object.<object>.<layer>`;
/// layers of unknown kind are kept).
fn reads_layer_named(mode: super::RepresentationMode, name: &str) -> bool {
    match name
        .strip_prefix("object.")
        .and_then(|n| n.rsplit_once('.'))
        .and_then(|(_, l)| pis_trace::LayerKind::from_name(l))
    {
        Some(kind) => reads_layer(mode, kind),
        None => true,
    }
}

/// The set's directory and its scene.toml: the input set's, or the input scene.toml traced
/// into its cache first (what the container cannot store refused before the trace).
fn set_dir(req: &PackRequest, stages: &mut Stages) -> Result<(PathBuf, PathBuf), Failure> {
    Ok(if req.input.is_dir() {
        let set = RaySet::open(&req.input).map_err(trace_failure)?;
        (req.input.clone(), set.default_scene())
    } else if req.input.is_file() {
        let options =
            LoadOptions { preset: req.preset.clone(), resolution: req.resolution, spp: req.spp };
        let scene = pis_scene::load_with(&req.input, &options).map_err(Failure::from)?;
        let settings = scene_trace_settings(&scene, req.denoise)?;
        let dir = cache_dir(&req.input, &scene, &settings);
        if !dir.join("set.json").is_file() {
            // What the container cannot store is refused before the trace.
            let frames = (0..scene.space.point_count())
                .map(|i| scene.frame(&scene.space.point(i)))
                .collect::<Result<Vec<_>, _>>()
                .map_err(|e| Failure::new(Exit::Invalid, e))?;
            super::transforms::check_transforms(&scene, &frames)
                .map_err(|e| Failure::new(Exit::NotSupported, e))?;
            let r = pis_trace::render_set(&scene, &dir, &settings, None, &pis_trace::NoProgress)
                .map_err(trace_failure)?;
            for w in &r.warnings {
                stages.note(&format!("warning: {w}"));
            }
            let layers =
                r.denoiser.map_or("raw layers".to_string(), |d| format!("denoised by {d}"));
            stages.done("trace", &format!("{} points into {} ({layers})", r.points, dir.display()));
        }
        (dir, req.input.clone())
    } else {
        return Err(Failure::new(
            Exit::Io,
            anyhow!("{}: no such set directory or scene file", req.input.display()),
        ));
    })
}

/// How the set's images are held, as `req.memory` and this machine allow, and the scratch
/// file beside the output where they stream.
fn memory_plan(
    req: &PackRequest,
    set: &RaySet,
    stages: &mut Stages,
) -> Result<(MemoryPlan, Option<Arc<Scratch>>), Failure> {
    let res = (set.meta.resolution[0], set.meta.resolution[1]);
    let channels: u64 = 3 + set
        .meta
        .objects
        .iter()
        .flat_map(|o| &o.layers)
        .filter_map(|l| pis_trace::LayerKind::from_name(l))
        .filter(|&k| reads_layer(req.representation, k))
        .map(|k| k.channels().len() as u64)
        .sum::<u64>();
    let memory = MemoryPlan::new(
        pis_trace::memory::image_bytes(res.0, res.1, channels, set.meta.points.len() as u64),
        req.memory,
        pis_trace::memory::available_memory(),
    );
    if memory.stream {
        stages.note(&format!("the set is {}", memory.describe()));
    }
    let scratch = if memory.stream {
        Some(Arc::new(Scratch::beside(&req.output).map_err(|e| Failure::new(Exit::Io, e))?))
    } else {
        None
    };
    Ok((memory, scratch))
}

/// Point `i`'s image and each of its layers are `res`, as the set at `dir` declares.
fn check_point_size(
    dir: &Path,
    i: usize,
    img: &pis_trace::PointImages,
    res: (u32, u32),
) -> Result<(), Failure> {
    if (img.width, img.height) != res {
        return Err(invalid(format!(
            "{}: point {i} is {}x{}, the set declares {}x{}",
            dir.display(),
            img.width,
            img.height,
            res.0,
            res.1
        )));
    }
    for l in &img.layers {
        if l.width != res.0 || l.height != res.1 {
            return Err(invalid(format!(
                "{}: point {i} layer {} is {}x{}, the set declares {}x{}",
                dir.display(),
                l.name,
                l.width,
                l.height,
                res.0,
                res.1
            )));
        }
    }
    Ok(())
}

/// Opens (or traces) the set, loads its scene and reads and checks every point.
pub fn load(req: &PackRequest, stages: &mut Stages) -> Result<LoadedSet, Failure> {
    let (dir, scene_path) = set_dir(req, stages)?;
    let scene_path = req.scene.clone().unwrap_or(scene_path);
    let set = RaySet::open(&dir).map_err(trace_failure)?;
    let res = (set.meta.resolution[0], set.meta.resolution[1]);
    let (memory, scratch) = memory_plan(req, &set, stages)?;
    let scene = set_scene(&set, &scene_path, res, req.preset.as_deref())?;
    if set.meta.points.len() != scene.space.point_count() {
        return Err(invalid(format!(
            "{}: the set has {} points, the scene's space {}",
            dir.display(),
            set.meta.points.len(),
            scene.space.point_count()
        )));
    }
    let mut samples = Vec::new();
    let mut frames = Vec::new();
    let mut images = Vec::new();
    let mut spans = Vec::new();
    let channel_names = pis_trace::channel_names(&scene);
    let mut records = Vec::new();
    let denoised: Vec<Vec<String>> = set
        .meta
        .points
        .iter()
        .map(|p| p.denoise.as_ref().map_or_else(Vec::new, |d| d.layers.clone()))
        .collect();
    // Only the layers (and ray records) the pack reads are kept, as each point is read.
    let with_records = set.meta.objects.iter().any(|o| o.records)
        && req.representation != super::RepresentationMode::Texture;
    for (i, p) in set.meta.points.iter().enumerate() {
        if p.samples != scene.space.point(i) {
            return Err(invalid(format!(
                "{}: point {i} has samples {:?}, expected {:?}",
                dir.display(),
                p.samples,
                scene.space.point(i)
            )));
        }
        let mut img = set.read_point(i).map_err(trace_failure)?;
        img.layers.retain(|l| reads_layer_named(req.representation, &l.name));
        check_point_size(&dir, i, &img, res)?;
        let frame = scene.frame(&p.samples).map_err(|e| Failure::new(Exit::Invalid, e))?;
        if let Some(d) = p.camera.differs_from(frame.camera.world_from_camera, frame.camera.yfov) {
            return Err(invalid(format!(
                "{}: point {i}: {} places the camera otherwise than the set was traced ({d}); pass the scene.toml the set was traced from (--scene, and --preset where it was traced with one)",
                dir.display(),
                scene_path.display()
            )));
        }
        frames.push(frame);
        samples.push(p.samples.clone());
        match &scratch {
            Some(sc) => spans.push(
                spill_point(sc, &img, &channel_names).map_err(|e| Failure::new(Exit::Io, e))?,
            ),
            None => images.push(img),
        }
        records.push(if with_records {
            set.read_records(i).map_err(trace_failure)?
        } else {
            Vec::new()
        });
    }
    let trace = set
        .meta
        .renderer
        .as_ref()
        .and_then(|r| r.settings.clone())
        .unwrap_or_else(|| TraceSettings::new(res, set.meta.spp.max(1)));
    if trace.shading_seed() == pis_trace::ShadingSeed::Sample {
        stages.note(&format!(
            "warning: {} was traced with shading seeded per camera sample (pis-trace --shading-seed sample): a surface's noise differs between its images, so the solved textures average it rather than match it; a set to pack is traced with the default seeding",
            dir.display()
        ));
    }
    let images = match &scratch {
        Some(sc) => SetImages::Spilled { scratch: sc.clone(), width: res.0, height: res.1, spans },
        None => SetImages::Held(images),
    };
    let loaded = LoadedSet {
        dir,
        scene,
        resolution: res,
        samples,
        frames,
        images,
        scratch,
        memory,
        channels: channel_names,
        display_filter: set.meta.filter,
        trace,
        records,
        weigh_rows: req.confidence,
        denoised: if set.raw { Vec::new() } else { denoised },
    };
    super::transforms::check_transforms(&loaded.scene, &loaded.frames)
        .map_err(|e| Failure::new(Exit::NotSupported, e))?;
    stages.done(
        "read",
        &format!(
            "{} points of {}x{} from {}",
            loaded.samples.len(),
            res.0,
            res.1,
            loaded.dir.display()
        ),
    );
    Ok(loaded)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pipeline::RepresentationMode;

    #[test]
    fn surface_textures_keep_the_surface_layers_and_the_combined_image() {
        let t = RepresentationMode::Texture;
        for name in [
            "combined",
            "object.vase.coverage",
            "object.vase.diffuse",
            "object.glass_cup.specular",
            "object.a.b.diffuse",
            "object.vase.unknown",
        ] {
            assert!(reads_layer_named(t, name), "{name}");
        }
        for name in [
            "object.vase.local",
            "object.vase.distant",
            "object.vase.fresnel",
            "object.cup.refraction",
            "object.cup.reflection_confidence",
        ] {
            assert!(!reads_layer_named(t, name), "{name}");
        }
        for mode in [
            RepresentationMode::Pem,
            RepresentationMode::Auto,
            RepresentationMode::PemInfinity,
            RepresentationMode::StaticEnv,
        ] {
            assert!(
                reads_layer_named(mode, "object.vase.local")
                    && reads_layer_named(mode, "object.cup.refraction_modulation"),
                "{mode:?}"
            );
        }
    }
}
