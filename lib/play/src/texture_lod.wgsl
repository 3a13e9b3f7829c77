// The level of detail of an isotropic lookup, shared by the textured-object pipeline
// (textured.wgsl), the player's frame (frame/frame.wgsl) and the shells (shell.wgsl, whose
// cube lookups take it per face): prepended to each at build time. The twin of pis-compile's
// hardware model (lod.rs), with the same order of operations: change them together.

// The Vulkan LOD for isotropic filtering: λ = clamp(log2(max(ρx, ρy)), 0, max_level).
fn texture_lod(ddx: vec2<f32>, ddy: vec2<f32>, size: vec2<f32>, max_level: f32) -> f32 {
    let rho_x = sqrt((ddx.x * size.x) * (ddx.x * size.x) + (ddx.y * size.y) * (ddx.y * size.y));
    let rho_y = sqrt((ddy.x * size.x) * (ddy.x * size.x) + (ddy.y * size.y) * (ddy.y * size.y));
    let rho = max(max(rho_x, rho_y), 1e-30);
    return clamp(log2(rho), 0.0, max(max_level, 0.0));
}
