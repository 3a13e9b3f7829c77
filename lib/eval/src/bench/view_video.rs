//! The view-based baseline (thesis 4.8): the gold-standard images themselves, in zig-zag
//! order through the parameter space, encoded as one video at a byte budget and compared
//! with the gold standard after decoding, over the whole image.

use crate::baselines::path::{linear_index, zigzag};
use crate::baselines::video::{decode, encode_to_budget, Frames, Matched, VideoCodec};
use crate::metrics::{srgb_encode, SquaredError};
use anyhow::{anyhow, Result};

use pis_pack::Inferred;

/// The set's gold-standard (`combined`) images in zig-zag order, as 8-bit display values,
/// with the linear images for the error.
pub struct ViewFrames {
    pub frames: Frames,
    /// Linear RGB per frame (interleaved), same order.
    pub gold: Vec<Vec<f32>>,
}

/// The linear value of an 8-bit display value (sRGB decoding).
pub fn linear_of(d: u8) -> f32 {
    let v = d as f32 / 255.0;
    if v <= 0.040_45 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

/// Collects the frames along the zig-zag path.
pub fn view_frames(set: &Inferred) -> Result<ViewFrames> {
    let set = &set.set;
    let counts: Vec<u32> = set.scene.space.dims.iter().map(|d| d.values.len() as u32).collect();
    let (w, h) = set.resolution;
    let n = w as usize * h as usize;
    let mut rgb = Vec::with_capacity(n * 3 * set.samples.len());
    let mut gold = Vec::new();
    for p in zigzag(&counts) {
        let i = linear_index(&p, &counts);
        let img = set.images.shared(i).map_err(|e| anyhow!("point {p:?}: {e}"))?;
        let l =
            img.layer("combined").ok_or_else(|| anyhow!("point {p:?} has no combined image"))?;
        let mut lin = vec![0.0f32; n * 3];
        for (c, name) in ["R", "G", "B"].iter().enumerate() {
            let plane = l
                .channel(name)
                .ok_or_else(|| anyhow!("point {p:?}: the combined image has no {name} channel"))?;
            for k in 0..n {
                lin[k * 3 + c] = plane[k];
            }
        }
        rgb.extend(lin.iter().map(|&v| (srgb_encode(v) * 255.0).round() as u8));
        gold.push(lin);
    }
    Ok(ViewFrames { frames: Frames { width: w, height: h, count: gold.len(), rgb }, gold })
}

/// One encoded point: what the encoder spent and the PSNR over the whole image.
pub struct ViewPoint {
    pub matched: Matched,
    pub psnr_db: f64,
}

/// Encodes the frames at `budget` bytes and measures the decoded frames.
pub fn view_point(v: &ViewFrames, codec: VideoCodec, budget: usize) -> Result<ViewPoint> {
    let matched = encode_to_budget(std::slice::from_ref(&v.frames), codec, budget)?;
    let f = &v.frames;
    let decoded = decode(&matched.streams[0], codec, f.width, f.height, f.count)?;
    let mut e = SquaredError::default();
    let frame = f.width as usize * f.height as usize * 3;
    for (i, g) in v.gold.iter().enumerate() {
        for (d, r) in decoded.rgb[i * frame..(i + 1) * frame].iter().zip(g) {
            e.add(linear_of(*d), *r);
        }
    }
    Ok(ViewPoint { matched, psnr_db: e.psnr() })
}
