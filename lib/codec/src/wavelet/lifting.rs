//! CDF 9/7 wavelet by lifting (Daubechies–Sweldens), with whole-sample symmetric extension
//! so that any length ≥ 2 is transformed, and the 2D Mallat decomposition (SPEC.md 11.4).

const ALPHA: f32 = -1.586_134_3;
const BETA: f32 = -0.052_980_118;
const GAMMA: f32 = 0.882_911_1;
const DELTA: f32 = 0.443_506_87;
const K: f32 = 1.230_174_1;

/// Mirror index for whole-sample symmetric extension of a length-`n` signal.
#[inline]
fn mirror(i: isize, n: usize) -> usize {
    let n = n as isize;
    let j = if i < 0 { -i } else { i };
    (if j >= n { 2 * (n - 1) - j } else { j }) as usize
}

fn lift(x: &mut [f32], odd: bool, c: f32) {
    let n = x.len();
    let start = if odd { 1 } else { 0 };
    let mut i = start;
    while i < n {
        let a = x[mirror(i as isize - 1, n)];
        let b = x[mirror(i as isize + 1, n)];
        x[i] += c * (a + b);
        i += 2;
    }
}

/// One level of the forward 1D transform of `x` (length ≥ 2), output de-interleaved: the
/// `ceil(n/2)` low-pass values first, then the `floor(n/2)` high-pass values.
pub fn forward_1d(x: &mut [f32], tmp: &mut Vec<f32>) {
    let n = x.len();
    if n < 2 {
        return;
    }
    lift(x, true, ALPHA);
    lift(x, false, BETA);
    lift(x, true, GAMMA);
    lift(x, false, DELTA);
    tmp.clear();
    tmp.extend(x.iter().step_by(2).map(|v| v / K));
    tmp.extend(x.iter().skip(1).step_by(2).map(|v| v * K));
    x.copy_from_slice(tmp);
}

/// Inverse of [`forward_1d`]. The lifting steps run on the de-interleaved halves (`s`, the
/// even samples; `d`, the odd ones), which is [`lift`]'s arithmetic value for value with the
/// mirror rule resolved at the two ends, and the halves are interleaved last.
pub fn inverse_1d(x: &mut [f32], tmp: &mut Vec<f32>) {
    let n = x.len();
    if n < 2 {
        return;
    }
    tmp.clear();
    tmp.extend_from_slice(x);
    let (s, d) = tmp.split_at_mut(n.div_ceil(2));
    s.iter_mut().for_each(|v| *v *= K);
    d.iter_mut().for_each(|v| *v /= K);
    lift_even(s, d, -DELTA);
    lift_odd(d, s, -GAMMA);
    lift_even(s, d, -BETA);
    lift_odd(d, s, -ALPHA);
    for (pair, (&e, &o)) in x.chunks_exact_mut(2).zip(s.iter().zip(d.iter())) {
        pair[0] = e;
        pair[1] = o;
    }
    if n % 2 == 1 {
        x[n - 1] = s[s.len() - 1];
    }
}

/// The even samples' step: `s[j] += c · (d[j−1] + d[j])`, a missing neighbour mirrored
/// (`d[−1]` is `d[0]`; with an odd length `d[hi]` is `d[hi−1]`). `d` is not empty.
fn lift_even(s: &mut [f32], d: &[f32], c: f32) {
    let hi = d.len();
    s[0] += c * (d[0] + d[0]);
    for (v, pair) in s[1..hi].iter_mut().zip(d.windows(2)) {
        *v += c * (pair[0] + pair[1]);
    }
    if s.len() > hi {
        s[hi] += c * (d[hi - 1] + d[hi - 1]);
    }
}

/// The odd samples' step: `d[j] += c · (s[j] + s[j+1])`, a missing `s[j+1]` mirrored to
/// `s[j]` (an even length's last odd sample).
fn lift_odd(d: &mut [f32], s: &[f32], c: f32) {
    let inner = d.len().min(s.len() - 1);
    for (v, pair) in d[..inner].iter_mut().zip(s.windows(2)) {
        *v += c * (pair[0] + pair[1]);
    }
    if d.len() > inner {
        let j = inner;
        d[j] += c * (s[j] + s[j]);
    }
}

