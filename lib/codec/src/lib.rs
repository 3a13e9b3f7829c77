//! Level-image codecs for PIS containers.
//!
//! A *level image* is what one pyramid level stores for one parameter sample: a sequence of
//! float planes (one per cube face and stored MIP level), each `width × height × channels`
//! values, row by row from the top, channels interleaved. Every codec takes and returns that
//! sequence as one `f32` slice; the plane shapes come from the container, never from the
//! codestream, so a decoder cannot be told to allocate more than the container declares.
//!
//! Codec ids are part of the file format (format-spec/SPEC.md, "Codecs"). This crate
//! implements `raw` (0) and `lossless` (1); `wavelet` (2) and `dct` (3) are reserved ids that
//! decode to [`CodecError::NotSupported`] until they are implemented.

mod error;
mod lossless;
mod raw;
mod shape;

pub use error::CodecError;
pub use shape::{value_count, PlaneShape};

/// The level-image codecs a container may name (SPEC.md, table "Codec ids").
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum CodecId {
    /// Little-endian IEEE-754 `f32` values, no compression.
    Raw,
    /// Exact: XOR prediction from the left (or upper) neighbour, byte planes, raw DEFLATE.
    Lossless,
    /// Reserved: CDF 9/7 wavelet with an embedded set-partitioning bit stream.
    Wavelet,
    /// Reserved: 8×8 block DCT with a scaled quantization matrix.
    Dct,
}

impl CodecId {
    pub const ALL: [CodecId; 4] = [
        CodecId::Raw,
        CodecId::Lossless,
        CodecId::Wavelet,
        CodecId::Dct,
    ];

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

    pub fn name(self) -> &'static str {
        match self {
            CodecId::Raw => "raw",
            CodecId::Lossless => "lossless",
            CodecId::Wavelet => "wavelet",
            CodecId::Dct => "dct",
        }
    }

    /// True when this build can decode the codec.
    pub fn is_supported(self) -> bool {
        matches!(self, CodecId::Raw | CodecId::Lossless)
    }
}

impl std::fmt::Display for CodecId {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Encodes `values` (the concatenated planes) with `codec`.
pub fn encode(
    codec: CodecId,
    planes: &[PlaneShape],
    values: &[f32],
) -> Result<Vec<u8>, CodecError> {
    let n = value_count(planes)?;
    if values.len() != n {
        return Err(CodecError::Length {
            expected: n,
            found: values.len(),
        });
    }
    match codec {
        CodecId::Raw => Ok(raw::encode(values)),
        CodecId::Lossless => Ok(lossless::encode(planes, values)),
        CodecId::Wavelet | CodecId::Dct => Err(CodecError::NotSupported(codec)),
    }
}

/// Decodes a codestream into the concatenated planes. The output never exceeds the size the
/// shapes declare, and memory grows only as decoded bytes arrive.
pub fn decode(codec: CodecId, planes: &[PlaneShape], bytes: &[u8]) -> Result<Vec<f32>, CodecError> {
    let n = value_count(planes)?;
    match codec {
        CodecId::Raw => raw::decode(n, bytes),
        CodecId::Lossless => lossless::decode(planes, n, bytes),
        CodecId::Wavelet | CodecId::Dct => Err(CodecError::NotSupported(codec)),
    }
}

#[cfg(test)]
mod tests;
