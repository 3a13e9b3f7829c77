//! Played frames against the ray-traced gold standard: every sample point of a set drawn
//! through the player (offscreen), PSNR on display values per object and for the whole
//! image.
//!
//! Per object, the measure is pis-pack's prediction's: the pixels the player draws the
//! object at (its object index) that the tracer's coverage says the object covers, against
//! the object's gold surface radiance there (diffuse + specular layers, both stored divided
//! by coverage). The whole image is measured against the set's combined image.

use std::path::Path;

use anyhow::Result;
use pis_play::{FloatImage, Player};

use crate::metrics::SquaredError;

/// Comparison settings.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CompareOptions {
    /// Frame size; default the set's resolution (other sizes are compared after nothing:
    /// the size must equal the set's for pixel-wise PSNR).
    pub size: Option<(u32, u32)>,
}

/// One parameter block of one object.
#[derive(Clone, Debug, PartialEq)]
pub struct BlockScore {
    pub block: usize,
    pub psnr_db: f64,
    pub error: SquaredError,
}

/// One object over all points.
#[derive(Clone, Debug, PartialEq)]
pub struct ObjectScore {
    pub name: String,
    pub psnr_db: f64,
    pub error: SquaredError,
    pub blocks: Vec<BlockScore>,
}

/// One sample point.
#[derive(Clone, Debug, PartialEq)]
pub struct PointComparison {
    pub index: usize,
    pub point: Vec<f32>,
    /// Whole image.
    pub psnr_db: f64,
    pub objects: Vec<ObjectScore>,
}

/// All points.
#[derive(Clone, Debug, PartialEq)]
pub struct Comparison {
    /// Whole image, every point.
    pub psnr_db: f64,
    pub objects: Vec<ObjectScore>,
    pub points: Vec<PointComparison>,
}

/// One drawn frame with its gold image, handed to the caller as it is compared.
pub struct FramePair<'a> {
    pub index: usize,
    pub point: &'a [f32],
    pub rendered: &'a FloatImage,
    pub gold: &'a FloatImage,
    pub object_ids: &'a [u32],
}

/// Draws every sample point of the set at `set_dir` through `player` and compares.
pub fn compare_with_set(player: &mut Player, set_dir: &Path, options: &CompareOptions, each: &mut dyn FnMut(&FramePair)) -> Result<Comparison> {
    let _ = (player, set_dir, options, each);
    anyhow::bail!("not implemented")
}
