//! Codec 0, `raw`: the values as little-endian IEEE-754 `f32`.

use crate::CodecError;

pub fn encode(values: &[f32]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_le_bytes()).collect()
}

pub fn decode(n: usize, bytes: &[u8]) -> Result<Vec<f32>, CodecError> {
    if bytes.len() != n * 4 {
        return Err(CodecError::DecodedLength { expected: n * 4, found: bytes.len() });
    }
    Ok(bytes.chunks_exact(4).map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect())
}
