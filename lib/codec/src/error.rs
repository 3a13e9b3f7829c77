use crate::CodecId;

/// Why a level image could not be encoded or decoded.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum CodecError {
    #[error("codec '{0}' is reserved but not implemented in this build")]
    NotSupported(CodecId),
    #[error("plane shape {width}×{height}×{channels} is empty or too large")]
    Shape { width: u32, height: u32, channels: u32 },
    #[error("expected {expected} values, found {found}")]
    Length { expected: usize, found: usize },
    #[error("codestream decodes to {found} bytes, expected {expected}")]
    DecodedLength { expected: usize, found: usize },
    #[error("cannot encode: {0}")]
    Input(String),
    #[error("codestream is corrupt: {0}")]
    Corrupt(String),
    /// The codestream's data ends before its last byte (SPEC.md 11, rule 8008).
    #[error("codestream has {extra} bytes after the end of its data ({length} bytes in all)")]
    TrailingBytes { extra: usize, length: usize },
}
