//! The gold-standard frames pis-bench traces at exact cameras: fixed or adaptive samples,
//! once or as a pair from independent streams
//! (`--reference-noise-threshold`, pis-trace's adaptive sampling) and, as an option,
//! denoised (`--reference-denoise`: the combined image through Open Image Denoise with its
//! albedo and normal guides, as pis-trace denoises a set's combined image, RAYSET.md 5.4).

use anyhow::{anyhow, Result};
use pis_pack::{Exit, Failure};
use pis_scene::{Frame, Scene};
use pis_trace::{PointImages, ShadingSeed, TraceSettings};

/// How pis-bench traces its gold-standard frames.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReferenceTrace {
    /// Samples per pixel (each pixel's most, when adaptive).
    pub spp: u32,
    /// What seeds the shading (`Sample` for a gold standard whose noise falls as 1/spp).
    pub seed: ShadingSeed,
    /// Trace every frame twice from independent sample streams: the gold standard is their
    /// mean, their difference measures its noise (needs `seed` `Sample`).
    pub pair: bool,
    /// Adaptive sampling: a pixel stops once its estimated relative error is below this
    /// (0: every pixel takes `spp`).
    pub noise_threshold: f32,
    /// Adaptive sampling: the samples every pixel takes first.
    pub min_spp: u32,
    /// Denoise each frame's combined image.
    pub denoise: bool,
}

/// The stream of the second trace of a reference pair (the first is the default, 0).
pub const SECOND_STREAM: u64 = 1;

/// A reference frame: its (first) trace's images, and its combined image as interleaved
/// linear RGB: with a pair, the mean of two traces from independent streams, and both.
pub struct ReferenceFrame {
    pub images: PointImages,
    pub rgb: Vec<f32>,
    pub pair: Option<[Vec<f32>; 2]>,
}

impl ReferenceTrace {
    /// `spp` fixed samples per pixel seeded by `seed`, traced once, not denoised.
    pub fn new(spp: u32, seed: ShadingSeed) -> ReferenceTrace {
        ReferenceTrace { spp, seed, pair: false, noise_threshold: 0.0, min_spp: 0, denoise: false }
    }

    /// Refuses, before any frame is traced, a pair seeded per cell (both traces would carry
    /// the same surface noise) and a denoised reference where Open Image Denoise cannot be
    /// loaded.
    pub fn check(&self) -> Result<(), Failure> {
        if self.pair && self.seed != ShadingSeed::Sample {
            return Err(Failure::new(Exit::Usage, anyhow!("--reference-pair needs --reference-seed sample: seeded per cell, both renders carry the same surface noise, so their difference cannot measure it")));
        }
        if self.denoise {
            pis_trace::oidn::shared().map_err(|e| {
                Failure::new(Exit::NotSupported, anyhow!("--reference-denoise: {e}"))
            })?;
        }
        Ok(())
    }

    /// The trace settings of stream `stream` at `resolution`.
    pub fn settings(&self, resolution: (u32, u32), stream: u64) -> TraceSettings {
        let mut s = TraceSettings::new(resolution, self.spp)
            .with_shading_seed(self.seed)
            .with_seed(stream)
            .with_adaptive(self.noise_threshold, self.min_spp.min(self.spp));
        s.denoise = self.denoise;
        s
    }

    /// How the references are traced, for reports: `16 spp, shading seeded per sample`,
    /// with `, adaptive (threshold 0.02, 4–16 spp)` and `, denoised` as they apply.
    pub fn describe(&self) -> String {
        let (spp, mut s) =
            (self.spp, format!("{} spp, shading seeded per {}", self.spp, self.seed.name()));
        if self.noise_threshold > 0.0 {
            let min = self.min_spp.min(spp);
            s += &format!(", adaptive (threshold {}, {min}–{spp} spp)", self.noise_threshold);
        }
        if self.denoise {
            s += ", denoised";
        }
        s
    }

    /// Says on stderr that `tool` traces `frames` reference frames, and how.
    pub fn announce(&self, tool: &str, frames: usize) {
        let twice = if self.pair { ", each twice from independent streams" } else { "" };
        eprintln!(
            "pis-bench: {tool}: tracing {frames} reference frames ({}){twice}",
            self.describe()
        );
    }

    /// Traces the reference frame at `frame` (with a pair, a second time from
    /// [`SECOND_STREAM`]).
    pub fn frame(&self, scene: &Scene, frame: &Frame) -> Result<ReferenceFrame> {
        let images = trace(scene, frame, &self.settings(scene.resolution, 0))?;
        let rgb = combined_rgb(&images)?;
        if !self.pair {
            return Ok(ReferenceFrame { images, rgb, pair: None });
        }
        let second = trace(scene, frame, &self.settings(scene.resolution, SECOND_STREAM))?;
        let second = combined_rgb(&second)?;
        let mean = rgb.iter().zip(&second).map(|(a, b)| 0.5 * (a + b)).collect();
        Ok(ReferenceFrame { images, rgb: mean, pair: Some([rgb, second]) })
    }
}

/// Traces one reference frame: its images, the combined image denoised in place where the
/// settings denoise.
pub fn trace(scene: &Scene, frame: &Frame, settings: &TraceSettings) -> Result<PointImages> {
    let mut r = pis_trace::render_point(scene, frame, settings, &|| {})?;
    if let Some(input) = r.denoise_input.take() {
        let oidn = pis_trace::oidn::shared().map_err(|e| anyhow!("denoising a reference: {e}"))?;
        let denoised = pis_trace::denoise::denoise_point(oidn, &r.images, &input, &[])?;
        r.images.layers.extend(denoised.images);
        pis_trace::denoise::prefer_denoised(&mut r.images);
    }
    Ok(r.images)
}

/// The combined image of `images` as interleaved linear RGB.
pub fn combined_rgb(images: &PointImages) -> Result<Vec<f32>> {
    let l = images
        .layer("combined")
        .ok_or_else(|| anyhow!("the traced frame has no combined image"))?;
    let n = l.width as usize * l.height as usize;
    let mut rgb = vec![0.0f32; n * 3];
    for (c, name) in ["R", "G", "B"].iter().enumerate() {
        let p = l.channel(name).ok_or_else(|| anyhow!("the traced frame has no {name}"))?;
        rgb.chunks_exact_mut(3).zip(p).for_each(|(px, v)| px[c] = *v);
    }
    Ok(rgb)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_settings_and_their_description_follow_the_trace() {
        let fixed = ReferenceTrace::new(16, ShadingSeed::Sample);
        let s = fixed.settings((8, 6), 1);
        assert_eq!((s.spp, s.seed, s.adaptive(), s.denoise), (16, 1, false, false));
        assert_eq!(fixed.describe(), "16 spp, shading seeded per sample");
        let adaptive = ReferenceTrace {
            noise_threshold: 0.02,
            min_spp: 32,
            denoise: true,
            ..ReferenceTrace::new(16, ShadingSeed::Cell)
        };
        let s = adaptive.settings((8, 6), 0);
        assert_eq!((s.min_spp, s.adaptive(), s.denoise), (16, true, true));
        assert_eq!(
            adaptive.describe(),
            "16 spp, shading seeded per cell, adaptive (threshold 0.02, 16–16 spp), denoised"
        );
        let pair = ReferenceTrace { pair: true, ..fixed };
        assert!(pair.check().is_ok());
        let cell = ReferenceTrace { pair: true, ..ReferenceTrace::new(16, ShadingSeed::Cell) };
        assert!(cell.check().is_err_and(|f| f.exit == Exit::Usage));
    }
}
