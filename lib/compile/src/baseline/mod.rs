//! The two baselines of thesis 3.3 that least-squares inference is measured against:
//! [`forward`] mapping (each texel mapped to the image and filtered there) and
//! [`traced`] textures (rays cast through supersampled texel centres). Neither knows how
//! the hardware filters; both fill what they cannot see by boundary reflection
//! ([`hole_fill`]) and build their MIP levels by decimation (`pis_format::mip`).

pub mod forward;
pub mod hole_fill;
pub mod lanczos;
pub mod texel_map;
pub mod traced;

use pis_format::mip::decimate;

use crate::TextureLayout;

/// An object's segmented image layer: `width × height` RGB radiance and which pixels the
/// object covers.
#[derive(Clone, Debug, PartialEq)]
pub struct LayerImage {
    pub width: u32,
    pub height: u32,
    /// Row-major RGB, y = 0 the top row.
    pub rgb: Vec<f32>,
    pub covered: Vec<bool>,
}

/// Level 0 (`layout.width × layout.height × 3`) and its decimated MIP levels, in the order
/// of [`TextureLayout`].
pub fn with_mip_levels(level0: Vec<f32>, layout: &TextureLayout) -> Vec<f32> {
    let mut out = level0.clone();
    let mut cur = level0;
    for m in 1..layout.levels {
        let (w, h) = layout.level_size(m - 1);
        cur = decimate(&cur, w, h, 3);
        out.extend_from_slice(&cur);
    }
    out
}

#[cfg(test)]
mod tests;
