// The translucent objects laid over the opaque surfaces (translucent.rs; SPEC.md 9): per
// sample, the translucent target's premultiplied colour C and opacity A, drawn with the
// blending "one, one minus source alpha" into the frame, so that
//
//   frame = C + (1 − A) · frame
//
// for colour and alpha alike. `fs_composite_ms` reads the sample it shades: taking
// `sample_index` runs it once per sample.

@group(0) @binding(0) var layer: texture_2d<f32>;
@group(0) @binding(1) var layer_ms: texture_multisampled_2d<f32>;

// One triangle covering the target.
@vertex
fn vs_full(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let x = f32((i << 1u) & 2u);
    let y = f32(i & 2u);
    return vec4<f32>(x * 2.0 - 1.0, 1.0 - y * 2.0, 0.0, 1.0);
}

@fragment
fn fs_composite(@builtin(position) p: vec4<f32>) -> @location(0) vec4<f32> {
    return textureLoad(layer, vec2<i32>(p.xy), 0);
}

@fragment
fn fs_composite_ms(
    @builtin(position) p: vec4<f32>,
    @builtin(sample_index) s: u32,
) -> @location(0) vec4<f32> {
    return textureLoad(layer_ms, vec2<i32>(p.xy), i32(s));
}
