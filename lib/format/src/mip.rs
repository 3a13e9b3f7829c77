//! MIP chains of textures whose size is not a power of two (section 3.2): each level halves
//! the previous one, rounding up; on an odd side the last texel row or column is replicated
//! before the 2×2 box filter, so no undefined texel is ever filtered in.

/// Number of MIP levels of a `width × height` texture, halving with rounding up down to
/// 1×1: `1 + ceil(log2(max(width, height)))`.
pub fn mip_count(width: u32, height: u32) -> u32 {
    let m = width.max(height).max(1);
    1 + (32 - (m - 1).leading_zeros())
}

/// Size of MIP level `m`.
pub fn mip_size(width: u32, height: u32, m: u32) -> (u32, u32) {
    let mut s = (width, height);
    for _ in 0..m {
        s = (s.0.div_ceil(2), s.1.div_ceil(2));
    }
    s
}

/// One decimation step: `width × height × channels` values → `ceil(w/2) × ceil(h/2)`.
/// Output texel (i, j) is the mean of input texels (2i + dx, 2j + dy), dx, dy ∈ {0, 1},
/// with coordinates clamped to the last column and row.
pub fn decimate(src: &[f32], width: u32, height: u32, channels: u32) -> Vec<f32> {
    let (w, h, c) = (width as usize, height as usize, channels as usize);
    let (ow, oh) = (w.div_ceil(2), h.div_ceil(2));
    let mut out = vec![0.0; ow * oh * c];
    for j in 0..oh {
        let (y0, y1) = (2 * j, (2 * j + 1).min(h - 1));
        for i in 0..ow {
            let (x0, x1) = (2 * i, (2 * i + 1).min(w - 1));
            for ch in 0..c {
                let at = |x: usize, y: usize| src[(y * w + x) * c + ch];
                out[(j * ow + i) * c + ch] =
                    0.25 * (at(x0, y0) + at(x1, y0) + at(x0, y1) + at(x1, y1));
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chain_sizes_round_up() {
        assert_eq!(mip_count(1, 1), 1);
        assert_eq!(mip_count(2, 1), 2);
        assert_eq!(mip_count(5, 3), 4); // 5×3, 3×2, 2×1, 1×1
        assert_eq!(mip_count(8, 8), 4);
        assert_eq!(mip_count(9, 2), 5);
        assert_eq!(mip_size(5, 3, 1), (3, 2));
        assert_eq!(mip_size(5, 3, 2), (2, 1));
    }

    #[test]
    fn odd_sizes_replicate_the_boundary() {
        // 3×1: [1, 3, 10] → [(1+3)/2, (10+10)/2].
        let v = decimate(&[1.0, 3.0, 10.0], 3, 1, 1);
        assert_eq!(v, vec![2.0, 10.0]);
        // A constant texture stays constant at every size.
        let c = vec![0.5; 7 * 5 * 3];
        assert!(decimate(&c, 7, 5, 3).iter().all(|&x| x == 0.5));
    }
}
