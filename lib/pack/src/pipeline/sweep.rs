//! One set loaded and inferred once, packed at many settings: the rate–distortion sweeps of
//! `pis-bench` encode and predict without writing a file per point.

use std::time::Instant;

use serde::Serialize;

use super::encode::encode_all;
use super::infer_layers::infer_all;
use super::input::{load, LoadedSet};
use super::model::ObjectModel;
use super::packed::LayerTextures;
use super::plan::Plan;
use super::predict::{decoded_textures, predicted_psnr, solved_chains};
use super::{PackRequest, Stages};
use crate::error::{Exit, Failure};

/// A loaded set and its inferred textures under one request's inference settings (layers,
/// filter, texture size, iteration cap).
pub struct Inferred {
    pub set: LoadedSet,
    /// The blocks, space and staggering the models were inferred for, resolved once.
    pub plan: Plan,
    pub models: Vec<ObjectModel>,
    /// Wall-clock milliseconds of loading and of inference.
    pub load_ms: f64,
    pub infer_ms: f64,
}

/// One packed point of a sweep.
#[derive(Clone, Debug, Serialize)]
pub struct PackPoint {
    /// Bytes of the level images (what the target ratio counts, thesis 4.8).
    pub texture_bytes: usize,
    /// Bytes of the whole container (geometry, tables and headers included).
    pub file_bytes: usize,
    pub raw_image_bytes: u64,
    /// Predicted PSNR through the hardware model over covered pixels, decoded textures.
    pub psnr_db: f64,
    /// The same with the textures as solved.
    pub psnr_db_solved: f64,
    /// Pyramids, allocation, encoding and prediction.
    pub encode_ms: f64,
}

impl PackPoint {
    /// Raw image bytes / level-image bytes.
    pub fn ratio(&self) -> f64 {
        self.raw_image_bytes as f64 / self.texture_bytes.max(1) as f64
    }

    /// Raw image bytes / container bytes.
    pub fn file_ratio(&self) -> f64 {
        self.raw_image_bytes as f64 / self.file_bytes.max(1) as f64
    }
}

impl Inferred {
    /// Loads (or traces) the set of `req` and infers every object's layers, telling
    /// `progress`.
    pub fn new(req: &PackRequest, progress: &dyn super::Progress) -> Result<Inferred, Failure> {
        let mut stages = Stages::new(progress);
        let t = Instant::now();
        let set = load(req, &mut stages)?;
        let load_ms = t.elapsed().as_secs_f64() * 1e3;
        let t = Instant::now();
        let plan = Plan::new(&set, req).map_err(|e| Failure::new(Exit::Usage, e))?;
        let mut matrices = super::matrices::Matrices::open(req.matrix, req.filter)?;
        if let Some(device) = matrices.device() {
            stages.note(&format!("probe mode on {device}"));
        }
        let inferred = infer_all(&set, req, &plan, &mut matrices, &mut stages)
            .map_err(|e| Failure::new(Exit::Runtime, e))?;
        // `auto` chooses once, for the request's own target.
        let (models, _) = super::choice::choose(&set, inferred, &plan, req, &mut stages)?;
        let infer_ms = t.elapsed().as_secs_f64() * 1e3;
        Ok(Inferred { set, plan, models, load_ms, infer_ms })
    }

    /// Parameter points of the set.
    pub fn points(&self) -> usize {
        self.set.samples.len()
    }

    /// Raw image bytes of the set (3 bytes per pixel).
    pub fn raw_image_bytes(&self) -> u64 {
        self.set.raw_image_bytes()
    }

    /// Total conjugate-gradient iterations of every solve.
    pub fn solver_iterations(&self) -> u64 {
        self.models.iter().flat_map(|m| &m.layers).map(|l| l.iterations).sum()
    }

    /// Encodes with `req`'s codec, pyramid and target (its inference settings are ignored)
    /// and predicts the PSNR, writing nothing.
    pub fn pack_point(&self, req: &PackRequest) -> Result<PackPoint, Failure> {
        let t = Instant::now();
        let mut stages = Stages::quiet();
        let packed = encode_all(&self.set, &self.models, &self.aiming_at(req), req, &mut stages)?;
        let file_bytes = pis_format::to_bytes_unchecked(&packed.container).len();
        let q = predicted_psnr(&self.set, &self.models, &packed)
            .map_err(|e| Failure::new(Exit::Runtime, e))?;
        Ok(PackPoint {
            texture_bytes: packed.layer_bytes.iter().flatten().sum(),
            file_bytes,
            raw_image_bytes: self.set.raw_image_bytes(),
            psnr_db: q.overall,
            psnr_db_solved: q.overall_solved,
            encode_ms: t.elapsed().as_secs_f64() * 1e3,
        })
    }

    /// The textures as solved (MIP chains rebuilt by decimation, as the player does), per
    /// object model and layer.
    pub fn solved(&self) -> anyhow::Result<Vec<Vec<LayerTextures>>> {
        self.models.iter().map(solved_chains).collect()
    }

    /// The textures after encoding with `req`'s codec, pyramid and target and decoding.
    pub fn decoded(&self, req: &PackRequest) -> Result<(Vec<Vec<LayerTextures>>, usize), Failure> {
        let mut stages = Stages::quiet();
        let packed = encode_all(&self.set, &self.models, &self.aiming_at(req), req, &mut stages)?;
        let bytes = packed.layer_bytes.iter().flatten().sum();
        Ok((
            decoded_textures(&self.models, &packed).map_err(|e| Failure::new(Exit::Runtime, e))?,
            bytes,
        ))
    }

    /// Encodes with `req`'s codec, pyramid and target and writes the container to
    /// `req.output` (atomically); returns the file's bytes.
    pub fn write(&self, req: &PackRequest) -> Result<u64, Failure> {
        let mut stages = Stages::quiet();
        let packed = encode_all(&self.set, &self.models, &self.aiming_at(req), req, &mut stages)?;
        Ok(pis_format::write(&req.output, &packed.container)?)
    }

    /// The plan of the inference aiming at `req`'s target (its blocks and staggering are the
    /// inference's).
    fn aiming_at(&self, req: &PackRequest) -> Plan {
        self.plan.aiming_at(req.target, self.set.raw_image_bytes())
    }

    /// The set's directory.
    pub fn set_dir(&self) -> &std::path::Path {
        &self.set.dir
    }
}
