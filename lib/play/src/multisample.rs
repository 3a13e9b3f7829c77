//! Multisample antialiasing of the player's frames: how many coverage samples per pixel a
//! frame's colour, depth and object-index attachments get.
//!
//! The ray-traced gold standard is filtered (every pixel a Gaussian-weighted average of
//! sub-pixel samples, pis-trace's film filter), so a pixel on an object's silhouette mixes
//! the object with what lies behind it. With one sample per pixel the player draws such a
//! pixel wholly one or the other. With n samples the depth test and the object-index test
//! run per sample and the resolve averages the samples, so an edge pixel is the covered
//! fraction of each surface. Shading stays once per pixel at its centre (no per-sample
//! shading): a pixel whose samples all lie on one triangle gets exactly the single-sample
//! value, which is what pis-compile's hardware model predicts (also across a flat polygon's
//! triangles, whose texture coordinates are one affine function; on a curved mesh's own
//! edges each triangle shades the pixel at its centre, and the two values are mixed).

use crate::frame::ID_FORMAT;
use crate::gpu::Gpu;
use crate::textured::DEPTH_FORMAT;

/// Samples per pixel the player draws with unless told otherwise.
pub const DEFAULT_SAMPLES: u32 = 4;

/// The sample counts the player offers: 1 (no antialiasing) and 4 (the count every
/// multisampling adapter supports).
pub const SAMPLE_COUNTS: [u32; 2] = [1, 4];

/// The multisampling a frame gets: the count asked for, the count drawn with, and why they
/// differ when they do.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Multisample {
    pub requested: u32,
    pub samples: u32,
    /// Why fewer samples than requested are drawn.
    pub note: Option<String>,
}

/// Checks a requested sample count.
pub fn check_samples(requested: u32) -> Result<(), String> {
    if SAMPLE_COUNTS.contains(&requested) {
        Ok(())
    } else {
        Err(format!("multisampling {requested}: expected 1 (off) or 4 samples per pixel"))
    }
}

/// The samples per pixel of frames drawn into `colour` targets: `requested` where the device
/// can multisample `colour` (a float or normalized format, and resolve it by averaging),
/// the object-index format and the depth format that many times, else 1 with a note naming
/// the format that cannot.
pub fn choose(gpu: &Gpu, requested: u32, colour: wgpu::TextureFormat) -> Multisample {
    if requested <= 1 {
        return Multisample { requested, samples: 1, note: None };
    }
    let mut missing = Vec::new();
    for (format, role, resolve) in [
        (colour, "colour", true),
        (ID_FORMAT, "object index", false),
        (DEPTH_FORMAT, "depth", false),
    ] {
        let f = gpu.format_features(format);
        // The resolve averages: the colour must be a float (or normalized) format.
        let averaged =
            matches!(format.sample_type(None, None), Some(wgpu::TextureSampleType::Float { .. }));
        let ok = f.flags.sample_count_supported(requested)
            && f.allowed_usages.contains(wgpu::TextureUsages::RENDER_ATTACHMENT)
            && (!resolve
                || (averaged
                    && f.flags.contains(wgpu::TextureFormatFeatureFlags::MULTISAMPLE_RESOLVE)));
        if !ok {
            let what = if resolve { "multisampled and resolved" } else { "multisampled" };
            missing.push(format!("{role} format {format:?} cannot be {what} {requested}×"));
        }
    }
    if missing.is_empty() {
        Multisample { requested, samples: requested, note: None }
    } else {
        let note = format!(
            "{} on {}; drawing 1 sample per pixel (no antialiasing)",
            missing.join(", "),
            gpu.info.name
        );
        Multisample { requested, samples: 1, note: Some(note) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_one_and_four_samples_are_offered() {
        assert!(check_samples(1).is_ok());
        assert!(check_samples(4).is_ok());
        for n in [0, 2, 3, 8, 16] {
            let e = check_samples(n).unwrap_err();
            assert!(e.contains(&n.to_string()) && e.contains("1 (off) or 4"), "{e}");
        }
    }
}
