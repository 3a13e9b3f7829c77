//! The cube faces a byte budget can carry. A reader refuses a level image that decodes to
//! more than [`MAX_EXPANSION`] times the bytes of the file's codestreams (SPEC.md section 12,
//! rule 6009), so that no small file makes it allocate without bound. A shell's level image
//! holds every MIP level of its six faces, so a large face under a high ratio on a small set
//! would be solved and coded only for the writer to refuse the file: the face is capped
//! before anything is solved.

use pis_codec::CodecId;
use pis_format::checks::MAX_EXPANSION;

use super::super::plan::Plan;
use super::views::{LARGEST_FACE, MIN_FACE};

/// Bytes one level image of a cube map with `face`-texel faces decodes to: six faces, every
/// MIP level down to 1 × 1, `channels` values of 4 bytes per texel.
pub fn cube_level_image_bytes(face: u32, channels: u64) -> u64 {
    let texels: u64 = (0..=face.max(1).ilog2()).map(|l| ((face >> l) as u64).pow(2)).sum();
    6 * texels * channels * 4
}

/// The largest face a byte budget leaves a shell, and the budget.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FaceCap {
    pub face: u32,
    pub budget: u64,
}

impl FaceCap {
    /// The report's words for a shell at the cap, when the cap is below `largest`, the
    /// largest face without a budget.
    pub fn note(&self, largest: u32) -> Option<String> {
        (self.face < largest).then(|| format!(
            "; cube faces at most {0}² (the ratio leaves {1} bytes, and a level image may decode to at most {2} times the file's codestream bytes: SPEC.md section 12)",
            self.face, self.budget, MAX_EXPANSION))
    }
}

/// The face cap under `plan`'s ratio: a four-channel shell's level image within half of
/// [`MAX_EXPANSION`] times the level-image budget (the allocation may spend a little less
/// than the budget). `None` where no budget is set beforehand: a PSNR target, or the
/// lossless codec.
pub fn face_cap(plan: &Plan, codec: CodecId) -> Option<FaceCap> {
    if codec == CodecId::Lossless {
        return None;
    }
    let budget = plan.budget()?;
    Some(FaceCap { face: largest_face_within(MAX_EXPANSION.saturating_mul(budget) / 2), budget })
}

/// The largest power-of-two face, at least [`MIN_FACE`], whose four-channel level image
/// decodes to at most `bytes`.
fn largest_face_within(bytes: u64) -> u32 {
    let mut face = LARGEST_FACE;
    while face > MIN_FACE && cube_level_image_bytes(face, 4) > bytes {
        face /= 2;
    }
    face
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cube_level_image_holds_every_mip_level_of_six_faces() {
        // 2²: 4 + 1 texels a face
        assert_eq!(cube_level_image_bytes(2, 3), 6 * 5 * 3 * 4);
        // the figures the format's checks print for 128² and 256² three-channel shells
        assert_eq!(cube_level_image_bytes(128, 3), 1_572_840);
        assert_eq!(cube_level_image_bytes(256, 3), 6_291_432);
        assert_eq!(cube_level_image_bytes(1, 4), 6 * 4 * 4);
    }

    #[test]
    fn the_cap_is_the_largest_face_within_the_bound() {
        let exact = cube_level_image_bytes(64, 4);
        assert_eq!(largest_face_within(exact), 64);
        assert_eq!(largest_face_within(exact - 1), 32);
        assert_eq!(largest_face_within(u64::MAX), LARGEST_FACE);
        assert_eq!(largest_face_within(0), MIN_FACE);
        // 150 bytes (a 160 × 120 view at 384:1): half of 8192 × 150 fits 64² but not 128²
        assert_eq!(largest_face_within(MAX_EXPANSION * 150 / 2), 64);
    }
}
