// A lens object's term in the player's frame (appended to shell.wgsl; SPEC.md 9, thesis
// 6.4): one additive draw per term and parameter sample, in the frame's layer pass after
// the surface layers. The vertices are the frame's tessellation of the lens object (world
// space), each corner carrying its triangle's F·G and, per shell of the term, the cube-map
// vector of the outgoing ray (its hit on the shell minus the shell's origin) with a flag in
// w: 1 where the triangle draws that shell. Per fragment every shell is looked up as
// hybrid_object.wgsl looks up one (cube_lod from the fine derivatives of the interpolated
// vector, cube_sample over every stored level), the shells are composited "over" in order
// (premultiplied colours) and the sum times the interpolated F·G and the sample's weight
// adds to the frame where the pixel's nearest surface is this object. pis-compile's
// `hybrid::term_radiance` is the twin of `hybrid_term`.

struct HybridFrameUniforms {
    clip_from_world: mat4x4<f32>,
    // Per shell slot: cube face size N and MIP level count (x, y).
    shells: array<vec4<u32>, 4>,
    // The sample's blending weight (x).
    weight: vec4<f32>,
    // The object's index in the file; the term's shell count (1 to 4).
    object: u32,
    count: u32,
    _pad1: u32,
    _pad2: u32,
};

@group(0) @binding(0) var<uniform> hf: HybridFrameUniforms;
@group(0) @binding(1) var lens_cube0: texture_2d_array<f32>;
@group(0) @binding(2) var lens_cube1: texture_2d_array<f32>;
@group(0) @binding(3) var lens_cube2: texture_2d_array<f32>;
@group(0) @binding(4) var lens_cube3: texture_2d_array<f32>;
@group(1) @binding(0) var ids: texture_2d<u32>;
@group(1) @binding(1) var ids_ms: texture_multisampled_2d<u32>;

struct HybridFrameVsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) fg: vec3<f32>,
    @location(1) v0: vec4<f32>,
    @location(2) v1: vec4<f32>,
    @location(3) v2: vec4<f32>,
    @location(4) v3: vec4<f32>,
};

// The tessellation lies on the mesh's triangles: its depth is pulled toward the camera by
// a few ulps of the depth range so that it passes the test against the id pass's depth of
// the same surface (LessEqual), not against a surface in front of it.
const LENS_DEPTH_PULL: f32 = 1e-5;

@vertex
fn vs_hybrid_frame(@location(0) position: vec3<f32>, @location(1) fg: vec3<f32>, @location(2) v0: vec4<f32>, @location(3) v1: vec4<f32>, @location(4) v2: vec4<f32>, @location(5) v3: vec4<f32>) -> HybridFrameVsOut {
    var out: HybridFrameVsOut;
    let clip = hf.clip_from_world * vec4<f32>(position, 1.0);
    out.clip = vec4<f32>(clip.xy, clip.z - LENS_DEPTH_PULL * clip.w, clip.w);
    out.fg = fg;
    out.v0 = v0;
    out.v1 = v1;
    out.v2 = v2;
    out.v3 = v3;
    return out;
}

// Shell k's premultiplied RGBA along the interpolated vector v (xyz) with derivatives
// ddx, ddy.
fn lens_shell(k: u32, v: vec3<f32>, ddx: vec3<f32>, ddy: vec3<f32>) -> vec4<f32> {
    let size = hf.shells[k].x;
    let levels = hf.shells[k].y;
    let lambda = cube_lod(v, ddx, ddy, f32(size), f32(levels - 1u));
    switch k {
        case 0u: { return cube_sample(lens_cube0, size, levels, v, lambda); }
        case 1u: { return cube_sample(lens_cube1, size, levels, v, lambda); }
        case 2u: { return cube_sample(lens_cube2, size, levels, v, lambda); }
        default: { return cube_sample(lens_cube3, size, levels, v, lambda); }
    }
}

// The term (SPEC.md 9): shells "over" in increasing order, rgb += through · c.rgb,
// through ·= 1 − clamp(c.a, 0, 1), shells the triangle does not draw skipped; times F·G.
fn hybrid_term(in: HybridFrameVsOut) -> vec3<f32> {
    // Derivatives first, in uniform control flow.
    var v = array<vec4<f32>, 4>(in.v0, in.v1, in.v2, in.v3);
    var dx = array<vec3<f32>, 4>(dpdxFine(in.v0.xyz), dpdxFine(in.v1.xyz), dpdxFine(in.v2.xyz), dpdxFine(in.v3.xyz));
    var dy = array<vec3<f32>, 4>(dpdyFine(in.v0.xyz), dpdyFine(in.v1.xyz), dpdyFine(in.v2.xyz), dpdyFine(in.v3.xyz));
    var acc = vec3<f32>(0.0);
    var through = 1.0;
    for (var k = 0u; k < hf.count; k = k + 1u) {
        if (v[k].w > 0.5) {
            let c = lens_shell(k, v[k].xyz, dx[k], dy[k]);
            acc = acc + through * c.rgb;
            through = through * (1.0 - clamp(c.a, 0.0, 1.0));
        }
    }
    return acc * in.fg;
}

@fragment
fn fs_hybrid_frame(in: HybridFrameVsOut) -> @location(0) vec4<f32> {
    let c = hybrid_term(in) * hf.weight.x;
    if (textureLoad(ids, vec2<i32>(in.clip.xy), 0).r != hf.object) {
        discard;
    }
    return vec4<f32>(c, 1.0);
}

struct HybridFrameSamples {
    @location(0) colour: vec4<f32>,
    @builtin(sample_mask) mask: u32,
};

// `fs_hybrid_frame` for multisampled targets, as frame.wgsl's `fs_layer_ms`.
@fragment
fn fs_hybrid_frame_ms(in: HybridFrameVsOut, @builtin(sample_mask) covered: u32) -> HybridFrameSamples {
    let c = hybrid_term(in) * hf.weight.x;
    let pixel = vec2<i32>(in.clip.xy);
    var mask = 0u;
    for (var i = 0u; i < textureNumSamples(ids_ms); i = i + 1u) {
        if ((covered & (1u << i)) != 0u && textureLoad(ids_ms, pixel, i32(i)).r == hf.object) {
            mask = mask | (1u << i);
        }
    }
    if (mask == 0u) {
        discard;
    }
    var out: HybridFrameSamples;
    out.colour = vec4<f32>(c, 1.0);
    out.mask = mask;
    return out;
}
