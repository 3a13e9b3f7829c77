//! The unknown vector x: every texel of every MIP level of one texture.

use pis_format::mip::{mip_count, mip_size};

/// A texture of `width × height` used texels with `levels` MIP levels (sizes halve with
/// rounding up, SPEC.md 8.3). x holds level 0's texels row by row (row 0 = t near 0), then
/// level 1's, and so on; one scalar per texel (the colour channels share A, thesis 3.4).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct TextureLayout {
    pub width: u32,
    pub height: u32,
    pub levels: u32,
}

impl Default for TextureLayout {
    /// A single texel.
    fn default() -> Self {
        TextureLayout { width: 1, height: 1, levels: 1 }
    }
}

impl TextureLayout {
    /// A texture with its whole MIP chain.
    pub fn full(width: u32, height: u32) -> Self {
        TextureLayout { width, height, levels: mip_count(width, height) }
    }

    /// Size of MIP level `m`.
    pub fn level_size(&self, m: u32) -> (u32, u32) {
        mip_size(self.width, self.height, m)
    }

    /// Index in x of the first texel of level `m`.
    pub fn level_offset(&self, m: u32) -> usize {
        (0..m).map(|l| { let (w, h) = self.level_size(l); w as usize * h as usize }).sum()
    }

    /// Index in x of texel (i, j) of level `m`.
    pub fn texel(&self, m: u32, i: u32, j: u32) -> usize {
        let (w, _) = self.level_size(m);
        self.level_offset(m) + j as usize * w as usize + i as usize
    }

    /// n_t: the length of x.
    pub fn texel_count(&self) -> usize {
        self.level_offset(self.levels)
    }
}
