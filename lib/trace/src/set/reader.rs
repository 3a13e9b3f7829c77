//! Reading a ray-traced set.

use super::exr_io::decode_exr;
use super::meta::SetMeta;
use super::{SET_FORMAT, SET_JSON, SET_VERSION};
use crate::error::TraceError;
use crate::layers::{LayerKind, PointImages};
use crate::records::{decode_records, RayRecord};
use std::fs;
use std::path::{Path, PathBuf};

/// Rounding a filtered coverage may show beyond [0, 1].
const COVERAGE_SLACK: f32 = 1e-4;

/// A ray-traced set opened for reading: its metadata, points loaded on demand.
#[derive(Clone, Debug)]
pub struct RaySet {
    pub dir: PathBuf,
    pub meta: SetMeta,
    /// Read the raw layers even where the set holds `denoised.` twins (RAYSET.md 5.4);
    /// by default a layer with a twin reads as the twin.
    pub raw: bool,
}

impl RaySet {
    /// Opens the set in directory `dir` and validates `set.json`.
    /// The scene.toml set.json records (resolved against the set directory), if any.
    pub fn scene_file(&self) -> Option<PathBuf> {
        let f = self.meta.scene_file.as_deref()?;
        Some(self.dir.join(f))
    }

    /// The scene this set is read with when none is named: the scene.toml set.json records
    /// where that file exists, else `scene.toml` inside the set directory.
    pub fn default_scene(&self) -> PathBuf {
        self.scene_file().filter(|p| p.is_file()).unwrap_or_else(|| self.dir.join("scene.toml"))
    }

    pub fn open(dir: impl AsRef<Path>) -> Result<RaySet, TraceError> {
        let dir = dir.as_ref().to_path_buf();
        let path = dir.join(SET_JSON);
        let bytes = fs::read(&path).map_err(|e| TraceError::io(&path, e))?;
        let meta: SetMeta = serde_json::from_slice(&bytes)
            .map_err(|e| TraceError::InvalidSet { path: path.clone(), message: e.to_string() })?;
        let bad = |message: String| TraceError::InvalidSet { path: path.clone(), message };
        if meta.format != SET_FORMAT {
            return Err(bad(format!(
                "field `format` is {:?}, expected {SET_FORMAT:?}",
                meta.format
            )));
        }
        if meta.version != SET_VERSION {
            return Err(bad(format!(
                "field `version` is {}, only {SET_VERSION} is supported",
                meta.version
            )));
        }
        if meta.resolution[0] == 0 || meta.resolution[1] == 0 {
            return Err(bad(format!("field `resolution` is {:?}: no pixels", meta.resolution)));
        }
        for o in &meta.objects {
            if let Some(l) = o.layers.iter().find(|l| LayerKind::from_name(l).is_none()) {
                return Err(bad(format!("object {:?}: unknown layer {l:?}", o.name)));
            }
        }
        for (i, p) in meta.points.iter().enumerate() {
            if p.samples.len() != meta.space.len() || p.values.len() != meta.space.len() {
                return Err(bad(format!(
                    "points[{i}]: {} samples for {} dimensions",
                    p.samples.len(),
                    meta.space.len()
                )));
            }
            if p.objects.len() != meta.objects.len() {
                return Err(bad(format!(
                    "points[{i}]: {} object placements for {} objects",
                    p.objects.len(),
                    meta.objects.len()
                )));
            }
            if p.image.contains(['/', '\\'])
                || p.rays.as_deref().is_some_and(|r| r.contains(['/', '\\']))
            {
                return Err(bad(format!(
                    "points[{i}]: file names must not contain path separators"
                )));
            }
            for (k, (d, (&s, &v))) in
                meta.space.iter().zip(p.samples.iter().zip(&p.values)).enumerate()
            {
                let Some(&want) = d.values.get(s as usize) else {
                    return Err(bad(format!(
                        "points[{i}].samples[{k}] is {s}; dimension `{}` has {} samples",
                        d.name,
                        d.values.len()
                    )));
                };
                if !v.is_finite() || (v - want).abs() > 1e-4 * want.abs().max(1.0) {
                    return Err(bad(format!(
                        "points[{i}].values[{k}] is {v}; sample {s} of dimension `{}` is {want}",
                        d.name
                    )));
                }
            }
        }
        Ok(RaySet { dir, meta, raw: false })
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.meta.points.len()
    }

