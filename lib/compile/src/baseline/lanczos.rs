//! Lanczos-windowed sinc filtering (thesis 3.6: half-width 4 for forward mapping, 6 for
//! down-sampling supersampled traced textures).

use std::f64::consts::PI;

/// L_a(x) = sinc(x)·sinc(x/a) for |x| < a, else 0.
pub fn lanczos(x: f64, a: f64) -> f64 {
    if x.abs() >= a {
        return 0.0;
    }
    if x.abs() < 1e-12 {
        return 1.0;
    }
    let px = PI * x;
    a * px.sin() * (px / a).sin() / (px * px)
}

/// The separable Lanczos filter of half-width `a · scale` pixels, evaluated at (x, y) in
/// pixel units (pixel centres at i + ½) over an RGB image, normalized by its weight sum.
pub fn filter_at(
    rgb: &[f32],
    width: u32,
    height: u32,
    x: f64,
    y: f64,
    a: f64,
    scale: f64,
) -> [f32; 3] {
    let (cx, cy) = (x - 0.5, y - 0.5);
    let r = a * scale;
    let (x0, x1) =
        ((cx - r).ceil().max(0.0) as i64, ((cx + r).floor() as i64).min(width as i64 - 1));
    let (y0, y1) =
        ((cy - r).ceil().max(0.0) as i64, ((cy + r).floor() as i64).min(height as i64 - 1));
    let mut acc = [0.0f64; 3];
    let mut wsum = 0.0;
    for j in y0..=y1 {
        let wy = lanczos((j as f64 - cy) / scale, a);
        if wy == 0.0 {
            continue;
        }
        for i in x0..=x1 {
            let w = wy * lanczos((i as f64 - cx) / scale, a);
            let k = (j as usize * width as usize + i as usize) * 3;
            for c in 0..3 {
                acc[c] += w * rgb[k + c] as f64;
            }
            wsum += w;
        }
    }
    if wsum.abs() < 1e-12 {
        // Outside the image: the nearest pixel.
        let i = (cx.round().clamp(0.0, width as f64 - 1.0)) as usize;
        let j = (cy.round().clamp(0.0, height as f64 - 1.0)) as usize;
        let k = (j * width as usize + i) * 3;
        return [rgb[k], rgb[k + 1], rgb[k + 2]];
    }
    acc.map(|v| (v / wsum) as f32)
}

/// Down-samples an RGB image by an integer factor with a separable Lanczos filter of
/// `a` lobes in output pixels (half-width `a · factor` input pixels).
pub fn decimate(rgb: &[f32], width: u32, height: u32, factor: u32, a: f64) -> Vec<f32> {
    let (ow, oh) = (width / factor, height / factor);
    let mut out = Vec::with_capacity(ow as usize * oh as usize * 3);
    for j in 0..oh {
        for i in 0..ow {
            let (x, y) = ((i as f64 + 0.5) * factor as f64, (j as f64 + 0.5) * factor as f64);
            out.extend(filter_at(rgb, width, height, x, y, a, factor as f64));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_constant_image_stays_constant() {
        let img = vec![0.25f32; 9 * 6 * 3];
        let d = decimate(&img, 9, 6, 3, 2.0);
        assert_eq!(d.len(), 3 * 2 * 3);
        assert!(d.iter().all(|v| (v - 0.25).abs() < 1e-6));
        assert!((lanczos(0.0, 4.0) - 1.0).abs() < 1e-12 && lanczos(1.0, 4.0).abs() < 1e-12);
    }
}
