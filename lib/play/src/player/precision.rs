//! The precision a file's textures are held in on the GPU: 16-bit floats where the file's
//! own measurement says rounding to them leaves its frames within its coding error (SPEC.md
//! 6.6 `half_float_psnr_db`), 32-bit floats elsewhere. Half floats halve the textures'
//! memory, the uploads of textures rebuilt on the workers and the texels the GPU filters.

use pis_format::precision::{HalfFloatFit, HALF_FLOAT_MARGIN_DB};
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
}

impl PrecisionChoice {
    /// Whether both are `Rgba16Float`.
    pub fn half(&self) -> bool {
        self.surface == wgpu::TextureFormat::Rgba16Float
            && self.cube == wgpu::TextureFormat::Rgba16Float
    }
}

/// The precision for a file of provenance `p` on `gpu` when `asked`.
pub(super) fn choose(
    gpu: &Gpu,
    p: Option<&Provenance>,
    asked: TexturePrecision,
) -> PrecisionChoice {
    let fit = HalfFloatFit::of(p);
    let (half, why) = match (asked, fit) {
        (TexturePrecision::Half, _) => (true, "half floats asked for".to_string()),
        (TexturePrecision::Full, _) => (false, "full precision asked for".to_string()),
        (TexturePrecision::Auto, None) => {
            (false, "the file records no half-float measurement (half_float_psnr_db)".to_string())
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
    };
    let half_format = wgpu::TextureFormat::Rgba16Float;
    if half {
        return PrecisionChoice { surface: half_format, cube: half_format, why };
    }
    let mut why = why;
    if gpu.texture_format == half_format {
        why.push_str("; the adapter cannot filter 32-bit floats, so surfaces are half floats");
    }
    PrecisionChoice { surface: gpu.texture_format, cube: gpu.cube_format, why }
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
    }
}
