// The player's textured-object pipeline. One function written twice: every function here has
// a twin of the same name in pis-compile's hardware model, with the same order of operations
// (fine derivatives: interpolate.rs; the sampler: filter.rs). Change both together. The
// texture math it shares with the player's frame is prepended at build time (textured.rs):
// texture_lod.wgsl (texture_lod: lod.rs) and texture_transform.wgsl (cut_uv, texcoord:
// transform.rs).

struct Uniforms {
    // projection · view · world of the object.
    clip_from_object: mat4x4<f32>,
    // The block's affine texture transform (SPEC.md 7.3): (a, b, c, d) and (e, f).
    affine_abcd: vec4<f32>,
    affine_ef: vec2<f32>,
    // Used size of level 0 in texels (w, h).
    size: vec2<f32>,
    // Used size / allocated size per axis: maps (s, t) ∈ [0, 1]² onto the used region.
    scale: vec2<f32>,
    // Largest level of detail: levels − 1 for trilinear and anisotropic, 0 for nearest and
    // bilinear.
    max_level: f32,
    // 1 for anisotropic filtering: the adapter picks footprint and LOD (no model twin).
    anisotropic: u32,
    // The block's branch cuts (SPEC.md 7.3): (u_cut, v_cut, 1 if cut along u, 1 if cut
    // along v).
    cut: vec4<f32>,
};

@group(0) @binding(0) var<uniform> u: Uniforms;
@group(0) @binding(1) var tex: texture_2d<f32>;
@group(0) @binding(2) var samp: sampler;

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    // (s, t), interpolated perspective-correct.
    @location(0) st: vec2<f32>,
};

@vertex
fn vs_main(@location(0) position: vec3<f32>, @location(1) uv: vec2<f32>) -> VsOut {
    var out: VsOut;
    out.clip = u.clip_from_object * vec4<f32>(position, 1.0);
    out.st = texcoord(uv);
    return out;
}

// Depth-only pass of the occluders.
@vertex
fn vs_depth(@location(0) position: vec3<f32>) -> @builtin(position) vec4<f32> {
    return u.clip_from_object * vec4<f32>(position, 1.0);
}

@fragment
fn fs_main(in: VsOut) -> @location(0) vec4<f32> {
    // Fine derivatives: differences across the pixel's row and column of its 2×2 quad.
    let ddx = dpdxFine(in.st);
    let ddy = dpdyFine(in.st);
    let lambda = texture_lod(ddx, ddy, u.size, u.max_level);
    let c = sample(in.st, ddx, ddy, lambda);
    // Alpha 1 marks coverage.
    return vec4<f32>(c.rgb, 1.0);
}
