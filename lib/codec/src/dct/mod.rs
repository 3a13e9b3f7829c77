//! Codec 3, `dct`: 8×8 block DCT, the JPEG matrix scaled by a quality factor, adaptive
//! arithmetic coding (SPEC.md 11.5). Float input: the stream stores a unit, one step of the
//! 8-bit scale the matrix was designed for: the range of the values (at least 1/1024 of their
//! largest magnitude) over 255.

pub mod entropy;
pub mod quant;
pub mod transform;

use crate::arith::{Decoder, Encoder};
use crate::{colour, lossy_header, value_count, CodecError, PlaneShape, Rate, RdCurve, RdPoint};

pub use crate::lossy_header::{HEADER_LEN, VERSION};
/// Quality of [`Rate::Default`].
pub const DEFAULT_QUALITY: u8 = 75;

/// Header bytes of a codestream for `planes` ([`HEADER_LEN`] whatever the planes).
pub fn header_len(_planes: &[PlaneShape]) -> usize {
    HEADER_LEN
}

/// The (width, height) of each (plane, channel) array in stream order.
fn arrays(planes: &[PlaneShape]) -> Vec<(usize, usize)> {
    planes
        .iter()
        .flat_map(|p| {
            std::iter::repeat_n((p.width as usize, p.height as usize), p.channels as usize)
        })
        .collect()
}

/// Copies block (bx, by) of a `w × h` array, replicating the last column and row.
fn load_block(a: &[f32], w: usize, h: usize, bx: usize, by: usize, b: &mut [f32; 64]) {
    for y in 0..8 {
        let sy = (by * 8 + y).min(h - 1);
        for x in 0..8 {
            let sx = (bx * 8 + x).min(w - 1);
            b[y * 8 + x] = a[sy * w + sx];
        }
    }
}

/// Encodes with quality `quality` (1..=100).
pub fn encode_quality(
    planes: &[PlaneShape],
    values: &[f32],
    quality: u8,
) -> Result<Vec<u8>, CodecError> {
    let n = value_count(planes)?;
    if values.len() != n {
        return Err(CodecError::Length { expected: n, found: values.len() });
    }
    if let Some(i) = values.iter().position(|v| !v.is_finite()) {
        return Err(CodecError::Input(format!("value {i} is not finite")));
    }
    let quality = quality.clamp(1, 100);
    let colour = colour::applies(planes);
    let chans = colour::split(planes, values, colour);
    let (lo, hi) = chans
        .iter()
        .flatten()
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), v| (lo.min(*v), hi.max(*v)));
    let range = hi - lo;
    if !range.is_finite() {
        return Err(CodecError::Input("colour transform overflows f32".into()));
    }
    // The range, but no less than 1/1024 of the largest magnitude: a constant or nearly
    // constant image keeps its level (its DC stays far below the quantizer's clamp).
    let big = lo.abs().max(hi.abs());
    let unit = (range.max(big / 1024.0) / 255.0).max(f32::MIN_POSITIVE);
    let mut out = vec![VERSION, quality, colour as u8, 0];
    out.extend(unit.to_le_bytes());
    let steps = quant::steps(quality, unit);
    let mut enc = Encoder::new();
    let mut ctx = entropy::Contexts::default();
    let mut b = [0.0f32; 64];
    for (a, (w, h)) in chans.iter().zip(arrays(planes)) {
        let mut prev = 0;
        for by in 0..h.div_ceil(8) {
            for bx in 0..w.div_ceil(8) {
                load_block(a, w, h, bx, by, &mut b);
                transform::forward(&mut b);
                let mut q = [0i32; 64];
                for (k, &z) in quant::ZIGZAG.iter().enumerate() {
                    q[k] = quant::quantize(b[z], steps[z]);
                }
                entropy::put_block(&mut enc, &mut ctx, &q, prev);
                prev = q[0];
            }
        }
    }
    out.extend(enc.finish());
    Ok(out)
}

