// The player's frame: every object of the file, each layer of each drawn parameter sample
// added in linear space. Two passes share `vs_main`, so their depths are identical:
// `fs_id` writes depth and the object index (nearest surface wins), then `fs_layer` adds
// weight × texture wherever the pixel's nearest surface is this object.
//
// A translucent object (SPEC.md 9) is left out of the id pass and drawn after the opaque
// ones: its own id pass, nearest translucent surface in front of the opaque ones winning,
// then `fs_layer` adds its premultiplied colour and opacity into a target of its own
// (`alpha_mode`), which `composite.wgsl` lays over the opaque surfaces.
//
// Multisampled frames (multisample.rs) run the same passes with depth and object indices
// per sample: `fs_layer_ms` shades once per pixel, exactly as `fs_layer` does, and covers
// the samples whose nearest surface is this object; the resolve averages the samples.
//
// The reflection term of reflective objects is drawn in the same additive pass by
// reflection.wgsl, whose vertex shader computes the clip position as `vs_main` does.
//
// `cut_uv`, `texcoord` and `texture_lod`, the twins of pis-compile's hardware model, are
// textured.wgsl's: texture_lod.wgsl and texture_transform.wgsl, prepended at build time
// (pipelines.rs).

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
    // Multilinear weight of this parameter sample's texture.
    weight: f32,
    // The object's index in the file.
    object: u32,
    // 1 for anisotropic filtering: the adapter picks footprint and LOD (no model twin).
    anisotropic: u32,
    // What the output's alpha is (`layer_alpha`): 0, an opaque object's layer; 1, the
    // layer that carries a translucent object's opacity; 2, a translucent object's other
    // layers.
    alpha_mode: u32,
    _pad2: u32,
    // The block's branch cuts (SPEC.md 7.3): (u_cut, v_cut, 1 if cut along u, 1 if cut
    // along v).
    cut: vec4<f32>,
    // Per channel, what the texture's colour is multiplied by besides `weight`: a
    // relightable layer's coefficient weight for the frame's lights (SPEC.md 9), else 1.
    tint: vec4<f32>,
};

@group(0) @binding(0) var<uniform> u: Uniforms;
@group(0) @binding(1) var tex: texture_2d<f32>;
@group(0) @binding(2) var samp: sampler;
@group(1) @binding(0) var ids: texture_2d<u32>;
@group(1) @binding(1) var ids_ms: texture_multisampled_2d<u32>;

struct VsOut {
    @invariant @builtin(position) clip: vec4<f32>,
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

@fragment
fn fs_id(in: VsOut) -> @location(0) u32 {
    return u.object;
}

@fragment
fn fs_layer(in: VsOut) -> @location(0) vec4<f32> {
    // Fine derivatives: differences across the pixel's row and column of its 2×2 quad.
    let ddx = dpdxFine(in.st);
    let ddy = dpdyFine(in.st);
    let lambda = texture_lod(ddx, ddy, u.size, u.max_level);
    let c = sample(in.st, ddx, ddy, lambda);
    if (textureLoad(ids, vec2<i32>(in.clip.xy), 0).r != u.object) {
        discard;
    }
    return vec4<f32>(c.rgb * u.weight * u.tint.rgb, layer_alpha(c.a));
}

// The output's alpha for texel alpha `a`: an opaque object's layers mark coverage (blended
// with max); a translucent object's opacity adds up over samples (weight × opacity), its
// other layers add none.
fn layer_alpha(a: f32) -> f32 {
    switch u.alpha_mode {
        case 1u: { return a * u.weight; }
        case 2u: { return 0.0; }
        default: { return 1.0; }
    }
}

struct LayerSamples {
    @location(0) colour: vec4<f32>,
    @builtin(sample_mask) mask: u32,
};

// `fs_layer` for multisampled targets. Reading `sample_mask` (unlike `sample_index`) does
// not turn on per-sample shading: this runs once per pixel and fragment, at the pixel's
// centre, with `fs_layer`'s derivatives and LOD; only the samples it writes are chosen per
// sample, among those the triangle covers (and the depth test passes), by the object index.
@fragment
fn fs_layer_ms(in: VsOut, @builtin(sample_mask) covered: u32) -> LayerSamples {
    let ddx = dpdxFine(in.st);
    let ddy = dpdyFine(in.st);
    let lambda = texture_lod(ddx, ddy, u.size, u.max_level);
    let c = textureSampleLevel(tex, samp, in.st * u.scale, lambda);
    let pixel = vec2<i32>(in.clip.xy);
    var mask = 0u;
    for (var i = 0u; i < textureNumSamples(ids_ms); i = i + 1u) {
        if ((covered & (1u << i)) != 0u && textureLoad(ids_ms, pixel, i32(i)).r == u.object) {
            mask = mask | (1u << i);
        }
    }
    if (mask == 0u) {
        discard;
    }
    var out: LayerSamples;
    out.colour = vec4<f32>(c.rgb * u.weight * u.tint.rgb, layer_alpha(c.a));
    out.mask = mask;
    return out;
}
