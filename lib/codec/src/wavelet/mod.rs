//! Codec 2, `wavelet`: CDF 9/7 lifting and an embedded, arithmetic-coded bit-plane stream
//! (SPEC.md 11.4). Any prefix of a codestream that keeps the header is itself a valid
//! codestream of lower quality, and one encode yields the whole rate–distortion curve.

pub mod bitplane;
pub mod lifting;
mod work;

use crate::{colour, lossy_header, value_count, CodecError, PlaneShape, Rate, RdCurve, RdPoint};
use bitplane::Band;

pub use crate::lossy_header::{HEADER_LEN, VERSION};
/// Decomposition levels requested by the encoder (each plane uses as many as its size allows).
pub const DEFAULT_LEVELS: u32 = 5;
/// Largest level count a header may name.
pub const MAX_LEVELS: u32 = 10;
/// Bit-planes coded below the largest scaled coefficient by [`Rate::Default`].
pub const DEFAULT_BITS: u32 = 16;
/// Truncation points measured by the trait's `rd_curve`.
pub const CURVE_POINTS: usize = 24;
const NO_PLANES: u8 = 255;

// The header carries no channel means: the low-pass band carries them, and a pyramid of
// small level images cannot afford 4 bytes per channel each.

/// Header bytes of a codestream for `planes` ([`HEADER_LEN`] whatever the planes).
pub fn header_len(_planes: &[PlaneShape]) -> usize {
    HEADER_LEN
}

/// A full encode: the codestream and its rate–distortion curve (one point per prefix length
/// where the error changes, estimated in the transform domain; see [`Encoded::curve`]).
/// [`Encoded::measured_curve`] gives exact errors at chosen prefix lengths.
#[derive(Clone, Debug)]
pub struct Encoded {
    pub bytes: Vec<u8>,
    /// `mse` per value of the decoded image when the stream is cut to `bytes`. The first
    /// point is the empty stream (zeros), the second the bare header (zeros as well).
    /// The errors are summed over weighted wavelet coefficients: CDF 9/7 is not orthogonal,
    /// so they are estimates (within a factor of about 1.5 at the coarsest cuts, closer as
    /// the rate grows), dense (every byte where the image changes) and free.
    pub curve: RdCurve,
}

impl Encoded {
    /// Exact rate–distortion points: decodes the prefixes at `points` lengths spaced
    /// geometrically from the header to the full stream (plus the empty stream) and measures
    /// the error against `values`.
    pub fn measured_curve(
        &self,
        planes: &[PlaneShape],
        values: &[f32],
        points: usize,
    ) -> Result<RdCurve, CodecError> {
        self.measured_curve_weighted(planes, values, None, points)
    }

    /// [`Encoded::measured_curve`] with per-value error weights ([`crate::weighted_mse`]).
    pub fn measured_curve_weighted(
        &self,
        planes: &[PlaneShape],
        values: &[f32],
        weights: Option<&[f32]>,
        points: usize,
    ) -> Result<RdCurve, CodecError> {
        let hl = header_len(planes);
        let total = self.bytes.len();
        let mut cuts = vec![0, hl.min(total)];
        let points = points.max(2);
        for k in 1..points {
            let f = k as f64 / (points - 1) as f64;
            let c = (hl as f64) * ((total as f64) / hl as f64).powf(f);
            cuts.push((c.round() as usize).clamp(hl.min(total), total));
        }
        cuts.sort_unstable();
        cuts.dedup();
        let mut out = Vec::with_capacity(cuts.len());
        for c in cuts {
            let back = decode(planes, &self.bytes[..c])?;
            out.push(RdPoint { bytes: c, mse: crate::weighted_mse(values, &back, weights) });
        }
        Ok(RdCurve { points: out })
    }
}

impl Encoded {
    /// The stream cut to at most `budget` bytes (empty when the header does not fit).
    pub fn truncated(&self, budget: usize, planes: &[PlaneShape]) -> &[u8] {
        if budget < header_len(planes) {
            &[]
        } else {
            &self.bytes[..budget.min(self.bytes.len())]
        }
    }
}

