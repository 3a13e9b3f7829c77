//! The precision a file's textures are held in on the GPU: 16-bit floats where the file's
//! own measurement says rounding to them leaves its frames within its coding error (SPEC.md
//! 6.6 `half_float_psnr_db`), 32-bit floats elsewhere. Half floats halve the textures'
//! memory, the uploads of textures rebuilt on the workers and the texels the GPU filters.
//! The level images the GPU rebuild reads are chosen the same way, by their own measurement
//! (`level16_psnr_db`): in 16 bits a value, they halve its uploads and the buffers it keeps.

use pis_format::precision::{
    HalfFloatFit, HALF_FLOAT_MARGIN_DB, HALF_FLOAT_PSNR_SETTING, LEVEL16_PSNR_SETTING,
};
use pis_format::Provenance;

use crate::gpu::Gpu;

/// The precision asked for.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TexturePrecision {
    /// Half floats where the file records that they cost at most 1 % of its coding error's
    /// squared error ([`HALF_FLOAT_MARGIN_DB`] below it), else full.
    #[default]
    Auto,
    /// 32-bit floats (`Rgba32Float`) for surfaces where the adapter can filter them, and
    /// for cube maps.
    Full,
    /// 16-bit floats (`Rgba16Float`) for surfaces and cube maps.
    Half,
}

impl TexturePrecision {
    /// The name `--texture-precision` takes.
    pub fn name(self) -> &'static str {
        match self {
            TexturePrecision::Auto => "auto",
            TexturePrecision::Full => "full",
            TexturePrecision::Half => "half",
        }
    }

    /// Every choice, in the order the tools list them.
    pub const ALL: [TexturePrecision; 3] =
        [TexturePrecision::Auto, TexturePrecision::Full, TexturePrecision::Half];
}

/// The texture formats a player holds a file's textures in, and why.
#[derive(Clone, Debug, PartialEq)]
pub struct PrecisionChoice {
    /// Surface textures' format.
    pub surface: wgpu::TextureFormat,
    /// Shells' cube maps' format.
    pub cube: wgpu::TextureFormat,
    /// Why, in a sentence.
    pub why: String,
    /// The level images the GPU rebuild reads are held in 16 bits a value (else as 32-bit
    /// floats).
    pub level16: bool,
    /// Why, in a sentence.
    pub levels_why: String,
}

impl PrecisionChoice {
    /// Whether both are `Rgba16Float`.
    pub fn half(&self) -> bool {
        self.surface == wgpu::TextureFormat::Rgba16Float
            && self.cube == wgpu::TextureFormat::Rgba16Float
    }
}

/// Whether half floats, and why, when `asked`, for a file that records `fit` under the
/// setting `setting`.
fn half_or_not(
    asked: TexturePrecision,
    fit: Option<HalfFloatFit>,
    setting: &str,
) -> (bool, String) {
    match (asked, fit) {
        (TexturePrecision::Half, _) => (true, "half floats asked for".to_string()),
        (TexturePrecision::Full, _) => (false, "full precision asked for".to_string()),
        (TexturePrecision::Auto, None) => {
            (false, format!("the file records no half-float measurement ({setting})"))
        }
        (TexturePrecision::Auto, Some(f)) => (
            f.allows_half(),
            format!(
                "half floats draw frames {:.1} dB from full precision, {:.1} dB below the file's coding error ({:.2} dB; {HALF_FLOAT_MARGIN_DB} needed)",
                f.half_psnr_db,
                f.margin_db(),
                f.coding_psnr_db
            ),
        ),
    }
}

/// The precision for a file of provenance `p` on `gpu` when `asked`: of its textures, and of
/// the level images the GPU rebuild reads.
pub(super) fn choose(
    gpu: &Gpu,
    p: Option<&Provenance>,
    asked: TexturePrecision,
) -> PrecisionChoice {
    let (half, why) = half_or_not(asked, HalfFloatFit::of(p), HALF_FLOAT_PSNR_SETTING);
    let (level16, levels_why) =
        half_or_not(asked, HalfFloatFit::of_levels(p), LEVEL16_PSNR_SETTING);
    let half_format = wgpu::TextureFormat::Rgba16Float;
    if half {
        let (surface, cube) = (half_format, half_format);
        return PrecisionChoice { surface, cube, why, level16, levels_why };
    }
    let mut why = why;
    if gpu.texture_format == half_format {
        why.push_str("; the adapter cannot filter 32-bit floats, so surfaces are half floats");
    }
    let (surface, cube) = (gpu.texture_format, gpu.cube_format);
    PrecisionChoice { surface, cube, why, level16, levels_why }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn prov(half_db: &str, coding_db: &str) -> Provenance {
        Provenance {
            settings: vec![
                ("predicted_psnr_db".to_string(), coding_db.to_string()),
                ("half_float_psnr_db".to_string(), half_db.to_string()),
            ],
            ..Default::default()
        }
    }

    #[test]
    fn auto_follows_the_files_measurement() {
        let Some(gpu) = Gpu::new().ok() else {
            eprintln!("no adapter: skipped");
            return;
        };
        let full = gpu.texture_format;
        let c = choose(&gpu, Some(&prov("80", "36")), TexturePrecision::Auto);
        assert!(c.half(), "{c:?}");
        let c = choose(&gpu, Some(&prov("50", "36")), TexturePrecision::Auto);
        assert_eq!(c.surface, full, "{c:?}");
        assert!(c.why.contains("14.0 dB below"), "{c:?}");
        let c = choose(&gpu, None, TexturePrecision::Auto);
        assert_eq!(c.cube, wgpu::TextureFormat::Rgba32Float, "{c:?}");
        assert!(choose(&gpu, None, TexturePrecision::Half).half());
        assert!(!choose(&gpu, Some(&prov("80", "36")), TexturePrecision::Full).half());
        // The level images by their own measurement.
        let mut p = prov("80", "36");
        assert!(!choose(&gpu, Some(&p), TexturePrecision::Auto).level16);
        p.settings.push(("level16_psnr_db".to_string(), "57".to_string()));
        let c = choose(&gpu, Some(&p), TexturePrecision::Auto);
        assert!(c.level16 && c.levels_why.contains("21.0 dB below"), "{c:?}");
        p.settings.last_mut().unwrap().1 = "55".to_string();
        assert!(!choose(&gpu, Some(&p), TexturePrecision::Auto).level16);
        assert!(choose(&gpu, Some(&p), TexturePrecision::Half).level16);
    }
}
