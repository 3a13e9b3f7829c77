//! The parameter point the comparison is made at: the set's (or a freshly traced) images
//! there, and an object's coverage and surface radiance in them.

use std::time::Instant;

use anyhow::{anyhow, bail, Context, Result};
use pis_scene::{Frame, LoadOptions, Scene};
use pis_trace::layers::LayerKind;
use pis_trace::{PointImages, TraceSettings};

use super::InferRequest;

/// The scene at the point, its frame and traced images, its samples and values, the trace
/// settings and how long tracing took (0 for a set's point).
pub struct Point {
    pub scene: Scene,
    pub frame: Frame,
    pub images: PointImages,
    pub samples: Vec<u32>,
    pub values: Vec<f32>,
    pub settings: TraceSettings,
    pub trace_ms: f64,
}

/// The samples nearest `at` (default: the middle sample of every dimension).
fn nearest_samples(scene: &Scene, at: Option<&[f32]>) -> Result<Vec<u32>> {
    let dims = &scene.space.dims;
    match at {
        None => Ok(dims.iter().map(|d| d.samples() / 2).collect()),
        Some(v) => {
            if v.len() != dims.len() {
                bail!(
                    "--at gives {} values, the parameter space has {} dimensions ({})",
                    v.len(),
                    dims.len(),
                    dims.iter().map(|d| d.name.as_str()).collect::<Vec<_>>().join(", ")
                );
            }
            Ok(dims
                .iter()
                .zip(v)
                .map(|(d, &x)| {
                    d.values
                        .iter()
                        .enumerate()
                        .min_by(|a, b| (a.1 - x).abs().total_cmp(&(b.1 - x).abs()))
                        .map_or(0, |(i, _)| i as u32)
                })
                .collect())
        }
    }
}

/// The point `req` names, read from its set or traced from its scene.
pub fn load_point(req: &InferRequest) -> Result<Point> {
    let is_set = req.input.is_dir();
    if is_set {
        let set = pis_trace::set::RaySet::open(&req.input)?;
        let scene_path = req.scene.clone().unwrap_or_else(|| set.default_scene());
        let res = (set.meta.resolution[0], set.meta.resolution[1]);
        let options = LoadOptions { resolution: Some(res), ..LoadOptions::default() };
        let scene = pis_scene::load_with(&scene_path, &options).with_context(|| {
            format!("loading {} (the set's scene; pass --scene)", scene_path.display())
        })?;
        let samples = nearest_samples(&scene, req.at.as_deref())?;
        let index = set
            .meta
            .points
            .iter()
            .position(|p| p.samples == samples)
            .ok_or_else(|| anyhow!("the set has no point at samples {samples:?}"))?;
        let images = set.read_point(index)?;
        let frame = scene.frame(&samples)?;
        let values = set.meta.points[index].values.clone();
        let mut settings = TraceSettings::new(res, set.meta.spp.max(1));
        settings.filter = set.meta.filter;
        Ok(Point { scene, frame, images, samples, values, settings, trace_ms: 0.0 })
    } else {
        let options =
            LoadOptions { preset: req.preset.clone(), resolution: req.resolution, spp: req.spp };
        let scene = pis_scene::load_with(&req.input, &options)?;
        let samples = nearest_samples(&scene, req.at.as_deref())?;
        let frame = scene.frame(&samples)?;
        let values =
            scene.space.dims.iter().zip(&samples).map(|(d, &s)| d.values[s as usize]).collect();
        let settings = TraceSettings::new(scene.resolution, scene.spp);
        let t = Instant::now();
        let render = pis_trace::render_point(&scene, &frame, &settings, &|| {})?;
        let trace_ms = t.elapsed().as_secs_f64() * 1e3;
        Ok(Point { scene, frame, images: render.images, samples, values, settings, trace_ms })
    }
}

/// Per pixel: coverage and the object's surface radiance (diffuse + specular).
pub fn object_layer(images: &PointImages, channel: &str) -> Result<(Vec<f32>, Vec<f32>)> {
    let get = |k: LayerKind| {
        images
            .object_layer(channel, k)
            .ok_or_else(|| anyhow!("the point has no {} layer for object {channel}", k.name()))
    };
    let cov = get(LayerKind::Coverage)?
        .channel("A")
        .ok_or_else(|| anyhow!("coverage without A"))?
        .to_vec();
    let (d, s) = (get(LayerKind::Diffuse)?, get(LayerKind::Specular)?);
    let n = cov.len();
    let mut rgb = vec![0.0f32; n * 3];
    for (c, name) in ["R", "G", "B"].iter().enumerate() {
        let (dp, sp) = (d.channel(name), s.channel(name));
        for k in 0..n {
            rgb[k * 3 + c] = dp.map_or(0.0, |p| p[k]) + sp.map_or(0.0, |p| p[k]);
        }
    }
    Ok((cov, rgb))
}
