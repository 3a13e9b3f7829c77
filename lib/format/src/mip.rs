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
/// with coordinates clamped to the last column and row: 0.25 · (((a + b) + c) + d), a and b
/// from row 2j, c and d from row 2j + 1, each pair left to right.
pub fn decimate(src: &[f32], width: u32, height: u32, channels: u32) -> Vec<f32> {
    let (w, h, c) = (width as usize, height as usize, channels as usize);
    let (ow, oh) = (w.div_ceil(2), h.div_ceil(2));
    let mut out = vec![0.0; ow * oh * c];
    for (j, row) in out.chunks_exact_mut(ow * c).enumerate() {
        let (y0, y1) = (2 * j, (2 * j + 1).min(h - 1));
        let (r0, r1) = (&src[y0 * w * c..][..w * c], &src[y1 * w * c..][..w * c]);
        match c {
            1 => decimate_row::<1>(r0, r1, row),
            3 => decimate_row::<3>(r0, r1, row),
            4 => decimate_row::<4>(r0, r1, row),
            _ => decimate_row_any(r0, r1, c, row),
        }
    }
    out
}

/// One output row of [`decimate`] from input rows `r0` and `r1`, `C` channels a texel: whole
/// pairs of texels, then an odd last texel with itself.
fn decimate_row<const C: usize>(r0: &[f32], r1: &[f32], out: &mut [f32]) {
    let pairs = r0.len() / (2 * C);
    let mean = |a: f32, b: f32, c: f32, d: f32| 0.25 * (a + b + c + d);
    for ((o, p0), p1) in
        out.chunks_exact_mut(C).zip(r0.chunks_exact(2 * C)).zip(r1.chunks_exact(2 * C))
    {
        for ch in 0..C {
            o[ch] = mean(p0[ch], p0[C + ch], p1[ch], p1[C + ch]);
        }
    }
    if !r0.len().is_multiple_of(2 * C) {
        let (t0, t1) = (&r0[2 * pairs * C..], &r1[2 * pairs * C..]);
        for ch in 0..C {
            out[pairs * C + ch] = mean(t0[ch], t0[ch], t1[ch], t1[ch]);
        }
    }
}

/// [`decimate_row`] for any channel count.
fn decimate_row_any(r0: &[f32], r1: &[f32], c: usize, out: &mut [f32]) {
    let w = r0.len() / c;
    for (i, o) in out.chunks_exact_mut(c).enumerate() {
        let (x0, x1) = (2 * i * c, (2 * i + 1).min(w - 1) * c);
        for ch in 0..c {
            o[ch] = 0.25 * (r0[x0 + ch] + r0[x1 + ch] + r1[x0 + ch] + r1[x1 + ch]);
        }
    }
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

    /// The definition, texel by texel.
    fn decimate_by_definition(src: &[f32], w: usize, h: usize, c: usize) -> Vec<f32> {
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

    #[test]
    fn decimation_is_its_definition_bit_for_bit() {
        for c in 1..=5usize {
            for (w, h) in [(1, 1), (2, 2), (3, 1), (1, 4), (7, 5), (8, 6), (13, 9)] {
                let src: Vec<f32> =
                    (0..w * h * c).map(|k| ((k * 7919 % 1009) as f32 * 0.37).sin()).collect();
                let got = decimate(&src, w as u32, h as u32, c as u32);
                let want = decimate_by_definition(&src, w, h, c);
                assert!(
                    got.iter().zip(&want).all(|(a, b)| a.to_bits() == b.to_bits())
                        && got.len() == want.len(),
                    "{w}x{h}x{c}"
                );
            }
        }
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
