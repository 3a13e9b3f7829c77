//! Codec 1, `lossless`: exact round trip of every `f32` bit pattern.
//!
//! 1. Prediction: within each plane, each value's bit pattern is XORed with the bit pattern of
//!    the same channel of its left neighbour; the first value of a row uses the value above;
//!    the first value of a plane uses 0.
//! 2. Byte planes: the residuals' most significant bytes, then the next bytes, down to the
//!    least significant bytes (4 runs of n bytes).
//! 3. Raw DEFLATE (RFC 1951) of those 4n bytes. The DEFLATE stream is the whole codestream:
//!    bytes after its final block make the codestream invalid (SPEC.md 11.1, rule 8008).

use std::io::{Read, Write};

use flate2::{read::DeflateDecoder, write::DeflateEncoder, Compression};

use crate::{CodecError, PlaneShape};

pub fn encode(planes: &[PlaneShape], values: &[f32]) -> Vec<u8> {
    let n = values.len();
    let mut residual = vec![0u32; n];
    let mut start = 0;
    for p in planes {
        let len = (p.width * p.height * p.channels) as usize;
        predict(p, &values[start..start + len], &mut residual[start..start + len]);
        start += len;
    }
    let mut shuffled = vec![0u8; 4 * n];
    for (i, r) in residual.iter().enumerate() {
        let b = r.to_be_bytes();
        for (k, byte) in b.iter().enumerate() {
            shuffled[k * n + i] = *byte;
        }
    }
    let mut enc = DeflateEncoder::new(Vec::new(), Compression::new(6));
    // Writing into a Vec cannot fail.
    enc.write_all(&shuffled).expect("in-memory write");
    enc.finish().expect("in-memory write")
}

fn predict(p: &PlaneShape, values: &[f32], out: &mut [u32]) {
    let row = (p.width * p.channels) as usize;
    let c = p.channels as usize;
    for i in 0..values.len() {
        let pred = predictor(i, row, c, |j| values[j].to_bits());
        out[i] = values[i].to_bits() ^ pred;
    }
}

/// The bit pattern that predicts value `i` of a plane, given a row length of `row` values.
fn predictor(i: usize, row: usize, c: usize, at: impl Fn(usize) -> u32) -> u32 {
    if i % row >= c {
        at(i - c)
    } else if i >= row {
        at(i - row)
    } else {
        0
    }
}

pub fn decode(planes: &[PlaneShape], n: usize, bytes: &[u8]) -> Result<Vec<f32>, CodecError> {
    let expected = 4 * n;
    // Grow with the data actually inflated: a forged shape cannot force a large allocation.
    let mut shuffled = Vec::new();
    let mut dec = DeflateDecoder::new(bytes);
    (&mut dec)
        .take(expected as u64 + 1)
        .read_to_end(&mut shuffled)
        .map_err(|e| CodecError::Corrupt(e.to_string()))?;
    if shuffled.len() != expected {
        return Err(CodecError::DecodedLength { expected, found: shuffled.len() });
    }
    // The DEFLATE stream is the whole codestream: its final block ends in the last byte.
    let used = dec.total_in() as usize;
    if used < bytes.len() {
        return Err(CodecError::TrailingBytes { extra: bytes.len() - used, length: bytes.len() });
    }
    let mut bits = vec![0u32; n];
    for (i, b) in bits.iter_mut().enumerate() {
        *b = u32::from_be_bytes([
            shuffled[i],
            shuffled[n + i],
            shuffled[2 * n + i],
            shuffled[3 * n + i],
        ]);
    }
    let mut start = 0;
    for p in planes {
        let len = (p.width * p.height * p.channels) as usize;
        let plane = &mut bits[start..start + len];
        let row = (p.width * p.channels) as usize;
        let c = p.channels as usize;
        for i in 0..len {
            let pred = predictor(i, row, c, |j| plane[j]);
            plane[i] ^= pred;
        }
        start += len;
    }
    Ok(bits.into_iter().map(f32::from_bits).collect())
}
