// A lens object's tessellation drawn with one shell for one term (appended to shell.wgsl):
// the pipeline that pis-compile's `hybrid::model::hybrid_render_matrix` is checked against.
// Each corner carries its triangle's cube vector (the outgoing ray's hit on the shell minus
// the shell's origin, from the per-frame vertex rays); the vector is interpolated
// perspective-correct and looked up as a shell's reflection direction is (cube_lod from fine
// derivatives, cube_sample over every stored level).

struct HybridUniforms {
    clip_from_world: mat4x4<f32>,
    // Face size N, MIP level count.
    size: u32,
    levels: u32,
    _pad: vec2<u32>,
};

@group(0) @binding(0) var<uniform> hu: HybridUniforms;
@group(0) @binding(1) var cube: texture_2d_array<f32>;

struct HybridVsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) vector: vec3<f32>,
};

@vertex
fn vs_hybrid(@location(0) position: vec3<f32>, @location(1) vector: vec3<f32>) -> HybridVsOut {
    var out: HybridVsOut;
    out.clip = hu.clip_from_world * vec4<f32>(position, 1.0);
    out.vector = vector;
    return out;
}

@vertex
fn vs_hybrid_depth(@location(0) position: vec3<f32>) -> @builtin(position) vec4<f32> {
    return hu.clip_from_world * vec4<f32>(position, 1.0);
}

@fragment
fn fs_hybrid(in: HybridVsOut) -> @location(0) vec4<f32> {
    let d = in.vector;
    let ddx = dpdxFine(d);
    let ddy = dpdyFine(d);
    let lambda = cube_lod(d, ddx, ddy, f32(hu.size), f32(hu.levels - 1u));
    let c = cube_sample(cube, hu.size, hu.levels, d, lambda);
    // Alpha 1 marks coverage.
    return vec4<f32>(c.rgb, 1.0);
}

@fragment
fn fs_hybrid_depth() -> @location(0) vec4<f32> {
    return vec4<f32>(0.0);
}
