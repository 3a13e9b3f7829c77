//! The gold standard beside the player: the ray-traced image (`combined` layer of a
//! ray-traced set, format-spec/RAYSET.md) at the parameter sample nearest to the shown point,
//! as 8-bit sRGB for display.

use std::path::Path;

use pis_format::Dimension;
use pis_trace::set::RaySet;

use crate::cli::{Exit, Failure};

/// A ray-traced set matched to a file's parameter space by dimension name.
pub struct GoldSet {
    set: RaySet,
    /// For each dimension of the set, the index of the file's dimension of that name.
    file_dim: Vec<usize>,
    last: Option<GoldImage>,
}

/// One gold-standard image ready for display.
#[derive(Clone, Debug, PartialEq)]
pub struct GoldImage {
    /// Index of the point in the set.
    pub index: usize,
    /// Sample index per dimension of the set.
    pub samples: Vec<u32>,
    pub width: u32,
    pub height: u32,
    /// sRGB-encoded RGBA, 8 bits per channel, alpha 255, rows from the top.
    pub srgba: Vec<u8>,
}

impl GoldSet {
    /// Opens the set in `dir` and matches its dimensions to `dims` by name (every dimension
    /// of the set must be one of the file's, and the reverse).
    /// Fails with exit code 2 when the set cannot be read, 3 when it is invalid or does not
    /// match the file's space.
    pub fn open(dir: &Path, dims: &[Dimension]) -> Result<GoldSet, Failure> {
        let set = RaySet::open(dir).map_err(|e| {
            let exit = pis_pack::trace_exit(&e);
            Failure::new(exit, anyhow::anyhow!("--set: {e}"))
        })?;
        let file_dim = match_dimensions(&set, dims).map_err(|m| {
            Failure::new(Exit::Invalid, anyhow::anyhow!("--set {}: {m}", dir.display()))
        })?;
        Ok(GoldSet { set, file_dim, last: None })
    }

    /// Index of the set's point nearest to `point` (values of the file's dimensions): per
    /// dimension the nearest sample value, then the point with those samples.
    pub fn nearest(&self, point: &[f32]) -> Option<usize> {
        let want: Vec<u32> = self
            .set
            .meta
            .space
            .iter()
            .zip(&self.file_dim)
            .map(|(d, &k)| {
                let v = point.get(k).copied().unwrap_or(0.0);
                let mut best = 0;
                for (i, s) in d.values.iter().enumerate() {
                    if (s - v).abs() < (d.values[best] - v).abs() {
                        best = i;
                    }
                }
                best as u32
            })
            .collect();
        self.set.meta.points.iter().position(|p| p.samples == want)
    }

    /// The gold-standard image nearest to `point`, read from disk unless it is the last one.
    pub fn image_near(&mut self, point: &[f32]) -> Result<&GoldImage, String> {
        let index = self.nearest(point).ok_or_else(|| {
            format!("{}: no point at the samples nearest to {point:?}", self.set.dir.display())
        })?;
        if self.last.as_ref().is_none_or(|g| g.index != index) {
            let images = self.set.read_point(index).map_err(|e| e.to_string())?;
            let combined = images
                .layer("combined")
                .ok_or_else(|| format!("point {index}: no `combined` layer"))?;
            let n = combined.width as usize * combined.height as usize;
            let mut srgba = vec![255u8; 4 * n];
            for (c, name) in ["R", "G", "B"].iter().enumerate() {
                if let Some(plane) = combined.channel(name) {
                    for (px, &v) in srgba.chunks_exact_mut(4).zip(plane) {
                        px[c] = (pis_eval::metrics::srgb_encode(v) * 255.0 + 0.5) as u8;
                    }
                }
            }
            let samples = self.set.meta.points[index].samples.clone();
            self.last = Some(GoldImage {
                index,
                samples,
                width: combined.width,
                height: combined.height,
                srgba,
            });
        }
        self.last.as_ref().ok_or_else(|| "no image".to_string())
    }

    /// Number of points in the set.
    pub fn len(&self) -> usize {
        self.set.len()
    }

    pub fn is_empty(&self) -> bool {
        self.set.is_empty()
    }
}

/// For each dimension of `set`, the index of the file dimension with its name.
fn match_dimensions(set: &RaySet, dims: &[Dimension]) -> Result<Vec<usize>, String> {
    let names = |v: Vec<&str>| v.join(", ");
    let set_names: Vec<&str> = set.meta.space.iter().map(|d| d.name.as_str()).collect();
    let file_names: Vec<&str> = dims.iter().map(|d| d.name.as_str()).collect();
    if set_names.len() != file_names.len() {
        return Err(format!(
            "the set's dimensions ({}) are not the file's ({})",
            names(set_names),
            names(file_names)
        ));
    }
    set_names
        .iter()
        .map(|n| {
            file_names.iter().position(|f| f == n).ok_or_else(|| {
                format!(
                    "the set's dimension '{n}' is not one of the file's ({})",
                    names(file_names.clone())
                )
            })
        })
        .collect()
}
