//! The channel decorrelation shared by the lossy codecs (SPEC.md 11.2).
//!
//! Channels 0–2 of a plane with 3 or 4 channels go through an orthonormal opponent
//! transform, so squared errors are the same before and after it:
//!
//! ```text
//! y  = (r + g + b) / √3      c1 = (r − b) / √2      c2 = (r − 2g + b) / √6
//! ```
//!
//! A fourth channel (alpha) and planes with 1 or 2 channels are coded as they are.

const S3: f32 = 0.577_350_26; // 1/√3
const S2: f32 = std::f32::consts::FRAC_1_SQRT_2;
const S6: f32 = 0.408_248_3; // 1/√6

/// Forward transform of one interleaved pixel (in place).
pub fn forward(px: &mut [f32]) {
    if px.len() >= 3 {
        let (r, g, b) = (px[0], px[1], px[2]);
        px[0] = (r + g + b) * S3;
        px[1] = (r - b) * S2;
        px[2] = (r - 2.0 * g + b) * S6;
    }
}

/// Inverse of [`forward`] (in place).
pub fn inverse(px: &mut [f32]) {
    if px.len() >= 3 {
        let (y, c1, c2) = (px[0], px[1], px[2]);
        px[0] = y * S3 + c1 * S2 + c2 * S6;
        px[1] = y * S3 - 2.0 * c2 * S6;
        px[2] = y * S3 - c1 * S2 + c2 * S6;
    }
}

#[allow(clippy::needless_range_loop)]
/// Splits interleaved planes into one `w × h` array per (plane, channel), after the colour
/// transform when `colour` is set.
pub fn split(planes: &[crate::PlaneShape], values: &[f32], colour: bool) -> Vec<Vec<f32>> {
    let mut out = Vec::new();
    let mut start = 0;
    for p in planes {
        let c = p.channels as usize;
        let n = (p.width * p.height) as usize;
        let mut chans = vec![vec![0.0f32; n]; c];
        let mut px = [0.0f32; 4];
        for i in 0..n {
            px[..c].copy_from_slice(&values[start + i * c..start + (i + 1) * c]);
            if colour {
                forward(&mut px[..c]);
            }
            for k in 0..c {
                chans[k][i] = px[k];
            }
        }
        start += n * c;
        out.extend(chans);
    }
    out
}

/// Inverse of [`split`]: writes the interleaved values.
pub fn merge<C: AsRef<[f32]>>(
    planes: &[crate::PlaneShape],
    chans: &[C],
    colour: bool,
    out: &mut Vec<f32>,
) {
    let mut idx = 0;
    for p in planes {
        let c = p.channels as usize;
        let n = (p.width * p.height) as usize;
        let start = out.len();
        out.resize(start + n * c, 0.0);
        let chans: Vec<&[f32]> = chans[idx..idx + c].iter().map(|v| &v.as_ref()[..n]).collect();
        match chans[..] {
            [y, c1, c2] if colour => merge_opponent::<3>(&mut out[start..], y, c1, c2, &[]),
            [y, c1, c2, a] if colour => merge_opponent::<4>(&mut out[start..], y, c1, c2, a),
            _ => {
                for (i, px) in out[start..].chunks_exact_mut(c).enumerate() {
                    for (v, chan) in px.iter_mut().zip(&chans) {
                        *v = chan[i];
                    }
                }
            }
        }
        idx += c;
    }
}

/// [`merge`] of a plane of `C` channels (3 or 4) whose first three are opponent colours
/// ([`inverse`]); `alpha` is empty for 3.
fn merge_opponent<const C: usize>(
    out: &mut [f32],
    y: &[f32],
    c1: &[f32],
    c2: &[f32],
    alpha: &[f32],
) {
    let colours = y.iter().zip(c1).zip(c2);
    for (i, (px, ((&y, &c1), &c2))) in out.chunks_exact_mut(C).zip(colours).enumerate() {
        let mut rgb = [y, c1, c2];
        inverse(&mut rgb);
        px[..3].copy_from_slice(&rgb);
        if C == 4 {
            px[3] = alpha[i];
        }
    }
}

/// True when the colour transform applies (some plane has 3 or 4 channels).
pub fn applies(planes: &[crate::PlaneShape]) -> bool {
    planes.iter().any(|p| p.channels >= 3)
}
