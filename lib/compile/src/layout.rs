//! The unknown vector x: every texel of every MIP level of one texture.

use pis_format::mip::{mip_count, mip_size};

/// A texture of `width × height` used texels with `levels` MIP levels (sizes halve with
/// rounding up, SPEC.md 8.3). x holds level 0's texels row by row (row 0 = t near 0), then
/// level 1's, and so on; one scalar per texel (the colour channels share A, thesis 3.4).
///
/// A cube map (an environment-map shell, SPEC.md 8.1–8.2) has `faces` = 6 square faces, each
/// with its own MIP chain, stored face after face in the order +X, −X, +Y, −Y, +Z, −Z: the
/// planes' order in a level image. A surface texture has one face.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct TextureLayout {
    pub width: u32,
    pub height: u32,
    pub levels: u32,
    pub faces: u32,
}

impl Default for TextureLayout {
    /// A single texel.
    fn default() -> Self {
        TextureLayout { width: 1, height: 1, levels: 1, faces: 1 }
    }
}

impl TextureLayout {
    /// A texture with its whole MIP chain.
    pub fn full(width: u32, height: u32) -> Self {
        TextureLayout { width, height, levels: mip_count(width, height), faces: 1 }
    }

    /// A single-face texture with `levels` MIP levels.
    pub fn new(width: u32, height: u32, levels: u32) -> Self {
        TextureLayout { width, height, levels, faces: 1 }
    }

    /// A cube map of six `size × size` faces, each with its whole MIP chain.
    pub fn cube(size: u32) -> Self {
        TextureLayout { width: size, height: size, levels: mip_count(size, size), faces: 6 }
    }

    /// Size of MIP level `m`.
    pub fn level_size(&self, m: u32) -> (u32, u32) {
        mip_size(self.width, self.height, m)
    }

    /// Index in x of the first texel of level `m` (of face 0; add [`Self::face_offset`]).
    pub fn level_offset(&self, m: u32) -> usize {
        (0..m)
            .map(|l| {
                let (w, h) = self.level_size(l);
                w as usize * h as usize
            })
            .sum()
    }

    /// Index in x of texel (i, j) of level `m` (of face 0).
    pub fn texel(&self, m: u32, i: u32, j: u32) -> usize {
        let (w, _) = self.level_size(m);
        self.level_offset(m) + j as usize * w as usize + i as usize
    }

    /// Index in x of texel (i, j) of level `m` of face `face`.
    pub fn face_texel(&self, face: u32, m: u32, i: u32, j: u32) -> usize {
        self.face_offset(face) + self.texel(m, i, j)
    }

    /// Texels of one face's MIP chain.
    pub fn face_len(&self) -> usize {
        self.level_offset(self.levels)
    }

    /// Index in x of the first texel of face `face`.
    pub fn face_offset(&self, face: u32) -> usize {
        face as usize * self.face_len()
    }

    /// n_t: the length of x.
    pub fn texel_count(&self) -> usize {
        self.faces.max(1) as usize * self.face_len()
    }
}
