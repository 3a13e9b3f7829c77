//! Boundary-reflection hole filling (thesis 3.6): an undefined sample p takes the value
//! mirrored across its nearest defined sample b, at 2b − p, or b's own value where the
//! mirror point is undefined too. Nearest is found by a breadth-first distance transform
//! over the 8-neighbourhood, in a fixed order (deterministic).

use std::collections::VecDeque;

/// Fills the samples where `defined` is false, in place, in an RGB `width × height` image.
/// With no defined sample at all the image is left as it is.
pub fn fill_by_reflection(rgb: &mut [f32], defined: &[bool], width: u32, height: u32) {
    let (w, h) = (width as i64, height as i64);
    let n = defined.len();
    let mut nearest: Vec<Option<u32>> = (0..n).map(|k| defined[k].then_some(k as u32)).collect();
    let mut queue: VecDeque<u32> = (0..n as u32).filter(|&k| defined[k as usize]).collect();
    if queue.is_empty() {
        return;
    }
    while let Some(k) = queue.pop_front() {
        let (x, y) = (k as i64 % w, k as i64 / w);
        let src = nearest[k as usize];
        for (dx, dy) in [(-1, 0), (1, 0), (0, -1), (0, 1), (-1, -1), (1, -1), (-1, 1), (1, 1)] {
            let (nx, ny) = (x + dx, y + dy);
            if nx < 0 || ny < 0 || nx >= w || ny >= h {
                continue;
            }
            let q = (ny * w + nx) as usize;
            if nearest[q].is_none() {
                nearest[q] = src;
                queue.push_back(q as u32);
            }
        }
    }
    for k in 0..n {
        if defined[k] {
            continue;
        }
        let Some(b) = nearest[k] else { continue };
        let (px, py) = (k as i64 % w, k as i64 / w);
        let (bx, by) = (b as i64 % w, b as i64 / w);
        let (mx, my) = (2 * bx - px, 2 * by - py);
        let src = if mx >= 0 && my >= 0 && mx < w && my < h && defined[(my * w + mx) as usize] {
            (my * w + mx) as usize
        } else {
            b as usize
        };
        for c in 0..3 {
            rgb[k * 3 + c] = rgb[src * 3 + c];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_hole_is_filled_by_the_mirror_image() {
        // 5×1: defined [1, 2, 3, ?, ?] → sample 3 mirrors 1 across 2: value of x=1 (2.0)...
        let mut rgb: Vec<f32> = [1.0, 2.0, 3.0, 0.0, 0.0].iter().flat_map(|&v| [v, v, v]).collect();
        let defined = [true, true, true, false, false];
        fill_by_reflection(&mut rgb, &defined, 5, 1);
        assert_eq!(rgb[9], 2.0); // x=3: nearest 2, mirror 1 → value 2
        assert_eq!(rgb[12], 1.0); // x=4: nearest 2, mirror 0 → value 1
    }
}
