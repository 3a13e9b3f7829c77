//! The gold-standard frames pis-bench traces at exact cameras: fixed or adaptive samples
//! (`--reference-noise-threshold`, pis-trace's adaptive sampling) and, as an option,
//! denoised (`--reference-denoise`: the combined image through Open Image Denoise with its
//! albedo and normal guides, as pis-trace denoises a set's combined image, RAYSET.md 5.4).

use anyhow::{anyhow, Result};
use pis_scene::{Frame, Scene};
use pis_trace::{PointImages, ShadingSeed, TraceSettings};

/// How the reference frames sample beyond their samples per pixel and seeding.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ReferenceSampling {
    /// Adaptive sampling: a pixel stops once its estimated relative error is below this
    /// (0: every pixel takes the reference's samples per pixel, its most otherwise).
    pub noise_threshold: f32,
    /// Adaptive sampling: the samples every pixel takes first.
    pub min_spp: u32,
    /// Denoise each reference frame's combined image.
    pub denoise: bool,
}

impl ReferenceSampling {
    /// Refuses a denoised reference where Open Image Denoise cannot be loaded, before any
    /// frame is traced.
    pub fn check(&self) -> Result<()> {
        if self.denoise {
            pis_trace::oidn::shared().map_err(|e| anyhow!("--reference-denoise: {e}"))?;
        }
        Ok(())
    }

    /// The reference's trace settings: `spp` samples (the most, when adaptive), shading
    /// seeded by `seed`, camera samples from stream `stream`.
    pub fn settings(
        &self,
        resolution: (u32, u32),
        spp: u32,
        seed: ShadingSeed,
        stream: u64,
    ) -> TraceSettings {
        let mut s = TraceSettings::new(resolution, spp)
            .with_shading_seed(seed)
            .with_seed(stream)
            .with_adaptive(self.noise_threshold, self.min_spp.min(spp));
        s.denoise = self.denoise;
        s
    }

    /// How the references are traced, for reports: `16 spp, shading seeded per sample`,
    /// with `, adaptive (threshold 0.02, 4–16 spp)` and `, denoised` as they apply.
    pub fn describe(&self, spp: u32, seed: ShadingSeed) -> String {
        let mut s = format!("{spp} spp, shading seeded per {}", seed.name());
        if self.noise_threshold > 0.0 {
            let min = self.min_spp.min(spp);
            s += &format!(", adaptive (threshold {}, {min}–{spp} spp)", self.noise_threshold);
        }
        if self.denoise {
            s += ", denoised";
        }
        s
    }
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

impl ReferenceSampling {
    /// Traces the reference frame at `frame`: `spp` samples (the most, when adaptive),
    /// shading seeded by `seed`, and with `pair` a second time from [`SECOND_STREAM`].
    pub fn frame(
        &self,
        scene: &Scene,
        frame: &Frame,
        (spp, seed): (u32, ShadingSeed),
        pair: bool,
    ) -> Result<ReferenceFrame> {
        let images = trace(scene, frame, &self.settings(scene.resolution, spp, seed, 0))?;
        let rgb = combined_rgb(&images)?;
        if !pair {
            return Ok(ReferenceFrame { images, rgb, pair: None });
        }
        let second =
            trace(scene, frame, &self.settings(scene.resolution, spp, seed, SECOND_STREAM))?;
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
    fn the_settings_and_their_description_follow_the_sampling() {
        let fixed = ReferenceSampling::default();
        let s = fixed.settings((8, 6), 16, ShadingSeed::Sample, 1);
        assert_eq!((s.spp, s.seed, s.adaptive(), s.denoise), (16, 1, false, false));
        assert_eq!(fixed.describe(16, ShadingSeed::Sample), "16 spp, shading seeded per sample");
        let adaptive = ReferenceSampling { noise_threshold: 0.02, min_spp: 32, denoise: true };
        let s = adaptive.settings((8, 6), 16, ShadingSeed::Cell, 0);
        assert_eq!((s.min_spp, s.adaptive(), s.denoise), (16, true, true));
        assert_eq!(
            adaptive.describe(16, ShadingSeed::Cell),
            "16 spp, shading seeded per cell, adaptive (threshold 0.02, 16–16 spp), denoised"
        );
    }
}
