//! The texture sampler state the player uses, which the hardware model reproduces.

/// Texture filtering (thesis 3.6 compares these).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Filter {
    /// Nearest texel of MIP level 0.
    Nearest,
    /// Bilinear on MIP level 0 only.
    Bilinear,
    /// Bilinear on the two MIP levels around the LOD, blended linearly.
    Trilinear,
}

/// Texture addressing outside [0, 1).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Address {
    ClampToEdge,
    Repeat,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Sampler {
    pub filter: Filter,
    /// Along s and t.
    pub address: [Address; 2],
}

impl Default for Sampler {
    fn default() -> Self {
        Sampler { filter: Filter::Trilinear, address: [Address::ClampToEdge; 2] }
    }
}
