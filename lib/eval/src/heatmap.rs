//! Error heatmaps: a scalar error per pixel through a perceptually ordered colour ramp
//! (magma: black through purple and orange to pale yellow), written as PNG atomically.

use std::path::Path;

/// Control points of the ramp, evenly spaced over [0, 1] (sRGB 8-bit).
const RAMP: [[u8; 3]; 9] = [
    [0, 0, 4],
    [28, 16, 68],
    [79, 18, 123],
    [129, 37, 129],
    [181, 54, 122],
    [229, 80, 100],
    [251, 135, 97],
    [254, 194, 135],
    [252, 253, 191],
];

/// The ramp's colour at `t` (clamped to [0, 1]; non-finite values give the low end).
pub fn ramp(t: f32) -> [u8; 3] {
    let t = if t.is_finite() { t.clamp(0.0, 1.0) } else { 0.0 };
    let x = t * (RAMP.len() - 1) as f32;
    let i = (x.floor() as usize).min(RAMP.len() - 2);
    let f = x - i as f32;
    let mut out = [0u8; 3];
    for k in 0..3 {
        let v = RAMP[i][k] as f32 * (1.0 - f) + RAMP[i + 1][k] as f32 * f;
        out[k] = v.round() as u8;
    }
    out
}

/// Maps `values` (row-major, `width × height`) through the ramp with `scale` at the top
/// (values ≥ scale are the brightest colour) into 8-bit RGB.
pub fn colourize(values: &[f32], scale: f32) -> Vec<u8> {
    let s = if scale > 0.0 && scale.is_finite() { scale } else { 1.0 };
    values.iter().flat_map(|&v| ramp(v / s)).collect()
}

/// Writes `values` as a heatmap PNG at `path` (temporary file, then rename).
pub fn write_heatmap(
    path: &Path,
    width: u32,
    height: u32,
    values: &[f32],
    scale: f32,
) -> anyhow::Result<()> {
    anyhow::ensure!(
        values.len() == width as usize * height as usize,
        "heatmap of {width}x{height} has {} values",
        values.len()
    );
    let rgb = colourize(values, scale);
    let mut png = Vec::new();
    image::codecs::png::PngEncoder::new(&mut png)
        .write_image(&rgb, width, height, image::ExtendedColorType::Rgb8)
        .map_err(|e| anyhow::anyhow!("cannot encode {}: {e}", path.display()))?;
    pis_format::write_atomic(path, &png)?;
    Ok(())
}

use image::ImageEncoder;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ramp_ends_and_order() {
        assert_eq!(ramp(0.0), RAMP[0]);
        assert_eq!(ramp(1.0), RAMP[8]);
        assert_eq!(ramp(f32::NAN), RAMP[0]);
        // Brightness (sum of channels) grows along the ramp.
        let b = |t: f32| ramp(t).iter().map(|&v| v as u32).sum::<u32>();
        assert!((1..=20).all(|i| b(i as f32 / 20.0) >= b((i - 1) as f32 / 20.0)));
    }

    #[test]
    fn heatmap_png_round_trips() {
        let dir = tempfile::tempdir().expect("temp dir");
        let path = dir.path().join("e.png");
        write_heatmap(&path, 3, 2, &[0.0, 0.5, 1.0, 2.0, 0.25, 0.75], 1.0).expect("written");
        let img = image::open(&path).expect("PNG").to_rgb8();
        assert_eq!(img.dimensions(), (3, 2));
        assert_eq!(img.get_pixel(0, 0).0, RAMP[0]);
        assert_eq!(img.get_pixel(2, 0).0, RAMP[8]);
        assert_eq!(img.get_pixel(0, 1).0, RAMP[8]);
        assert!(write_heatmap(&path, 4, 2, &[0.0; 3], 1.0).is_err());
    }
}
