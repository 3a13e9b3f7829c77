//! The MIP level of detail λ from screen-space derivatives, as the Vulkan specification
//! defines it for isotropic filtering (chapter "Texel Filtering", "Scale Factor Operation,
//! Level-of-Detail Operation"): with u = s·width, v = t·height of the base level,
//!
//! ```text
//! ρx = √((∂u/∂x)² + (∂v/∂x)²)    ρy = √((∂u/∂y)² + (∂v/∂y)²)
//! λ  = clamp(log2(max(ρx, ρy)), 0, max_level)
//! ```
//!
//! The player's fragment shader evaluates the same formula (`texture_lod` in
//! `texture_lod.wgsl`) and passes λ to `textureSampleLevel`, so no implementation's
//! approximation of ρ (the spec allows several) or per-quad LOD enters.

/// λ for derivatives `ddx`, `ddy` of (s, t), a base level of `size` texels, clamped to
/// `[0, max_level]`.
pub fn texture_lod(ddx: [f64; 2], ddy: [f64; 2], size: [f64; 2], max_level: f64) -> f64 {
    let rho_x = ((ddx[0] * size[0]).powi(2) + (ddx[1] * size[1]).powi(2)).sqrt();
    let rho_y = ((ddy[0] * size[0]).powi(2) + (ddy[1] * size[1]).powi(2)).sqrt();
    let rho = rho_x.max(rho_y).max(1e-30);
    rho.log2().clamp(0.0, max_level.max(0.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_to_one_minification_is_level_one() {
        // 2 texels per pixel along x on a 64-texel texture.
        let l = texture_lod([2.0 / 64.0, 0.0], [0.0, 1.0 / 64.0], [64.0, 64.0], 6.0);
        assert!((l - 1.0).abs() < 1e-12);
    }

    #[test]
    fn magnification_and_overflow_clamp() {
        assert_eq!(texture_lod([0.001, 0.0], [0.0, 0.001], [64.0, 64.0], 6.0), 0.0);
        assert_eq!(texture_lod([100.0, 0.0], [0.0, 0.0], [64.0, 64.0], 6.0), 6.0);
        assert_eq!(texture_lod([0.0; 2], [0.0; 2], [64.0, 64.0], 6.0), 0.0);
    }
}
