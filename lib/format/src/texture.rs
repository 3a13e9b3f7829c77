//! A decoded texture: every plane of one layer at one parameter point (SPEC.md,
//! "Reconstructing a texture").

use pis_codec::PlaneShape;

use crate::mip::{mip_count, mip_size};
use crate::model::{Block, Layer, MipMode, Placement};

/// The planes of a level image, in codestream order: for each face, MIP levels 0.. .
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LevelLayout {
    pub width: u32,
    pub height: u32,
    pub channels: u32,
    pub faces: u32,
    /// MIP levels stored per face (1 when the player decimates).
    pub mips: u32,
}

impl LevelLayout {
    pub fn of<S>(layer: &Layer<S>, block: &Block<S>) -> Self {
        let faces = match block.placement {
            Placement::Surface { .. } => 1,
            Placement::Shell { shape, .. } => shape.faces(),
        };
        let mips = match layer.mip_mode {
            MipMode::Decimated => 1,
            MipMode::Stored => mip_count(block.width, block.height),
        };
        LevelLayout {
            width: block.width,
            height: block.height,
            channels: layer.channels as u32,
            faces,
            mips,
        }
    }

    pub fn planes(&self) -> Vec<PlaneShape> {
        let mut out = Vec::with_capacity((self.faces * self.mips) as usize);
        for _ in 0..self.faces {
            for m in 0..self.mips {
                let (w, h) = mip_size(self.width, self.height, m);
                out.push(PlaneShape::new(w, h, self.channels));
            }
        }
        out
    }
}

/// A layer's texture at one parameter point, linear radiance (alpha straight).
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    pub layout: LevelLayout,
    /// All planes, concatenated in [`LevelLayout::planes`] order.
    pub data: Vec<f32>,
}

impl Texture {
    /// The values of MIP level `mip` of face `face`.
    pub fn plane(&self, face: u32, mip: u32) -> &[f32] {
        let planes = self.layout.planes();
        let idx = (face * self.layout.mips + mip) as usize;
        let start: usize =
            planes[..idx].iter().map(|p| (p.width * p.height * p.channels) as usize).sum();
        let p = planes[idx];
        &self.data[start..start + (p.width * p.height * p.channels) as usize]
    }
}
