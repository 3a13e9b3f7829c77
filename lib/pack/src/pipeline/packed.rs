//! A pack's coded result, what encoding hands the prediction, the report and the checks:
//! the container, each layer's coded blocks and bytes, and the predicted quality.

use std::collections::BTreeMap;

use pis_format::Container;

use super::storage::CodedLevel;

/// Linear textures of one layer, keyed like [`super::model::InferredLayer::textures`].
pub type LayerTextures = std::collections::BTreeMap<Vec<u32>, Vec<f32>>;

/// One block of one layer as coded: which layer sample each block-local sample is, and the
/// level images (gamma-compensated residuals) with their codestreams.
#[derive(Clone)]
pub struct PackedBlock {
    pub extent: Vec<u32>,
    /// Per block-local sample (row-major over the extent), the layer key.
    pub keys: Vec<Vec<u32>>,
    /// Per level: counts, images as encoded, codestreams.
    pub levels: Vec<CodedLevel>,
}

/// The container and what the report and checks need to know about it.
#[derive(Clone)]
pub struct Packed {
    pub container: Container,
    /// Per object model, per layer, per block.
    pub blocks: Vec<Vec<Vec<PackedBlock>>>,
    /// Bytes of everything but the level images.
    pub overhead: usize,
    /// Per object model, per layer: codestream bytes.
    pub layer_bytes: Vec<Vec<usize>>,
    pub stagger: Vec<Vec<u32>>,
    /// Per object model, per layer: each layer sample's screen weights, by key, kept for
    /// the master (empty without screen-error allocation or `--keep-master`; the
    /// allocation reads them from the pyramids).
    pub screen_weights: Vec<Vec<BTreeMap<Vec<u32>, Vec<f32>>>>,
    /// Per object model: the solved textures' squared display error against the traced
    /// images and the number of values it sums ([`super::predict::display_error`]).
    pub solved_error: Vec<(f64, usize)>,
    /// With [`super::MaxMse::Best`], where the constraint changed the allocation: which
    /// allocation was kept and why.
    pub max_mse: Option<MaxMseChoice>,
    /// The prediction made while choosing the allocation, which [`super::predict::predicted_psnr`] returns
    /// instead of rendering the same textures again.
    pub quality: Option<Quality>,
    /// Under a played-quality target: the search's trials and the one kept.
    pub played: Option<super::played::Played>,
}

/// The choice between the max-MSE constrained and the free allocation.
#[derive(Clone, Debug, PartialEq)]
pub struct MaxMseChoice {
    pub alpha: f64,
    /// The constrained allocation was kept.
    pub constrained: bool,
    /// Predicted PSNR (dB) of each.
    pub psnr_db_constrained: f64,
    pub psnr_db_free: f64,
}

/// Predicted quality: per object (decoded, as solved) and overall, plus the largest
/// difference between decoded and solved finest texels.
#[derive(Clone)]
pub struct Quality {
    pub objects: Vec<(f64, f64)>,
    pub overall: f64,
    pub overall_solved: f64,
    pub max_texel_error: f32,
}
