// The display-filter resolve of a multisampled frame (resolve.rs): per output pixel p, the
// samples of its 3×3 neighbourhood weighted by the ray-traced set's display filter
// w(d) = exp(−|d|² / 2σ²) for |d| ≤ R (d from p's centre, RAYSET.md section 4), grouped by
// the object index of each sample (the "no object" index too, whose colour is the cleared
// transparent black):
//
//   coverage_o = Σ w over o's samples / Σ w over all samples
//   radiance_o = the mean of p's own samples of o where p has some (textures are solved for
//                the pixel centre: interiors are not blurred), else the w-weighted mean of
//                o's samples in the neighbourhood
//   out        = Σ_o coverage_o · radiance_o   (RGBA: alpha is the filtered coverage of
//                                               all objects)
//
// which is the gold standard's composition Σ_o coverage_o · layer_o at silhouettes. A pixel
// whose neighbourhood holds one object only returns that object's radiance unchanged.
// `fs_classify` runs first and writes each pixel's shared object index, so that such pixels
// are found from 9 reads.
//
// Sample positions: wgpu asks for 4 samples, and WebGPU (and Vulkan's
// standardSampleLocations, which every Vulkan implementation of 4× MSAA that wgpu runs on
// reports, lavapipe included) fixes the 4× pattern within the pixel, origin at its top-left
// corner, y down: (0.375, 0.125), (0.875, 0.375), (0.125, 0.625), (0.625, 0.875).

struct Kernel {
    // 1 / (2σ²), in 1/pixel².
    inv_two_sigma2: f32,
    // R² in pixel².
    radius2: f32,
    _pad0: f32,
    _pad1: f32,
};

@group(0) @binding(0) var colour: texture_multisampled_2d<f32>;
@group(0) @binding(1) var ids: texture_multisampled_2d<u32>;
@group(0) @binding(2) var<uniform> kernel: Kernel;
// Per pixel, the object index all its samples share, or MIXED (`fs_classify`).
@group(1) @binding(0) var shared_ids: texture_2d<u32>;

// No object index is this large (the "no object" index is 0xffffffff).
const MIXED: u32 = 0xfffffffeu;

// 3×3 pixels × 4 samples: the most distinct objects a neighbourhood can hold.
const MAX_GROUPS: u32 = 36u;

const POSITIONS = array<vec2<f32>, 4>(
    vec2<f32>(0.375, 0.125),
    vec2<f32>(0.875, 0.375),
    vec2<f32>(0.125, 0.625),
    vec2<f32>(0.625, 0.875),
);

// One triangle covering the target.
@vertex
fn vs_full(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let x = f32((i << 1u) & 2u);
    let y = f32(i & 2u);
    return vec4<f32>(x * 2.0 - 1.0, 1.0 - y * 2.0, 0.0, 1.0);
}

// The squared distance from p's centre of sample `s` of the pixel at offset `o` from p.
fn distance2(o: vec2<i32>, s: i32) -> f32 {
    let d = vec2<f32>(o) + POSITIONS[s] - vec2<f32>(0.5);
    return dot(d, d);
}

// The filter's weight of sample `s` of the pixel at offset `o` from p.
fn weight(o: vec2<i32>, s: i32) -> f32 {
    let r2 = distance2(o, s);
    if (r2 > kernel.radius2) {
        return 0.0;
    }
    return exp(-r2 * kernel.inv_two_sigma2);
}

// The mean of p's own samples, a running mean: equal samples give exactly their value.
fn own_average(p: vec2<i32>, n: i32) -> vec4<f32> {
    var m = textureLoad(colour, p, 0);
    for (var s = 1; s < n; s = s + 1) {
        m = m + (textureLoad(colour, p, s) - m) / f32(s + 1);
    }
    return m;
}

