//! The 8-byte header that starts every `wavelet` and `dct` codestream (SPEC.md section 11):
//! version, a codec parameter, the colour flag, a second codec parameter, and a positive
//! `f32` scale. What the two parameters and the scale mean is each codec's business.

use crate::CodecError;

/// Codestream format version (header byte 0).
pub const VERSION: u8 = 1;
/// Header bytes of every lossy codestream.
pub const HEADER_LEN: usize = 8;

/// A parsed header.
pub(crate) struct LossyHeader {
    /// Byte 1.
    pub param: u8,
    /// Byte 2: the opponent colour transform is applied.
    pub colour: bool,
    /// Byte 3.
    pub param2: u8,
    /// Bytes 4..8: finite and positive.
    pub scale: f32,
}

/// Parses the header of a non-empty codestream; `scale_name` names bytes 4..8 in errors.
pub(crate) fn read(bytes: &[u8], scale_name: &str) -> Result<LossyHeader, CodecError> {
    if bytes.len() < HEADER_LEN {
        return Err(CodecError::Corrupt(format!(
            "{} bytes, shorter than the {HEADER_LEN}-byte header",
            bytes.len()
        )));
    }
    if bytes[0] != VERSION {
        return Err(CodecError::Corrupt(format!("version {} is not 1", bytes[0])));
    }
    let colour = match bytes[2] {
        0 => false,
        1 => true,
        f => return Err(CodecError::Corrupt(format!("flags {f:#04x}"))),
    };
    let scale = f32::from_le_bytes([bytes[4], bytes[5], bytes[6], bytes[7]]);
    if !(scale.is_finite() && scale > 0.0) {
        return Err(CodecError::Corrupt(format!("{scale_name} {scale}")));
    }
    Ok(LossyHeader { param: bytes[1], colour, param2: bytes[3], scale })
}
