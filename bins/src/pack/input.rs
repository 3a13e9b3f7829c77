//! The pack's input: a ray-traced set (traced first when given a scene.toml), its scene,
//! and every point's images, checked before any work is done.

use std::path::{Path, PathBuf};

use anyhow::anyhow;
use pis_scene::{Frame, LoadOptions, Scene};
use pis_trace::set::RaySet;
use pis_trace::{PointImages, TraceError, TraceSettings};

use super::{PackRequest, Stages};
use crate::cli::{Exit, Failure};

/// A set in memory with the scene it was traced from.
pub(crate) struct LoadedSet {
    pub(crate) dir: PathBuf,
    pub(crate) scene: Scene,
    pub(crate) resolution: (u32, u32),
    /// Sample indices per point, in the set's (linear-index) order.
    pub(crate) samples: Vec<Vec<u32>>,
    pub(crate) frames: Vec<Frame>,
    pub(crate) images: Vec<PointImages>,
    /// Per object, the set's channel name (`object.<name>` prefix of its layers).
    pub(crate) channels: Vec<String>,
}

impl LoadedSet {
    /// Raw image bytes of the set at 3 bytes per pixel (thesis 4.8).
    pub(crate) fn raw_image_bytes(&self) -> u64 {
        self.samples.len() as u64 * self.resolution.0 as u64 * self.resolution.1 as u64 * 3
    }
}

fn trace_failure(e: TraceError) -> Failure {
    let exit = match &e {
        TraceError::Io { .. } => Exit::Io,
        TraceError::Exr { .. } | TraceError::InvalidSet { .. } => Exit::Invalid,
        TraceError::Scene(_) | TraceError::InvalidInput(_) => Exit::Invalid,
    };
    Failure::new(exit, e)
}

fn invalid(msg: String) -> Failure {
    Failure::new(Exit::Invalid, anyhow!(msg))
}

/// The cache directory a scene.toml is traced into: beside it, named by size and spp.
pub fn cache_dir(scene_toml: &Path, scene: &Scene) -> PathBuf {
    let dir = scene_toml.parent().unwrap_or(Path::new("."));
    dir.join(".pis-cache").join(format!("{}-{}x{}-spp{}", scene.name, scene.resolution.0, scene.resolution.1, scene.spp))
}

/// Opens (or traces) the set, loads its scene and reads and checks every point.
pub(crate) fn load(req: &PackRequest, stages: &mut Stages) -> Result<LoadedSet, Failure> {
    let (dir, scene_path) = if req.input.is_dir() {
        (req.input.clone(), req.input.join("scene.toml"))
    } else if req.input.is_file() {
        let options = LoadOptions { preset: req.preset.clone(), resolution: req.resolution, spp: req.spp };
        let scene = pis_scene::load_with(&req.input, &options).map_err(|e| Failure::new(Exit::Invalid, e))?;
        let dir = cache_dir(&req.input, &scene);
        if !dir.join("set.json").is_file() {
            let settings = TraceSettings::new(scene.resolution, scene.spp);
            let r = pis_trace::render_set(&scene, &dir, &settings, None, &pis_trace::NoProgress).map_err(trace_failure)?;
            stages.done("trace", &format!("{} points into {}", r.points, dir.display()));
        }
        (dir, req.input.clone())
    } else {
        return Err(Failure::new(Exit::Io, anyhow!("{}: no such set directory or scene file", req.input.display())));
    };
    let scene_path = req.scene.clone().unwrap_or(scene_path);
    let set = RaySet::open(&dir).map_err(trace_failure)?;
    let res = (set.meta.resolution[0], set.meta.resolution[1]);
    let options = LoadOptions { preset: req.preset.clone(), resolution: Some(res), ..LoadOptions::default() };
    let scene = pis_scene::load_with(&scene_path, &options)
        .map_err(|e| Failure::new(Exit::Invalid, anyhow!("loading {} (the set's scene; pass --scene): {e}", scene_path.display())))?;
    if set.meta.points.len() != scene.space.point_count() {
        return Err(invalid(format!("{}: the set has {} points, the scene's space {}", dir.display(), set.meta.points.len(), scene.space.point_count())));
    }
    let mut samples = Vec::new();
    let mut frames = Vec::new();
    let mut images = Vec::new();
    for (i, p) in set.meta.points.iter().enumerate() {
        if p.samples != scene.space.point(i) {
            return Err(invalid(format!("{}: point {i} has samples {:?}, expected {:?}", dir.display(), p.samples, scene.space.point(i))));
        }
        let img = set.read_point(i).map_err(trace_failure)?;
        if (img.width, img.height) != res {
            return Err(invalid(format!("{}: point {i} is {}x{}, the set declares {}x{}", dir.display(), img.width, img.height, res.0, res.1)));
        }
        for l in &img.layers {
            if l.width != res.0 || l.height != res.1 {
                return Err(invalid(format!("{}: point {i} layer {} is {}x{}, the set declares {}x{}", dir.display(), l.name, l.width, l.height, res.0, res.1)));
            }
            if let Some(c) = l.planes.iter().position(|p| p.iter().any(|v| !v.is_finite())) {
                return Err(invalid(format!("{}: point {i} layer {} channel {} has NaN or infinite pixels", dir.display(), l.name, l.channels[c])));
            }
        }
        frames.push(scene.frame(&p.samples).map_err(|e| Failure::new(Exit::Invalid, e))?);
        samples.push(p.samples.clone());
        images.push(img);
    }
    let channels = pis_trace::channel_names(&scene);
    stages.done("read", &format!("{} points of {}x{} from {}", samples.len(), res.0, res.1, dir.display()));
    Ok(LoadedSet { dir, scene, resolution: res, samples, frames, images, channels })
}
