//! Level-image codecs for PIS containers.
//!
//! A *level image* is what one pyramid level stores for one parameter sample: a sequence of
//! float planes (one per cube face and stored MIP level), each `width × height × channels`
//! values, row by row from the top, channels interleaved. Every codec takes and returns that
//! sequence as one `f32` slice; the plane shapes come from the container, never from the
//! codestream, so a decoder cannot be told to allocate more than the container declares.
//!
//! Codec ids are part of the file format (format-spec/SPEC.md, "Codecs"). Every codec sits
//! behind the [`LevelCodec`] trait and is found by id with [`codec`]: `raw` (0), `lossless`
//! (1), `wavelet` (2: CDF 9/7 with an embedded bit-plane stream, [`wavelet`]) and `dct`
//! (3: 8×8 block DCT, [`dct`]). The lossy codecs take a [`Rate`] and give a
//! rate–distortion curve ([`RdCurve`]).
//!
//! Beside the codecs, the crate holds what turns a block of textures into level images and
//! bytes: the adaptive Laplacian pyramid over parameter space ([`pyramid`], thesis 4.3),
//! storage allocation by equal slopes ([`allocate`], thesis 4.5) and gamma compensation
//! ([`gamma`], thesis 4.6); and the display values PSNR is measured on ([`display`]).

pub mod allocate;
mod arith;
mod colour;
pub mod dct;
pub mod display;
mod error;
pub mod gamma;
mod lossless;
mod lossy_header;
pub mod pyramid;
mod raw;
mod rd;
mod shape;
pub mod wavelet;

pub use error::CodecError;
pub use rd::{Rate, RdCurve, RdPoint};
pub use shape::{value_count, PlaneShape};

/// The level-image codecs a container may name (SPEC.md, table "Codec ids").
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum CodecId {
    /// Little-endian IEEE-754 `f32` values, no compression.
    Raw,
    /// Exact: XOR prediction from the left (or upper) neighbour, byte planes, raw DEFLATE.
    Lossless,
    /// CDF 9/7 wavelet with an embedded, arithmetic-coded bit-plane stream.
    Wavelet,
    /// 8×8 block DCT with a quantization matrix scaled by a quality factor.
    Dct,
}

impl CodecId {
    pub const ALL: [CodecId; 4] = [CodecId::Raw, CodecId::Lossless, CodecId::Wavelet, CodecId::Dct];

    /// The id stored in the file.
    pub fn code(self) -> u16 {
        match self {
            CodecId::Raw => 0,
            CodecId::Lossless => 1,
            CodecId::Wavelet => 2,
            CodecId::Dct => 3,
        }
    }

    pub fn from_code(code: u16) -> Option<Self> {
        Self::ALL.into_iter().find(|c| c.code() == code)
    }

    /// The name the tools take (`--codec`) and print.
    pub fn name(self) -> &'static str {
        match self {
            CodecId::Raw => "raw",
            CodecId::Lossless => "lossless",
            CodecId::Wavelet => "wavelet",
            CodecId::Dct => "dct",
        }
    }

    /// The codec named `name`, if any.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|c| c.name() == name)
    }

    /// True when this build can decode the codec (every defined id in this build).
    pub fn is_supported(self) -> bool {
        codec(self).is_some()
    }

    /// True for codecs whose decoded values differ from the encoded ones.
    pub const fn is_lossy(self) -> bool {
        matches!(self, CodecId::Wavelet | CodecId::Dct)
    }
}

impl std::fmt::Display for CodecId {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for CodecId {
    type Err = UnknownCodec;

    fn from_str(s: &str) -> Result<Self, UnknownCodec> {
        CodecId::from_name(s).ok_or_else(|| UnknownCodec(s.to_string()))
    }
}

/// A codec name that is none of [`CodecId::ALL`]'s; its message lists those.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct UnknownCodec(pub String);

impl std::fmt::Display for UnknownCodec {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let names: Vec<&str> = CodecId::ALL.iter().map(|c| c.name()).collect();
        write!(f, "unknown codec {:?} ({})", self.0, names.join(", "))
    }
}

impl std::error::Error for UnknownCodec {}

