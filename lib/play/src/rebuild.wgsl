// A surface texture rebuilt from its level images on the GPU (SPEC.md 8.4 steps 2-3), the
// twin of decode.rs's `reconstruct` and `assemble` for a decimated MIP chain at full
// resolution: the pyramid's level images summed top first (the encoder's prediction order),
// the inverse gamma of pis-codec's `gamma::uncompensate` (its `pow_11_5` for the default
// 2.2, step for step), the texel widened to RGBA as `rgba_texel` does, written into the
// finest level of the padded layout (textured.rs) with the last used column and row
// repeated into the padding. mip.wgsl then decimates the chain.

struct Params {
    // Used size of the texture.
    used: vec2<u32>,
    // Allocated (padded) size of its finest level.
    alloc: vec2<u32>,
    channels: u32,
    // Level images stacked in `stack`, top first.
    levels: u32,
    // Values per level image: used.x * used.y * channels.
    plane: u32,
    // 0: identity (gamma 1), 1: pow_11_5 (gamma 2.2), 2: sign(v) |v|^gamma.
    mode: u32,
    gamma: f32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
};

@group(0) @binding(0) var<uniform> p: Params;
@group(0) @binding(1) var<storage, read> stack: array<f32>;
@group(0) @binding(2) var dst: texture_storage_2d<FORMAT, write>;

// pis-codec's pow_11_5: sign(v) |v|^(11/5) as |v|^2 |v|^(1/5), the fifth root by three
// Newton steps from a guess made of the exponent bits.
fn pow_11_5(v: f32) -> f32 {
    let a = abs(v);
    var y = bitcast<f32>(bitcast<u32>(a) / 5u + 0x32CCCCCDu);
    for (var k = 0; k < 3; k++) {
        let y2 = y * y;
        y = 0.8 * y + 0.2 * a / (y2 * y2);
    }
    var r = a * a * y;
    if (bitcast<u32>(a) == 0x7F800000u) {
        r = a;
    }
    return bitcast<f32>((bitcast<u32>(r) & 0x7FFFFFFFu) | (bitcast<u32>(v) & 0x80000000u));
}

fn linear(v: f32) -> f32 {
    if (p.mode == 0u) {
        return v;
    }
    if (p.mode == 1u) {
        return pow_11_5(v);
    }
    if (v == 0.0) {
        return v;
    }
    return sign(v) * pow(abs(v), p.gamma);
}

// Channel `ch` of the texel at `at`: the level images summed, then the inverse gamma.
fn value(at: u32, ch: u32) -> f32 {
    var s = stack[at + ch];
    for (var k = 1u; k < p.levels; k++) {
        s = s + stack[k * p.plane + at + ch];
    }
    return linear(s);
}

@compute @workgroup_size(8, 8)
fn rebuild(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= p.alloc.x || id.y >= p.alloc.y) {
        return;
    }
    let i = min(id.x, p.used.x - 1u);
    let j = min(id.y, p.used.y - 1u);
    let at = (j * p.used.x + i) * p.channels;
    var t: vec4<f32>;
    if (p.channels == 1u) {
        let g = value(at, 0u);
        t = vec4<f32>(g, g, g, 1.0);
    } else if (p.channels == 2u) {
        let g = value(at, 0u);
        t = vec4<f32>(g, g, g, value(at, 1u));
    } else if (p.channels == 3u) {
        t = vec4<f32>(value(at, 0u), value(at, 1u), value(at, 2u), 1.0);
    } else {
        t = vec4<f32>(value(at, 0u), value(at, 1u), value(at, 2u), value(at, 3u));
    }
    textureStore(dst, vec2<u32>(id.x, id.y), t);
}