/// The subbands of all (plane, channel) arrays in scan order, and the scale of each band
/// (the square root of its 2D synthesis energy).
/// Width, height and decomposition levels of one (plane, channel) array.
type ArrayShape = (usize, usize, u32);

fn layout(planes: &[PlaneShape], levels: u32) -> (Vec<Band>, Vec<f32>, Vec<ArrayShape>) {
    let mut bands = Vec::new();
    let mut scales = Vec::new();
    let mut arrays = Vec::new();
    let mut offset = 0;
    for p in planes {
        let (w, h) = (p.width as usize, p.height as usize);
        let lev = lifting::plane_levels(p.width, p.height, levels);
        let ex = lifting::basis_energies(w, lev);
        let ey = lifting::basis_energies(h, lev);
        // Sizes of the low-pass band after j levels.
        let mut sizes = vec![(w, h)];
        for _ in 0..lev {
            let (cw, ch) = sizes[sizes.len() - 1];
            sizes.push((cw.div_ceil(2), ch.div_ceil(2)));
        }
        for _ in 0..p.channels {
            arrays.push((w, h, lev));
            let (lw, lh) = sizes[lev as usize];
            let ll_scale =
                if lev == 0 { 1.0 } else { ex[lev as usize - 1].0 * ey[lev as usize - 1].0 };
            bands.push(Band { offset, width: lw, height: lh, class: 0, parent: None });
            scales.push(ll_scale.sqrt() as f32);
            offset += lw * lh;
            // Bands of the previous (coarser) level, per orientation.
            let mut coarser: [Option<usize>; 3] = [None; 3];
            for j in (1..=lev as usize).rev() {
                let (pw, ph) = sizes[j - 1];
                let (cw, ch) = sizes[j];
                let (lx, hx) = ex[j - 1];
                let (ly, hy) = ey[j - 1];
                let dims = [(pw - cw, ch), (cw, ph - ch), (pw - cw, ph - ch)];
                let energy = [hx * ly, lx * hy, hx * hy];
                let class = match j {
                    1 => 3,
                    2 => 2,
                    _ => 1,
                };
                for o in 0..3 {
                    let (bw, bh) = dims[o];
                    let idx = bands.len();
                    bands.push(Band { offset, width: bw, height: bh, class, parent: coarser[o] });
                    scales.push(energy[o].sqrt() as f32);
                    coarser[o] = Some(idx);
                    offset += bw * bh;
                }
            }
        }
    }
    (bands, scales, arrays)
}

/// Visits every coefficient of every band: f(band index, array index, position in the
/// array's Mallat layout, position in the coefficient vector).
fn for_each_band_coef(
    bands: &[Band],
    arrays: &[ArrayShape],
    mut f: impl FnMut(usize, usize, usize, usize),
) {
    for (b, (band, (ai, x0, y0))) in bands.iter().zip(band_places(arrays)).enumerate() {
        let w = arrays[ai].0;
        for y in 0..band.height {
            for x in 0..band.width {
                f(b, ai, (y0 + y) * w + x0 + x, band.offset + y * band.width + x);
            }
        }
    }
}

/// Writes each significant coefficient, dequantized, at its place in the Mallat layout of its
/// array (`chans` holds zeros: every other coefficient is 0). The significant indices are in
/// index order, so the bands are met in order.
fn place_significant(
    bands: &[Band],
    scales: &[f32],
    arrays: &[ArrayShape],
    (significant, state): (&[u32], &bitplane::CoefficientState),
    step: f32,
    chans: &mut [&mut [f32]],
) {
    let places = band_places(arrays);
    let mut b = 0;
    for &i in significant {
        let i = i as usize;
        while i >= bands[b].offset + bands[b].width * bands[b].height {
            b += 1;
        }
        let (band, (ai, x0, y0)) = (&bands[b], places[b]);
        let k = i - band.offset;
        let (y, x) = (k / band.width, k % band.width);
        let w = arrays[ai].0;
        chans[ai][(y0 + y) * w + x0 + x] = (state.value(i) * step as f64 / scales[b] as f64) as f32;
    }
}