/// Vertical lifting step on the top-left `cw × ch` region of a `w`-wide array: every odd (or
/// even) row gets `c ·` (row above + row below), with the same mirror rule as [`lift`], so
/// the arithmetic is that of [`forward_1d`] on each column, done a row at a time.
fn lift_rows(a: &mut [f32], w: usize, cw: usize, ch: usize, odd: bool, c: f32) {
    let mut y = if odd { 1 } else { 0 };
    while y < ch {
        let up = mirror(y as isize - 1, ch);
        let down = mirror(y as isize + 1, ch);
        for x in 0..cw {
            let s = a[up * w + x] + a[down * w + x];
            a[y * w + x] += c * s;
        }
        y += 2;
    }
}

/// Forward transform of the columns of the top-left `cw × ch` region (ch ≥ 2).
fn forward_cols(a: &mut [f32], w: usize, cw: usize, ch: usize, tmp: &mut Vec<f32>) {
    lift_rows(a, w, cw, ch, true, ALPHA);
    lift_rows(a, w, cw, ch, false, BETA);
    lift_rows(a, w, cw, ch, true, GAMMA);
    lift_rows(a, w, cw, ch, false, DELTA);
    let lo = ch.div_ceil(2);
    tmp.clear();
    tmp.resize(cw * ch, 0.0);
    for y in 0..ch {
        let dst = if y % 2 == 0 { y / 2 } else { lo + y / 2 };
        for x in 0..cw {
            let v = a[y * w + x];
            tmp[dst * cw + x] = if y % 2 == 0 { v / K } else { v * K };
        }
    }
    for y in 0..ch {
        a[y * w..y * w + cw].copy_from_slice(&tmp[y * cw..(y + 1) * cw]);
    }
}

/// Inverse of [`forward_cols`].
fn inverse_cols(a: &mut [f32], w: usize, cw: usize, ch: usize, tmp: &mut Vec<f32>) {
    let lo = ch.div_ceil(2);
    tmp.clear();
    for y in 0..ch {
        let (row, even) = if y % 2 == 0 { (y / 2, true) } else { (lo + y / 2, false) };
        let row = &a[row * w..row * w + cw];
        if even {
            tmp.extend(row.iter().map(|v| v * K));
        } else {
            tmp.extend(row.iter().map(|v| v / K));
        }
    }
    for y in 0..ch {
        a[y * w..y * w + cw].copy_from_slice(&tmp[y * cw..(y + 1) * cw]);
    }
    lift_rows(a, w, cw, ch, false, -DELTA);
    lift_rows(a, w, cw, ch, true, -GAMMA);
    lift_rows(a, w, cw, ch, false, -BETA);
    lift_rows(a, w, cw, ch, true, -ALPHA);
}

/// Number of decomposition levels of a `w × h` plane for a requested `levels`: a level is
/// applied while both sides of the current low-pass band are ≥ 2.
pub fn plane_levels(w: u32, h: u32, levels: u32) -> u32 {
    let (mut w, mut h, mut l) = (w, h, 0);
    while l < levels && w >= 2 && h >= 2 {
        w = w.div_ceil(2);
        h = h.div_ceil(2);
        l += 1;
    }
    l
}

/// Forward 2D transform of a `w × h` array in place (rows, then columns, on the low-pass band
/// of the previous level).
pub fn forward_2d(a: &mut [f32], w: usize, h: usize, levels: u32) {
    let mut tmp = Vec::new();
    let (mut cw, mut ch) = (w, h);
    for _ in 0..levels {
        for y in 0..ch {
            forward_1d(&mut a[y * w..y * w + cw], &mut tmp);
        }
        forward_cols(a, w, cw, ch, &mut tmp);
        cw = cw.div_ceil(2);
        ch = ch.div_ceil(2);
    }
}

/// Inverse of [`forward_2d`].
/// `tmp` is working memory (its contents do not matter).
pub fn inverse_2d(a: &mut [f32], w: usize, h: usize, levels: u32, tmp: &mut Vec<f32>) {
    let mut sizes = vec![(w, h)];
    for _ in 1..levels {
        let (cw, ch) = *sizes.last().unwrap_or(&(w, h));
        sizes.push((cw.div_ceil(2), ch.div_ceil(2)));
    }
    for &(cw, ch) in sizes.iter().take(levels as usize).rev() {
        inverse_cols(a, w, cw, ch, tmp);
        for y in 0..ch {
            inverse_1d(&mut a[y * w..y * w + cw], tmp);
        }
    }
}