// The first pass: per pixel, the object index its samples share, or MIXED. The resolve
// reads 9 of these instead of the neighbourhood's samples to find the pixels whose
// neighbourhood is one object's.
@fragment
fn fs_classify(@builtin(position) at: vec4<f32>) -> @location(0) u32 {
    let p = vec2<i32>(at.xy);
    let first = textureLoad(ids, p, 0).r;
    for (var s = 1; s < i32(textureNumSamples(ids)); s = s + 1) {
        if (textureLoad(ids, p, s).r != first) {
            return MIXED;
        }
    }
    return first;
}

@fragment
fn fs_resolve(@builtin(position) at: vec4<f32>) -> @location(0) vec4<f32> {
    let p = vec2<i32>(at.xy);
    let size = vec2<i32>(textureDimensions(ids));
    let n = i32(min(textureNumSamples(ids), 4u));
    // Most pixels: every sample of the 3×3 neighbourhood on one object (or none). Its
    // radiance at p, unfiltered. (Where only samples the filter does not reach differ, the
    // grouping below finds one group and returns the same value.)
    let first = textureLoad(shared_ids, p, 0).r;
    var one_object = first != MIXED;
    for (var k = 0; k < 9 && one_object; k = k + 1) {
        let q = clamp(p + vec2<i32>(k % 3 - 1, k / 3 - 1), vec2<i32>(0), size - vec2<i32>(1));
        one_object = textureLoad(shared_ids, q, 0).r == first;
    }
    if (one_object) {
        return own_average(p, n);
    }
    // Per group: object index, Σ w, Σ w·colour, own samples and their running mean.
    var index: array<u32, MAX_GROUPS>;
    var mass: array<f32, MAX_GROUPS>;
    var weighted: array<vec4<f32>, MAX_GROUPS>;
    var own: array<u32, MAX_GROUPS>;
    var own_mean: array<vec4<f32>, MAX_GROUPS>;
    var groups = 0u;
    var total = 0.0;
    for (var dy = -1; dy <= 1; dy = dy + 1) {
        for (var dx = -1; dx <= 1; dx = dx + 1) {
            let q = p + vec2<i32>(dx, dy);
            // Beyond the image there are no samples: the weights renormalise over those
            // inside.
            if (any(q < vec2<i32>(0)) || any(q >= size)) {
                continue;
            }
            let is_own = dx == 0 && dy == 0;
            for (var s = 0; s < n; s = s + 1) {
                let w = weight(vec2<i32>(dx, dy), s);
                if (w <= 0.0 && !is_own) {
                    continue;
                }
                let id = textureLoad(ids, q, s).r;
                let c = textureLoad(colour, q, s);
                var g = 0u;
                loop {
                    if (g >= groups || index[g] == id) {
                        break;
                    }
                    g = g + 1u;
                }
                if (g == groups) {
                    index[g] = id;
                    mass[g] = 0.0;
                    weighted[g] = vec4<f32>(0.0);
                    own[g] = 0u;
                    own_mean[g] = vec4<f32>(0.0);
                    groups = groups + 1u;
                }
                mass[g] = mass[g] + w;
                weighted[g] = weighted[g] + w * c;
                total = total + w;
                if (is_own) {
                    // A running mean: equal samples give exactly their value.
                    own[g] = own[g] + 1u;
                    if (own[g] == 1u) {
                        own_mean[g] = c;
                    } else {
                        own_mean[g] = own_mean[g] + (c - own_mean[g]) / f32(own[g]);
                    }
                }
            }
        }
    }
    // One object (or none) around p: its radiance at p, unfiltered.
    if (groups == 1u) {
        return own_mean[0];
    }
    var out = vec4<f32>(0.0);
    if (total <= 0.0) {
        // No sample within R (a filter narrower than the sample spacing): the pixel's own
        // samples averaged.
        for (var g = 0u; g < groups; g = g + 1u) {
            out = out + own_mean[g] * (f32(own[g]) / f32(n));
        }
        return out;
    }
    for (var g = 0u; g < groups; g = g + 1u) {
        if (mass[g] <= 0.0) {
            continue;
        }
        var radiance = weighted[g] / mass[g];
        if (own[g] > 0u) {
            radiance = own_mean[g];
        }
        out = out + radiance * (mass[g] / total);
    }
    return out;
}