/// Each band's array and the top-left corner of its place in the array's Mallat layout, in
/// band order.
fn band_places(arrays: &[ArrayShape]) -> Vec<(usize, usize, usize)> {
    let mut out = Vec::new();
    for (ai, &(w, h, lev)) in arrays.iter().enumerate() {
        let mut sizes = vec![(w, h)];
        for _ in 0..lev {
            let (cw, ch) = sizes[sizes.len() - 1];
            sizes.push((cw.div_ceil(2), ch.div_ceil(2)));
        }
        out.push((ai, 0, 0));
        for j in (1..=lev as usize).rev() {
            let (cw, ch) = sizes[j];
            out.extend([(ai, cw, 0), (ai, 0, ch), (ai, cw, ch)]);
        }
    }
    out
}

/// Encodes a level image and returns the full stream with its rate–distortion curve.
/// `levels` decomposition levels (≤ [`MAX_LEVELS`]), `bits` bit-planes below the largest
/// scaled coefficient (1..=30).
pub fn encode_full(
    planes: &[PlaneShape],
    values: &[f32],
    levels: u32,
    bits: u32,
) -> Result<Encoded, CodecError> {
    let n = value_count(planes)?;
    if values.len() != n {
        return Err(CodecError::Length { expected: n, found: values.len() });
    }
    if let Some(i) = values.iter().position(|v| !v.is_finite()) {
        return Err(CodecError::Input(format!("value {i} is not finite")));
    }
    let levels = levels.min(MAX_LEVELS);
    let bits = bits.clamp(1, 30);
    let colour = colour::applies(planes);
    let mut chans = colour::split(planes, values, colour);
    let (bands, scales, arrays) = layout(planes, levels);
    for (a, &(w, h, lev)) in chans.iter_mut().zip(&arrays) {
        lifting::forward_2d(a, w, h, lev);
    }
    let mut coefs = vec![0.0f32; n];
    for_each_band_coef(&bands, &arrays, |b, ai, pos, k| {
        coefs[k] = chans[ai][pos] * scales[b];
    });
    drop(chans);
    let peak = coefs.iter().fold(0.0f32, |m, v| m.max(v.abs()));
    if !peak.is_finite() {
        return Err(CodecError::Input("transform overflows f32".into()));
    }
    let mut header = Vec::with_capacity(header_len(planes));
    header.push(VERSION);
    header.push(levels as u8);
    header.push(colour as u8);
    let zero_mse = values.iter().map(|v| (*v as f64).powi(2)).sum::<f64>() / n as f64;
    let hl = header_len(planes);
    if peak == 0.0 {
        // Every value is 0: the empty stream says it.
        let curve = RdCurve { points: vec![RdPoint { bytes: 0, mse: 0.0 }] };
        return Ok(Encoded { bytes: Vec::new(), curve });
    }
    let step = (peak / (1u64 << bits) as f32).max(f32::MIN_POSITIVE);
    let a: Vec<f64> = coefs.iter().map(|c| (c.abs() as f64) / step as f64).collect();
    let neg: Vec<bool> = coefs.iter().map(|c| c.is_sign_negative() && *c != 0.0).collect();
    let max_m =
        a.iter().fold(0.0f64, |m, v| m.max(*v)).floor().min((1u64 << 31) as f64 - 1.0) as u32;
    let top = 31 - max_m.max(1).leading_zeros();
    header.push(top as u8);
    header.extend(step.to_le_bytes());
    let (body, trace) = bitplane::encode(&bands, &a, &neg, top);
    let unit = (step as f64) * (step as f64) / n as f64;
    let mut points = vec![RdPoint { bytes: 0, mse: zero_mse }];
    for c in trace {
        points.push(RdPoint { bytes: hl + c.needed as usize, mse: c.error * unit });
    }
    let mut bytes = header;
    bytes.extend(body);
    Ok(Encoded { bytes, curve: RdCurve { points } })
}

