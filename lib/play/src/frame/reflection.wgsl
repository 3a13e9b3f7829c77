// The player's reflection term (appended to shell.wgsl; SPEC.md 8.2 and 9, thesis ch. 5):
// one additive draw per reflective object and parameter sample, in the frame's layer pass
// after the surface layers and with its depth (`vs_reflection` computes the clip position
// as frame.wgsl's `vs_main` does, so the depth test passes on exactly the id pass's
// surface). At the pixel's interpolated world position P and normal N, with E the frame's
// camera position, every shell of the term (order 0 nearest) is looked up as the hardware
// model does (lookup_direction, cube_lod from the fine derivatives of the lookup vector,
// cube_sample), the shells are composited "over" with premultiplied colours, and the
// result times Schlick's Fresnel factor and the sample's blending weight adds to the frame
// wherever the pixel's nearest surface is this object (frame.wgsl's `fs_layer` masking).

// One shell of the term: origin and shape id, `a`, `b` (shell.rs `shell_uniform`) and the
// cube map's face size N, MIP level count and lookups per pixel side.
struct ShellSlot {
    origin_shape: vec4<f32>,
    a: vec4<f32>,
    b: vec4<f32>,
    size_levels: vec4<u32>,
};

struct ReflectionUniforms {
    // projection · view · world of the object.
    clip_from_object: mat4x4<f32>,
    // world of the object (rigid): positions and normals to world space.
    world_from_object: mat4x4<f32>,
    // The frame's camera position E (xyz).
    eye: vec4<f32>,
    // The object's f0 (xyz) and this parameter sample's blending weight (w).
    f0_weight: vec4<f32>,
    // The term's shells in order; `count` of them (1 or 2) are used.
    shells: array<ShellSlot, 2>,
    // The object's index in the file.
    object: u32,
    count: u32,
    _pad1: u32,
    _pad2: u32,
};

@group(0) @binding(0) var<uniform> ru: ReflectionUniforms;
// The cube maps of shells 0 and 1 (shell 0's again when the term has one shell).
@group(0) @binding(1) var cube0: texture_2d_array<f32>;
@group(0) @binding(2) var cube1: texture_2d_array<f32>;
// The depth cubes of shells 0 and 1 where they are depth shells (a 1-texel stand-in else).
@group(0) @binding(3) var depth0: texture_2d_array<f32>;
@group(0) @binding(4) var depth1: texture_2d_array<f32>;
@group(1) @binding(0) var ids: texture_2d<u32>;
@group(1) @binding(1) var ids_ms: texture_multisampled_2d<u32>;

struct ReflectionVsOut {
    @invariant @builtin(position) clip: vec4<f32>,
    // World position and normal, interpolated perspective-correct.
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
};

fn shell_geometry_of(k: u32) -> ShellGeometry {
    let s = ru.shells[k];
    return ShellGeometry(s.origin_shape.xyz, u32(s.origin_shape.w), s.a.xyz, s.b.xyz);
}

// Shell k's premultiplied RGBA at world position p with normal n: the trilinear, seamless
// lookup of `cube`, once or k × k times over the pixel (size_levels.z; `cube_sample_pixel`),
// a depth shell marched against `depth`.
fn shell_colour(k: u32, cube: texture_2d_array<f32>, depth: texture_2d_array<f32>, p: vec3<f32>, n: vec3<f32>) -> vec4<f32> {
    let sl = ru.shells[k].size_levels;
    return cube_sample_pixel(shell_geometry_of(k), cube, depth, sl.x, sl.y, sl.z, ru.eye.xyz, p, n);
}

// The reflection term (SPEC.md 9): the shells composited "over" in increasing order,
// rgb = rgb₀ + (1 − α₀)·rgb₁ (a 3-channel shell's texels have α = 1).
fn reflection_term(p: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    let c0 = shell_colour(0u, cube0, depth0, p, n);
    if (ru.count < 2u) {
        return c0.rgb;
    }
    let c1 = shell_colour(1u, cube1, depth1, p, n);
    return c0.rgb + (1.0 - c0.a) * c1.rgb;
}

// weight · F ⊙ reflection term at the fragment.
fn reflection_radiance(in: ReflectionVsOut) -> vec3<f32> {
    let term = reflection_term(in.world, in.normal);
    let f = fresnel(ru.f0_weight.xyz, in.world, in.normal, ru.eye.xyz);
    return ru.f0_weight.w * f * term;
}

@vertex
fn vs_reflection(@location(0) position: vec3<f32>, @location(2) normal: vec3<f32>) -> ReflectionVsOut {
    var out: ReflectionVsOut;
    out.clip = ru.clip_from_object * vec4<f32>(position, 1.0);
    out.world = (ru.world_from_object * vec4<f32>(position, 1.0)).xyz;
    out.normal = (ru.world_from_object * vec4<f32>(normal, 0.0)).xyz;
    return out;
}

@fragment
fn fs_reflection(in: ReflectionVsOut) -> @location(0) vec4<f32> {
    let c = reflection_radiance(in);
    if (textureLoad(ids, vec2<i32>(in.clip.xy), 0).r != ru.object) {
        discard;
    }
    // Colour adds up over layers, terms and samples; alpha (blended with max) marks coverage.
    return vec4<f32>(c, 1.0);
}

struct ReflectionSamples {
    @location(0) colour: vec4<f32>,
    @builtin(sample_mask) mask: u32,
};

// `fs_reflection` for multisampled targets, as frame.wgsl's `fs_layer_ms`: shaded once per
// pixel at its centre, written to the samples the triangle covers whose nearest surface is
// this object.
@fragment
fn fs_reflection_ms(in: ReflectionVsOut, @builtin(sample_mask) covered: u32) -> ReflectionSamples {
    let c = reflection_radiance(in);
    let pixel = vec2<i32>(in.clip.xy);
    var mask = 0u;
    for (var i = 0u; i < textureNumSamples(ids_ms); i = i + 1u) {
        if ((covered & (1u << i)) != 0u && textureLoad(ids_ms, pixel, i32(i)).r == ru.object) {
            mask = mask | (1u << i);
        }
    }
    if (mask == 0u) {
        discard;
    }
    var out: ReflectionSamples;
    out.colour = vec4<f32>(c, 1.0);
    out.mask = mask;
    return out;
}