/// Energies of the 1D synthesis basis functions of a length-`n` signal: `(low[j], high[j])`
/// for levels j = 1..=levels (index j − 1), each for a unit coefficient in the middle of its
/// band (`n_j / 2` of the low band, `n_j + (n_{j−1} − n_j) / 2` of the high band, with
/// `n_0 = n`, `n_j = ceil(n_{j−1} / 2)`). The codec scales each coefficient by the square root
/// of its 2D basis energy (the product of the energies along x and y), so that squared errors
/// of scaled coefficients approximate squared errors of the image.
pub fn basis_energies(n: usize, levels: u32) -> Vec<(f64, f64)> {
    let mut sizes = vec![n];
    for _ in 0..levels {
        sizes.push(sizes[sizes.len() - 1].div_ceil(2));
    }
    let mut out = Vec::new();
    let mut tmp = Vec::new();
    for j in 1..=levels as usize {
        let mut e = [0.0f64; 2];
        for (band, energy) in e.iter_mut().enumerate() {
            let mut x = vec![0.0f32; n];
            let pos =
                if band == 0 { sizes[j] / 2 } else { sizes[j] + (sizes[j - 1] - sizes[j]) / 2 };
            x[pos] = 1.0;
            for l in (1..=j).rev() {
                inverse_1d(&mut x[..sizes[l - 1]], &mut tmp);
            }
            *energy = x.iter().map(|v| (*v as f64) * (*v as f64)).sum();
        }
        out.push((e[0], e[1]));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn perfect_reconstruction_any_size() {
        for (w, h) in [(1, 1), (2, 2), (3, 5), (17, 9), (64, 33), (1, 7)] {
            let orig: Vec<f32> =
                (0..w * h).map(|i| ((i * 7919) % 101) as f32 * 0.1 - 3.0).collect();
            let mut a = orig.clone();
            let l = plane_levels(w as u32, h as u32, 6);
            forward_2d(&mut a, w, h, l);
            inverse_2d(&mut a, w, h, l, &mut Vec::new());
            for (x, y) in orig.iter().zip(&a) {
                assert!((x - y).abs() < 1e-4, "{w}x{h}: {x} vs {y}");
            }
        }
    }

    #[test]
    fn row_wise_column_lifting_matches_the_1d_transform() {
        let (w, h) = (7usize, 9usize);
        let orig: Vec<f32> = (0..w * h).map(|i| ((i * 31) % 17) as f32 - 8.0).collect();
        let mut a = orig.clone();
        let mut tmp = Vec::new();
        forward_cols(&mut a, w, w, h, &mut tmp);
        for x in 0..w {
            let mut col: Vec<f32> = (0..h).map(|y| orig[y * w + x]).collect();
            forward_1d(&mut col, &mut tmp);
            for y in 0..h {
                assert_eq!(col[y].to_bits(), a[y * w + x].to_bits());
            }
        }
    }

    /// [`inverse_1d`] as the definition reads: interleave, then [`lift`] with the mirror rule.
    fn inverse_1d_by_definition(x: &mut [f32]) {
        let n = x.len();
        if n < 2 {
            return;
        }
        let lo = n.div_ceil(2);
        let y: Vec<f32> =
            (0..n).map(|i| if i % 2 == 0 { x[i / 2] * K } else { x[lo + i / 2] / K }).collect();
        x.copy_from_slice(&y);
        lift(x, false, -DELTA);
        lift(x, true, -GAMMA);
        lift(x, false, -BETA);
        lift(x, true, -ALPHA);
    }

    #[test]
    fn inverse_1d_is_the_lifting_definition_bit_for_bit() {
        let mut tmp = Vec::new();
        for n in [1, 2, 3, 4, 5, 8, 9, 16, 31, 100, 257] {
            let orig: Vec<f32> = (0..n).map(|i| ((i * 7919) % 97) as f32 * 0.37 - 11.0).collect();
            let (mut fast, mut slow) = (orig.clone(), orig);
            inverse_1d(&mut fast, &mut tmp);
            inverse_1d_by_definition(&mut slow);
            let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&fast), bits(&slow), "length {n}");
        }
    }

    #[test]
    fn basis_energies_are_bounded() {
        // With this normalisation energies grow about twofold per level; the codec weights them.
        for (lo, hi) in basis_energies(4096, 5) {
            assert!(lo > 0.5 && hi > 0.5 && lo.is_finite(), "{lo} {hi}");
        }
    }
}