/// Encodes with a [`Rate`].
pub fn encode(planes: &[PlaneShape], values: &[f32], rate: Rate) -> Result<Vec<u8>, CodecError> {
    match rate {
        Rate::Default => Ok(encode_full(planes, values, DEFAULT_LEVELS, DEFAULT_BITS)?.bytes),
        Rate::Quality(q) => {
            let bits = (q.clamp(1, 100) as u32 * 24 / 100).max(1);
            Ok(encode_full(planes, values, DEFAULT_LEVELS, bits)?.bytes)
        }
        Rate::Bytes(budget) => {
            let e = encode_full(planes, values, DEFAULT_LEVELS, DEFAULT_BITS)?;
            Ok(e.truncated(budget, planes).to_vec())
        }
    }
}

/// Decodes a codestream or any prefix of one that keeps the header; the empty stream decodes
/// to zeros.
pub fn decode(planes: &[PlaneShape], bytes: &[u8]) -> Result<Vec<f32>, CodecError> {
    let n = value_count(planes)?;
    if n > bitplane::MAX_COEFFICIENTS {
        return Err(CodecError::Corrupt(format!(
            "{n} values in one codestream (at most {})",
            bitplane::MAX_COEFFICIENTS
        )));
    }
    if bytes.is_empty() {
        return Ok(vec![0.0; n]);
    }
    let hl = header_len(planes);
    let header = lossy_header::read(bytes, "step")?;
    let (levels, colour, top, step) =
        (header.param as u32, header.colour, header.param2, header.scale);
    if levels > MAX_LEVELS {
        return Err(CodecError::Corrupt(format!("{levels} levels (at most {MAX_LEVELS})")));
    }
    if top > 30 && top != NO_PLANES {
        return Err(CodecError::Corrupt(format!("top bit-plane {top}")));
    }
    let (bands, scales, arrays) = layout(planes, levels);
    work::with_work(|work| {
        let body = &bytes[hl..];
        let dec = (top != NO_PLANES)
            .then(|| bitplane::decode(&bands, n, top as u32, body, &mut work.coefficients));
        // The body is exactly the coded data: nothing after a top bit-plane of 255, and no byte
        // the decoder did not read after the last bit-plane (a truncated body is read to its end).
        let used = dec.as_ref().map_or(0, |d| d.used);
        if used < body.len() {
            return Err(CodecError::TrailingBytes {
                extra: body.len() - used,
                length: bytes.len(),
            });
        }
        work.arrays.clear();
        work.arrays.resize(n, 0.0);
        let mut chans = split_arrays(&mut work.arrays, &arrays);
        if let Some(dec) = dec {
            let values = (&dec.significant[..], &work.coefficients);
            place_significant(&bands, &scales, &arrays, values, step, &mut chans);
        }
        for (a, &(w, h, lev)) in chans.iter_mut().zip(&arrays) {
            lifting::inverse_2d(a, w, h, lev, &mut work.tmp);
        }
        let mut out = Vec::with_capacity(n);
        colour::merge(planes, &chans, colour, &mut out);
        if !out.iter().fold(true, |all, v| all & v.is_finite()) {
            return Err(CodecError::Corrupt("decoded values overflow f32".into()));
        }
        Ok(out)
    })
}

/// `buffer` cut into one slice per (plane, channel) array.
fn split_arrays<'a>(mut buffer: &'a mut [f32], arrays: &[ArrayShape]) -> Vec<&'a mut [f32]> {
    let mut out = Vec::with_capacity(arrays.len());
    for &(w, h, _) in arrays {
        let (head, rest) = std::mem::take(&mut buffer).split_at_mut(w * h);
        out.push(head);
        buffer = rest;
    }
    out
}
