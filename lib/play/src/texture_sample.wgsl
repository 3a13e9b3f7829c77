// The texture lookup, shared by the textured-object pipeline (textured.wgsl) and the
// player's frame (frame/frame.wgsl): prepended to both at build time (textured.rs,
// frame/pipelines.rs). At the hardware model's LOD λ (texture_lod.wgsl), or, for
// anisotropic filtering, from the same fine derivatives (scaled onto the allocated texture
// like the coordinates) so that the adapter chooses its anisotropic footprint and LOD as an
// implicit-derivative lookup would (no model twin).
//
// The shader this is prepended to declares the texture `tex`, the sampler `samp` and the
// uniform `u` with the allocated texture's `scale` (vec2<f32>) and `anisotropic` (u32: 1 for
// anisotropic filtering).

fn sample(st: vec2<f32>, ddx: vec2<f32>, ddy: vec2<f32>, lambda: f32) -> vec4<f32> {
    if (u.anisotropic != 0u) {
        return textureSampleGrad(tex, samp, st * u.scale, ddx * u.scale, ddy * u.scale);
    }
    return textureSampleLevel(tex, samp, st * u.scale, lambda);
}
