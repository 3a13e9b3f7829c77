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
    // Per shell slot: cube face size N, MIP level count and lookups per pixel side (x, y, z).
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

// Interpolated per sample: in a multisampled frame the lens terms are shaded at every
// sample (the thesis's supersampled hybrid frames, 6.4), the refracted image's fast changes
// averaged by the resolve as the tracer's samples average them; single-sampled, at the
// pixel centre, as the model.
struct HybridFrameVsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) @interpolate(perspective, sample) fg: vec3<f32>,
    @location(1) @interpolate(perspective, sample) v0: vec4<f32>,
    @location(2) @interpolate(perspective, sample) v1: vec4<f32>,
    @location(3) @interpolate(perspective, sample) v2: vec4<f32>,
    @location(4) @interpolate(perspective, sample) v3: vec4<f32>,
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
// ddx, ddy, looked up in `cube`: with the shell's lookups L = 1 one trilinear lookup at the
// LOD of the derivatives; with L > 1 the mean of L × L lookups along v + o.x·ddx + o.y·ddy
// at the sub-pixel offsets o = ((i + ½)/L − ½, (j + ½)/L − ½), at the LOD of the
// derivatives divided by L (SPEC.md 8.2; pis-compile's `hybrid_render_matrix` is its twin).
fn lens_shell(k: u32, cube: texture_2d_array<f32>, v: vec3<f32>, ddx: vec3<f32>, ddy: vec3<f32>) -> vec4<f32> {
    let size = hf.shells[k].x;
    let levels = hf.shells[k].y;
    let lookups = hf.shells[k].z;
    let max_level = f32(levels - 1u);
    if (!SUB_PIXEL_LOOKUPS || lookups <= 1u) {
        return cube_sample(cube, size, levels, v, cube_lod(v, ddx, ddy, f32(size), max_level));
    }
    let kf = f32(lookups);
    let sx = ddx / kf;
    let sy = ddy / kf;
    let w = 1.0 / (kf * kf);
    var acc = vec4<f32>(0.0);
    for (var j = 0u; j < lookups; j = j + 1u) {
        let oy = (f32(j) + 0.5) / kf - 0.5;
        for (var i = 0u; i < lookups; i = i + 1u) {
            let ox = (f32(i) + 0.5) / kf - 0.5;
            let d = v + ox * ddx + oy * ddy;
            acc = acc + w * cube_sample(cube, size, levels, d, cube_lod(d, sx, sy, f32(size), max_level));
        }
    }
    return acc;
}

// One step of "over": the running colour and transmittance after shell colour c.
fn lens_over(acc: vec4<f32>, c: vec4<f32>) -> vec4<f32> {
    return vec4<f32>(acc.rgb + acc.a * c.rgb, acc.a * (1.0 - clamp(c.a, 0.0, 1.0)));
}

// The derivatives of the four shell vectors (fine: across the pixel's 2×2 quad), taken in
// uniform control flow before any fragment is discarded.
struct LensDerivatives {
    dx: array<vec3<f32>, 4>,
    dy: array<vec3<f32>, 4>,
};

fn lens_derivatives(in: HybridFrameVsOut) -> LensDerivatives {
    return LensDerivatives(
        array<vec3<f32>, 4>(dpdxFine(in.v0.xyz), dpdxFine(in.v1.xyz), dpdxFine(in.v2.xyz), dpdxFine(in.v3.xyz)),
        array<vec3<f32>, 4>(dpdyFine(in.v0.xyz), dpdyFine(in.v1.xyz), dpdyFine(in.v2.xyz), dpdyFine(in.v3.xyz)),
    );
}

// The term (SPEC.md 9): shells "over" in increasing order, rgb += through · c.rgb,
// through ·= 1 − clamp(c.a, 0, 1), shells the triangle does not draw skipped; times F·G.
// Behind an opaque shell (through exactly 0) the farther shells add exactly nothing and are
// not looked up.
fn hybrid_term(in: HybridFrameVsOut, d: LensDerivatives) -> vec3<f32> {
    var acc = vec4<f32>(0.0, 0.0, 0.0, 1.0);
    if (hf.count > 0u && in.v0.w > 0.5) {
        acc = lens_over(acc, lens_shell(0u, lens_cube0, in.v0.xyz, d.dx[0], d.dy[0]));
    }
    if (hf.count > 1u && in.v1.w > 0.5 && acc.a > 0.0) {
        acc = lens_over(acc, lens_shell(1u, lens_cube1, in.v1.xyz, d.dx[1], d.dy[1]));
    }
    if (hf.count > 2u && in.v2.w > 0.5 && acc.a > 0.0) {
        acc = lens_over(acc, lens_shell(2u, lens_cube2, in.v2.xyz, d.dx[2], d.dy[2]));
    }
    if (hf.count > 3u && in.v3.w > 0.5 && acc.a > 0.0) {
        acc = lens_over(acc, lens_shell(3u, lens_cube3, in.v3.xyz, d.dx[3], d.dy[3]));
    }
    return acc.rgb * in.fg;
}

@fragment
fn fs_hybrid_frame(in: HybridFrameVsOut) -> @location(0) vec4<f32> {
    let d = lens_derivatives(in);
    if (textureLoad(ids, vec2<i32>(in.clip.xy), 0).r != hf.object) {
        discard;
    }
    return vec4<f32>(hybrid_term(in, d) * hf.weight.x, 1.0);
}

struct HybridFrameSamples {
    @location(0) colour: vec4<f32>,
    @builtin(sample_mask) mask: u32,
};

// `fs_hybrid_frame` for multisampled targets, run once per sample (the inputs are
// interpolated per sample): the sample is written where the pixel's object index at it is
// this object.
@fragment
fn fs_hybrid_frame_ms(in: HybridFrameVsOut, @builtin(sample_mask) covered: u32) -> HybridFrameSamples {
    let d = lens_derivatives(in);
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
    out.colour = vec4<f32>(hybrid_term(in, d) * hf.weight.x, 1.0);
    out.mask = mask;
    return out;
}