    /// True when the set has no points.
    pub fn is_empty(&self) -> bool {
        self.meta.points.is_empty()
    }

    /// The same set, read raw (`raw`) or with its denoised twins where it has them.
    pub fn with_raw(mut self, raw: bool) -> RaySet {
        self.raw = raw;
        self
    }

    /// Whether the points hold denoised twins of their layers.
    pub fn is_denoised(&self) -> bool {
        self.meta.points.iter().any(|p| p.denoise.as_ref().is_some_and(|d| !d.layers.is_empty()))
    }

    /// Reads the images of the `i`-th entry of `points` and checks their size and that every
    /// layer set.json lists is present. A layer with a `denoised.` twin reads as the twin
    /// unless the set is read raw ([`RaySet::raw`]); the twins themselves are not listed.
    pub fn read_point(&self, i: usize) -> Result<PointImages, TraceError> {
        let p = self.point_meta(i)?;
        let path = self.dir.join(&p.image);
        let bytes = fs::read(&path).map_err(|e| TraceError::io(&path, e))?;
        let mut images = decode_exr(&bytes, &path)?;
        if self.raw {
            crate::denoise::drop_denoised(&mut images);
        } else {
            crate::denoise::prefer_denoised(&mut images);
        }
        let bad = |message: String| TraceError::InvalidSet { path: path.clone(), message };
        if [images.width, images.height] != self.meta.resolution {
            return Err(bad(format!(
                "image is {}x{}, set.json says {}x{}",
                images.width, images.height, self.meta.resolution[0], self.meta.resolution[1]
            )));
        }
        if images.layer("combined").is_none() {
            return Err(bad("layer `combined` is missing".into()));
        }
        for o in &self.meta.objects {
            for l in &o.layers {
                let name = format!("object.{}.{l}", o.channel_name);
                let want = LayerKind::from_name(l).map_or(&[][..], |k| k.channels());
                match images.layer(&name) {
                    Some(img) if want.iter().all(|c| img.channel(c).is_some()) => {}
                    _ => return Err(bad(format!("layer `{name}` (channels {want:?}) is missing"))),
                }
            }
        }
        // Pixels are finite, coverage a fraction (section 4).
        for layer in &images.layers {
            let coverage = layer.name.ends_with(".coverage");
            for (c, plane) in layer.channels.iter().zip(&layer.planes) {
                if let Some(k) = plane.iter().position(|v| !v.is_finite()) {
                    return Err(bad(format!(
                        "layer `{}` channel {c}: pixel {k} is {}",
                        layer.name, plane[k]
                    )));
                }
                if coverage {
                    if let Some(k) = plane
                        .iter()
                        .position(|v| !(-COVERAGE_SLACK..=1.0 + COVERAGE_SLACK).contains(v))
                    {
                        return Err(bad(format!(
                            "layer `{}` channel {c}: pixel {k} covers {}, outside [0, 1]",
                            layer.name, plane[k]
                        )));
                    }
                }
            }
        }
        Ok(images)
    }

    /// Reads the ray records of the `i`-th entry of `points` (empty when it has none).
    pub fn read_records(&self, i: usize) -> Result<Vec<RayRecord>, TraceError> {
        let p = self.point_meta(i)?;
        let Some(name) = &p.rays else { return Ok(Vec::new()) };
        let path = self.dir.join(name);
        let bytes = fs::read(&path).map_err(|e| TraceError::io(&path, e))?;
        let records = decode_records(&bytes, &path)?;
        if let Some(r) = records.iter().find(|r| r.object as usize >= self.meta.objects.len()) {
            return Err(TraceError::InvalidSet {
                path,
                message: format!(
                    "record names object {} but the set has {}",
                    r.object,
                    self.meta.objects.len()
                ),
            });
        }
        Ok(records)
    }

    fn point_meta(&self, i: usize) -> Result<&super::meta::PointMeta, TraceError> {
        self.meta.points.get(i).ok_or_else(|| TraceError::InvalidSet {
            path: self.dir.join(SET_JSON),
            message: format!("point {i} requested, the set has {}", self.meta.points.len()),
        })
    }
}