/// A level-image codec. Implementations check `values.len()` against the shapes, take
/// signed float data, and never trust the codestream for sizes.
pub trait LevelCodec: Sync {
    /// The id stored in the file.
    fn id(&self) -> CodecId;
    /// Encodes the concatenated planes; exact codecs ignore `rate`.
    fn encode(
        &self,
        planes: &[PlaneShape],
        values: &[f32],
        rate: Rate,
    ) -> Result<Vec<u8>, CodecError>;
    /// Decodes into the concatenated planes. Damaged input gives an error or an image, never
    /// a panic; memory is bounded by a small multiple of the size the shapes declare.
    fn decode(&self, planes: &[PlaneShape], bytes: &[u8]) -> Result<Vec<f32>, CodecError>;
    /// Measured rate–distortion curve of `values`: for `wavelet` from one encode, decoded at
    /// [`wavelet::CURVE_POINTS`] truncation points (the dense estimate of every truncation
    /// point is [`wavelet::Encoded::curve`]), for `dct` at
    /// [`dct::CURVE_QUALITIES`], for exact codecs one point at zero error.
    fn rd_curve(&self, planes: &[PlaneShape], values: &[f32]) -> Result<RdCurve, CodecError> {
        self.rd_curve_weighted(planes, values, None)
    }
    /// [`LevelCodec::rd_curve`] with the error of each value weighted: the curve's `mse` is
    /// `Σ wᵢ (xᵢ − x̂ᵢ)² / n` ([`weighted_mse`]; weights of mean 1 keep the scale of the
    /// plain MSE). A writer passes how much each value shows on screen, so that storage goes
    /// where the error is seen (thesis 4.5). `None`: every value weighs 1.
    fn rd_curve_weighted(
        &self,
        planes: &[PlaneShape],
        values: &[f32],
        weights: Option<&[f32]>,
    ) -> Result<RdCurve, CodecError> {
        check_weights(values, weights)?;
        let bytes = self.encode(planes, values, Rate::Default)?;
        Ok(RdCurve { points: vec![RdPoint { bytes: bytes.len(), mse: 0.0 }] })
    }
}

/// Weights, when given, are one finite non-negative value per value.
fn check_weights(values: &[f32], weights: Option<&[f32]>) -> Result<(), CodecError> {
    if let Some(w) = weights {
        if w.len() != values.len() {
            return Err(CodecError::Length { expected: values.len(), found: w.len() });
        }
        if w.iter().any(|v| !(v.is_finite() && *v >= 0.0)) {
            return Err(CodecError::Input("error weights must be finite and non-negative".into()));
        }
    }
    Ok(())
}

struct RawCodec;
struct LosslessCodec;
struct WaveletCodec;
struct DctCodec;

fn check_len(planes: &[PlaneShape], values: &[f32]) -> Result<usize, CodecError> {
    let n = value_count(planes)?;
    if values.len() != n {
        return Err(CodecError::Length { expected: n, found: values.len() });
    }
    Ok(n)
}

impl LevelCodec for RawCodec {
    fn id(&self) -> CodecId {
        CodecId::Raw
    }
    fn encode(
        &self,
        planes: &[PlaneShape],
        values: &[f32],
        _: Rate,
    ) -> Result<Vec<u8>, CodecError> {
        check_len(planes, values)?;
        Ok(raw::encode(values))
    }
    fn decode(&self, planes: &[PlaneShape], bytes: &[u8]) -> Result<Vec<f32>, CodecError> {
        raw::decode(value_count(planes)?, bytes)
    }
}

impl LevelCodec for LosslessCodec {
    fn id(&self) -> CodecId {
        CodecId::Lossless
    }
    fn encode(
        &self,
        planes: &[PlaneShape],
        values: &[f32],
        _: Rate,
    ) -> Result<Vec<u8>, CodecError> {
        check_len(planes, values)?;
        Ok(lossless::encode(planes, values))
    }
    fn decode(&self, planes: &[PlaneShape], bytes: &[u8]) -> Result<Vec<f32>, CodecError> {
        lossless::decode(planes, value_count(planes)?, bytes)
    }
}

