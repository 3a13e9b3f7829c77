// A relightable layer's texture under the frame's lights (SPEC.md 9; Wong et al.): every
// texel of the finest level is Σ_c w_c · x_c, the coefficient textures x_c (the layers of
// one term, order and parameter sample, gathered as the slices of an array) weighted per
// channel by the lights' weights w_c. The twin of pis-compile's `relight::sum_coefficients`;
// the coarser levels are decimated from it (mip.wgsl), and filtering is linear, so drawing
// the sum is drawing each coefficient times its weight, added.

struct Sum {
    // Coefficient slices to add.
    count: u32,
    _pad: u32,
    // Used size of the finest level.
    used: vec2<u32>,
    // Its allocated size: the padding is written too, since a clamped lookup past the used
    // region reads it (and the coarser levels are decimated from it).
    alloc: vec2<u32>,
    _pad2: vec2<u32>,
    // Per slice c, w_c in rgb.
    weights: array<vec4<f32>, 81>,
};

@group(0) @binding(0) var<uniform> s: Sum;
@group(0) @binding(1) var coefficients: texture_2d_array<f32>;
@group(0) @binding(2) var dst: texture_storage_2d<FORMAT, write>;

@compute @workgroup_size(8, 8)
fn sum(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= s.used.x || id.y >= s.used.y) {
        return;
    }
    var acc = vec3<f32>(0.0, 0.0, 0.0);
    for (var c = 0u; c < s.count; c = c + 1u) {
        acc = acc + textureLoad(coefficients, id.xy, c, 0).rgb * s.weights[c].rgb;
    }
    // The padding repeats the last used column and row, as a decoded texture's does: the
    // texels of the last column and row write it, so each sum is made once.
    let last = s.used - vec2<u32>(1u, 1u);
    let end = select(id.xy + vec2<u32>(1u, 1u), s.alloc, id.xy == last);
    for (var y = id.y; y < end.y; y = y + 1u) {
        for (var x = id.x; x < end.x; x = x + 1u) {
            textureStore(dst, vec2<u32>(x, y), vec4<f32>(acc, 1.0));
        }
    }
}
