//! Rate and distortion: what a lossy codec may spend, and what it gets for it.

/// How much a codec may spend on one level image. Exact codecs (`raw`, `lossless`) ignore it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Rate {
    /// The codec's default: the whole embedded stream (`wavelet`, 16 bit-planes below the
    /// largest coefficient) or quality 75 (`dct`).
    Default,
    /// At most this many bytes (exactly this many for `wavelet` when the full stream is
    /// longer and the budget holds the header; the largest quality that fits for `dct`).
    /// A budget below the smallest stream gives the empty stream, which decodes to zeros.
    Bytes(usize),
    /// A quality factor 1..=100: the JPEG-style matrix scale for `dct`; for `wavelet`,
    /// `max(1, q·24/100)` bit-planes below the largest coefficient.
    Quality(u8),
}

/// One point of a rate–distortion curve: a codestream of `bytes` bytes decodes with mean
/// squared error `mse` per value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RdPoint {
    pub bytes: usize,
    pub mse: f64,
}

/// A rate–distortion curve, points in increasing `bytes`, `mse` non-increasing.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RdCurve {
    pub points: Vec<RdPoint>,
}

impl RdCurve {
    /// The error of the best point that fits in `bytes` (the first point's error when none
    /// fits, which is an over-estimate).
    pub fn mse_at(&self, bytes: usize) -> f64 {
        let k = self.points.partition_point(|p| p.bytes <= bytes);
        match k {
            0 => self.points.first().map_or(0.0, |p| p.mse),
            k => self.points[k - 1].mse,
        }
    }

    /// Keeps the points where the error strictly decreases (the useful truncation points).
    pub fn monotone(mut self) -> Self {
        let mut out: Vec<RdPoint> = Vec::with_capacity(self.points.len());
        self.points.sort_by_key(|p| p.bytes);
        for p in self.points {
            match out.last_mut() {
                Some(last) if last.bytes == p.bytes => last.mse = last.mse.min(p.mse),
                Some(last) if p.mse >= last.mse => {}
                _ => out.push(p),
            }
        }
        RdCurve { points: out }
    }
}
