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
    /// Trilinear lookups spread along the pixel footprint's major axis, with at most this
    /// many lookups (the sampler's anisotropy clamp, 1..=16). The adapter chooses the taps
    /// (no specification pins them down), so the hardware model does not describe this
    /// filter: its render matrix is measured through the GPU (probe mode, thesis 3.4.3).
    Anisotropic(u8),
}

/// The largest anisotropy clamp a sampler may ask for (WebGPU and Vulkan: 16).
pub const MAX_ANISOTROPY: u8 = 16;

impl Filter {
    /// True when the filter reads the coarser MIP levels (trilinear and anisotropic).
    pub fn uses_mips(self) -> bool {
        matches!(self, Filter::Trilinear | Filter::Anisotropic(_))
    }

    /// The filter's name as pis-pack records it (`filter` provenance setting).
    pub fn name(self) -> &'static str {
        match self {
            Filter::Nearest => "nearest",
            Filter::Bilinear => "bilinear",
            Filter::Trilinear => "trilinear",
            Filter::Anisotropic(_) => "anisotropic",
        }
    }
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
