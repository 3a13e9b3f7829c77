// Textures rebuilt from their level images on the GPU (SPEC.md 8.4 steps 2-4), the twin of
// decode.rs's `reconstruct`, `assemble` and `assemble_cube` at full resolution: the
// pyramid's level images summed top first (the encoder's prediction order), the inverse
// gamma of pis-codec's `gamma::uncompensate` (its `pow_11_5` for the default 2.2, step for
// step), the texel widened to RGBA as `rgba_texel` does.
// - `rebuild`: a surface texture's finest level, into the padded layout (textured.rs) with
//   the last used column and row repeated into the padding; mip.wgsl decimates the chain.
// - `cube_level`: one MIP level of a cube map's six faces; for a stored level below the
//   finest, the finest level decimated to its size (`src`) is added, as pis-format's
//   `add_stored_mips` does.
// - `cube_decimate`: one level of six faces decimated from the level above (`src`), the box
//   filter of pis-format's `mip::decimate` as in mip.wgsl.

struct Params {
    // Used size of the texture.
    used: vec2<u32>,
    // Allocated (padded) size of its finest level.
    alloc: vec2<u32>,
    channels: u32,
    // Level images stacked in `stack`, top first.
    levels: u32,
    // 32-bit words from one level image to the next in `stack`: its values (used.x * used.y
    // * channels), or where LEVEL16 two words and half its values rounded up.
    plane: u32,
    // 0: identity (gamma 1), 1: pow_11_5 (gamma 2.2), 2: sign(v) |v|^gamma.
    mode: u32,
    gamma: f32,
    // Cube maps: values before this MIP level's plane within a face, and per face.
    offset: u32,
    face_len: u32,
    // cube_level: 1 adds `src` (the finest level decimated to this size).
    add: u32,
};

@group(0) @binding(0) var<uniform> p: Params;
// The level images: 32-bit floats, or where LEVEL16 each its lo and step, then its values in
// 16 bits two to a word, the first in the low half (rebuild.rs `level16_words`; pis-format's
// `Level16`: lo + q · step).
@group(0) @binding(1) var<storage, read> stack: array<u32>;
override LEVEL16: bool = false;
@group(0) @binding(2) var dst: texture_storage_2d<SURFACE_FORMAT, write>;
@group(0) @binding(3) var cube_dst: texture_storage_2d_array<CUBE_FORMAT, write>;
@group(0) @binding(4) var src: texture_2d_array<f32>;

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

// Value `e` of level image `k` of the stack, as 32 bits.
fn level_value(k: u32, e: u32) -> f32 {
    let base = k * p.plane;
    if (LEVEL16) {
        let q = (stack[base + 2u + (e >> 1u)] >> (16u * (e & 1u))) & 0xFFFFu;
        return bitcast<f32>(stack[base]) + f32(q) * bitcast<f32>(stack[base + 1u]);
    }
    return bitcast<f32>(stack[base + e]);
}

// Channel `ch` of the texel at `at`: the level images summed, then the inverse gamma.
fn value(at: u32, ch: u32) -> f32 {
    var s = level_value(0u, at + ch);
    for (var k = 1u; k < p.levels; k++) {
        s = s + level_value(k, at + ch);
    }
    return linear(s);
}

// The texel whose channels start at `at`, as RGBA: grey for 1 channel, grey and alpha for
// 2, opaque RGB for 3.
fn texel(at: u32) -> vec4<f32> {
    if (p.channels == 1u) {
        let g = value(at, 0u);
        return vec4<f32>(g, g, g, 1.0);
    } else if (p.channels == 2u) {
        let g = value(at, 0u);
        return vec4<f32>(g, g, g, value(at, 1u));
    } else if (p.channels == 3u) {
        return vec4<f32>(value(at, 0u), value(at, 1u), value(at, 2u), 1.0);
    }
    return vec4<f32>(value(at, 0u), value(at, 1u), value(at, 2u), value(at, 3u));
}

@compute @workgroup_size(8, 8)
fn rebuild(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= p.alloc.x || id.y >= p.alloc.y) {
        return;
    }
    let i = min(id.x, p.used.x - 1u);
    let j = min(id.y, p.used.y - 1u);
    textureStore(dst, vec2<u32>(id.x, id.y), texel((j * p.used.x + i) * p.channels));
}

@compute @workgroup_size(8, 8, 1)
fn cube_level(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= p.used.x || id.y >= p.used.y || id.z >= 6u) {
        return;
    }
    let at = id.z * p.face_len + p.offset + (id.y * p.used.x + id.x) * p.channels;
    var t = texel(at);
    if (p.add == 1u) {
        // The decimated finest level, widened as its channels were: alpha is a channel
        // only for 2 and 4 (else 1, and stays 1).
        let d = textureLoad(src, vec2<u32>(id.x, id.y), id.z, 0);
        t = vec4<f32>(t.rgb + d.rgb, select(t.a, t.a + d.a, p.channels % 2u == 0u));
    }
    textureStore(cube_dst, vec2<u32>(id.x, id.y), id.z, t);
}

@compute @workgroup_size(8, 8, 1)
fn cube_decimate(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= p.used.x || id.y >= p.used.y || id.z >= 6u) {
        return;
    }
    // `alloc` holds the source level's size here.
    let x0 = 2u * id.x;
    let x1 = min(2u * id.x + 1u, p.alloc.x - 1u);
    let y0 = 2u * id.y;
    let y1 = min(2u * id.y + 1u, p.alloc.y - 1u);
    let a = textureLoad(src, vec2<u32>(x0, y0), id.z, 0);
    let b = textureLoad(src, vec2<u32>(x1, y0), id.z, 0);
    let c = textureLoad(src, vec2<u32>(x0, y1), id.z, 0);
    let d = textureLoad(src, vec2<u32>(x1, y1), id.z, 0);
    textureStore(cube_dst, vec2<u32>(id.x, id.y), id.z, 0.25 * (((a + b) + c) + d));
}