/// Encodes with a [`Rate`]; a byte budget picks the largest quality that fits (bisection).
pub fn encode(planes: &[PlaneShape], values: &[f32], rate: Rate) -> Result<Vec<u8>, CodecError> {
    match rate {
        Rate::Default => encode_quality(planes, values, DEFAULT_QUALITY),
        Rate::Quality(q) => encode_quality(planes, values, q),
        Rate::Bytes(budget) => {
            let (mut lo, mut hi) = (0u8, 101u8); // lo fits (0: empty stream), hi does not
            let mut best = Vec::new();
            while hi - lo > 1 {
                let mid = lo + (hi - lo) / 2;
                let s = encode_quality(planes, values, mid)?;
                if s.len() <= budget {
                    lo = mid;
                    best = s;
                } else {
                    hi = mid;
                }
            }
            Ok(best)
        }
    }
}

/// Decodes a codestream; the empty stream decodes to zeros.
pub fn decode(planes: &[PlaneShape], bytes: &[u8]) -> Result<Vec<f32>, CodecError> {
    let n = value_count(planes)?;
    if bytes.is_empty() {
        return Ok(vec![0.0; n]);
    }
    let hl = header_len(planes);
    let header = lossy_header::read(bytes, "unit")?;
    let (quality, colour, unit) = (header.param, header.colour, header.scale);
    if !(1..=100).contains(&quality) {
        return Err(CodecError::Corrupt(format!("quality {quality}")));
    }
    if header.param2 != 0 {
        return Err(CodecError::Corrupt("reserved byte is not 0".into()));
    }
    let steps = quant::steps(quality, unit);
    let mut dec = Decoder::new(&bytes[hl..]);
    let mut ctx = entropy::Contexts::default();
    let mut chans = Vec::new();
    let mut b = [0.0f32; 64];
    for (w, h) in arrays(planes) {
        // Memory grows with decoded blocks only: the first block proves the stream has data.
        let mut a: Vec<f32> = Vec::new();
        let mut prev = 0;
        let bw = w.div_ceil(8);
        for by in 0..h.div_ceil(8) {
            let mut row = vec![[0.0f32; 64]; 0];
            for _ in 0..bw {
                let q = entropy::get_block(&mut dec, &mut ctx, prev)
                    .ok_or_else(|| CodecError::Corrupt("codestream ends inside a block".into()))?;
                prev = q[0];
                for (k, &z) in quant::ZIGZAG.iter().enumerate() {
                    b[z] = q[k] as f32 * steps[z];
                }
                transform::inverse(&mut b);
                row.push(b);
            }
            for y in 0..8.min(h - by * 8) {
                for x in 0..w {
                    a.push(row[x / 8][y * 8 + x % 8]);
                }
            }
        }
        chans.push(a);
    }
    // The body is exactly the coded blocks: a decoder that did not run out of bytes has read
    // every one.
    let body = bytes.len() - hl;
    if !dec.exhausted() && dec.position() < body {
        return Err(CodecError::TrailingBytes {
            extra: body - dec.position(),
            length: bytes.len(),
        });
    }
    let mut out = Vec::with_capacity(n);
    colour::merge(planes, &chans, colour, &mut out);
    if out.iter().any(|v| !v.is_finite()) {
        return Err(CodecError::Corrupt("decoded values overflow f32".into()));
    }
    Ok(out)
}

/// Qualities sampled by [`rd_curve`].
pub const CURVE_QUALITIES: [u8; 14] = [2, 5, 10, 15, 20, 30, 40, 50, 60, 70, 80, 90, 95, 100];

/// The measured rate–distortion curve: one encode and decode per quality.
pub fn rd_curve(
    planes: &[PlaneShape],
    values: &[f32],
    qualities: &[u8],
) -> Result<RdCurve, CodecError> {
    rd_curve_weighted(planes, values, None, qualities)
}

/// [`rd_curve`] with per-value error weights ([`crate::weighted_mse`]).
pub fn rd_curve_weighted(
    planes: &[PlaneShape],
    values: &[f32],
    weights: Option<&[f32]>,
    qualities: &[u8],
) -> Result<RdCurve, CodecError> {
    value_count(planes)?;
    let zero = crate::weighted_mse(values, &vec![0.0; values.len()], weights);
    let mut points = vec![RdPoint { bytes: 0, mse: zero }];
    for &q in qualities {
        let s = encode_quality(planes, values, q)?;
        let back = decode(planes, &s)?;
        points.push(RdPoint { bytes: s.len(), mse: crate::weighted_mse(values, &back, weights) });
    }
    Ok(RdCurve { points }.monotone())
}