impl LevelCodec for WaveletCodec {
    fn id(&self) -> CodecId {
        CodecId::Wavelet
    }
    fn encode(
        &self,
        planes: &[PlaneShape],
        values: &[f32],
        rate: Rate,
    ) -> Result<Vec<u8>, CodecError> {
        wavelet::encode(planes, values, rate)
    }
    fn decode(&self, planes: &[PlaneShape], bytes: &[u8]) -> Result<Vec<f32>, CodecError> {
        wavelet::decode(planes, bytes)
    }
    fn rd_curve_weighted(
        &self,
        planes: &[PlaneShape],
        values: &[f32],
        weights: Option<&[f32]>,
    ) -> Result<RdCurve, CodecError> {
        check_weights(values, weights)?;
        let e =
            wavelet::encode_full(planes, values, wavelet::DEFAULT_LEVELS, wavelet::DEFAULT_BITS)?;
        Ok(e.measured_curve_weighted(planes, values, weights, wavelet::CURVE_POINTS)?.monotone())
    }
}

impl LevelCodec for DctCodec {
    fn id(&self) -> CodecId {
        CodecId::Dct
    }
    fn encode(
        &self,
        planes: &[PlaneShape],
        values: &[f32],
        rate: Rate,
    ) -> Result<Vec<u8>, CodecError> {
        dct::encode(planes, values, rate)
    }
    fn decode(&self, planes: &[PlaneShape], bytes: &[u8]) -> Result<Vec<f32>, CodecError> {
        dct::decode(planes, bytes)
    }
    fn rd_curve_weighted(
        &self,
        planes: &[PlaneShape],
        values: &[f32],
        weights: Option<&[f32]>,
    ) -> Result<RdCurve, CodecError> {
        check_weights(values, weights)?;
        dct::rd_curve_weighted(planes, values, weights, &dct::CURVE_QUALITIES)
    }
}

/// The codec registered for `id`, or `None` when this build cannot decode it.
pub fn codec(id: CodecId) -> Option<&'static dyn LevelCodec> {
    match id {
        CodecId::Raw => Some(&RawCodec),
        CodecId::Lossless => Some(&LosslessCodec),
        CodecId::Wavelet => Some(&WaveletCodec),
        CodecId::Dct => Some(&DctCodec),
    }
}

fn registered(id: CodecId) -> Result<&'static dyn LevelCodec, CodecError> {
    codec(id).ok_or(CodecError::NotSupported(id))
}

/// Encodes `values` (the concatenated planes) with `codec` at its default rate.
pub fn encode(
    codec: CodecId,
    planes: &[PlaneShape],
    values: &[f32],
) -> Result<Vec<u8>, CodecError> {
    encode_with(codec, planes, values, Rate::Default)
}

/// Encodes `values` with `codec` at `rate`.
pub fn encode_with(
    codec: CodecId,
    planes: &[PlaneShape],
    values: &[f32],
    rate: Rate,
) -> Result<Vec<u8>, CodecError> {
    registered(codec)?.encode(planes, values, rate)
}

/// Decodes a codestream into the concatenated planes. The output never exceeds the size the
/// shapes declare.
pub fn decode(codec: CodecId, planes: &[PlaneShape], bytes: &[u8]) -> Result<Vec<f32>, CodecError> {
    registered(codec)?.decode(planes, bytes)
}

/// Mean squared error per value between two equally long slices.
pub fn mse(a: &[f32], b: &[f32]) -> f64 {
    let s: f64 = a.iter().zip(b).map(|(x, y)| (*x as f64 - *y as f64).powi(2)).sum();
    s / a.len().max(1) as f64
}

/// `Σ wᵢ (aᵢ − bᵢ)² / n`: the mean squared error with each value's error weighted by
/// `weights` (plain [`mse`] when `None`).
pub fn weighted_mse(a: &[f32], b: &[f32], weights: Option<&[f32]>) -> f64 {
    let Some(w) = weights else {
        return mse(a, b);
    };
    let s: f64 =
        a.iter().zip(b).zip(w).map(|((x, y), w)| *w as f64 * (*x as f64 - *y as f64).powi(2)).sum();
    s / a.len().max(1) as f64
}

/// PSNR in dB of a mean squared error for a signal peak.
pub fn psnr(mse: f64, peak: f64) -> f64 {
    10.0 * (peak * peak / mse.max(1e-300)).log10()
}

#[cfg(test)]
mod tests;
