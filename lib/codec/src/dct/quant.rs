//! Quantization of the `dct` codec (SPEC.md 11.5): the JPEG luminance matrix (ITU-T T.81
//! Annex K, table K.1) scaled by the IJG quality rule, in units of the stream's `unit`.

/// Table K.1, row-major (frequency v down, u across).
pub const BASE: [u16; 64] = [
    16, 11, 10, 16, 24, 40, 51, 61, //
    12, 12, 14, 19, 26, 58, 60, 55, //
    14, 13, 16, 24, 40, 57, 69, 56, //
    14, 17, 22, 29, 51, 87, 80, 62, //
    18, 22, 37, 56, 68, 109, 103, 77, //
    24, 35, 55, 64, 81, 104, 113, 92, //
    49, 64, 78, 87, 103, 121, 120, 101, //
    72, 92, 95, 98, 112, 100, 103, 99,
];

/// Zig-zag scan: `ZIGZAG[k]` is the row-major index of the k-th coefficient.
pub const ZIGZAG: [usize; 64] = [
    0, 1, 8, 16, 9, 2, 3, 10, 17, 24, 32, 25, 18, 11, 4, 5, 12, 19, 26, 33, 40, 48, 41, 34, 27, 20,
    13, 6, 7, 14, 21, 28, 35, 42, 49, 56, 57, 50, 43, 36, 29, 22, 15, 23, 30, 37, 44, 51, 58, 59,
    52, 45, 38, 31, 39, 46, 53, 60, 61, 54, 47, 55, 62, 63,
];

/// Quantization steps (row-major) for quality `q` (1..=100) and unit `unit`:
/// `step = unit · max(BASE · s / 100, 1/4)` with `s = 5000 / q` below 50, else `200 − 2q`.
pub fn steps(quality: u8, unit: f32) -> [f32; 64] {
    let q = quality.clamp(1, 100) as f32;
    let s = if q < 50.0 { 5000.0 / q } else { 200.0 - 2.0 * q };
    let mut out = [0.0f32; 64];
    for (o, b) in out.iter_mut().zip(BASE) {
        *o = unit * (b as f32 * s / 100.0).max(0.25);
    }
    out
}

/// Nearest integer of `c / step`, clamped to ±2³⁰.
pub fn quantize(c: f32, step: f32) -> i32 {
    (c / step).round().clamp(-(1 << 30) as f32, (1 << 30) as f32) as i32
}
