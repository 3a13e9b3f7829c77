//! NVIDIA FLIP (Andersson et al. 2020), a perceptual difference between a rendered image and
//! its reference, computed by the `nv-flip` bindings on the images as a viewer sees them:
//! linear radiance clamped to [0, 1] and sRGB-encoded to 8 bits. A FLIP map holds one value
//! per pixel in [0, 1]; its mean is the single figure the method's authors recommend.

use pis_play::FloatImage;

use crate::metrics::srgb_encode;

/// Pixels per degree of visual angle: FLIP's default viewing condition (a 0.7 m distance
/// from a 0.7 m wide 3840-pixel monitor).
pub const PIXELS_PER_DEGREE: f32 = nv_flip::DEFAULT_PIXELS_PER_DEGREE;

/// The 8-bit sRGB display image of linear RGBA values (alpha dropped).
pub fn display_rgb8(img: &FloatImage) -> Vec<u8> {
    img.rgba
        .chunks_exact(4)
        .flat_map(|p| [p[0], p[1], p[2]])
        .map(|v| (srgb_encode(v) * 255.0).round() as u8)
        .collect()
}

/// The FLIP error map of `test` against `reference` (row-major, one value per pixel).
pub fn flip_map(reference: &FloatImage, test: &FloatImage) -> anyhow::Result<Vec<f32>> {
    anyhow::ensure!(
        (reference.width, reference.height) == (test.width, test.height)
            && reference.width > 0
            && reference.height > 0,
        "FLIP needs two images of one non-empty size, got {}x{} and {}x{}",
        reference.width,
        reference.height,
        test.width,
        test.height
    );
    let r = nv_flip::FlipImageRgb8::with_data(
        reference.width,
        reference.height,
        &display_rgb8(reference),
    );
    let t = nv_flip::FlipImageRgb8::with_data(test.width, test.height, &display_rgb8(test));
    Ok(nv_flip::flip(r, t, PIXELS_PER_DEGREE).to_vec())
}

/// A running mean of FLIP values.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FlipMean {
    pub sum: f64,
    pub count: u64,
}

impl FlipMean {
    pub fn add(&mut self, v: f32) {
        self.sum += v as f64;
        self.count += 1;
    }

    pub fn merge(&mut self, o: &FlipMean) {
        self.sum += o.sum;
        self.count += o.count;
    }

    /// The mean; `None` without values.
    pub fn mean(&self) -> Option<f64> {
        (self.count > 0).then(|| self.sum / self.count as f64)
    }
}

/// Mean FLIP of the whole map and of the pixels of each object (`ids[p]` is the object drawn
/// at pixel p, `u32::MAX` for none; `objects` objects).
pub fn means(map: &[f32], ids: &[u32], objects: usize) -> (FlipMean, Vec<FlipMean>) {
    let mut whole = FlipMean::default();
    let mut per = vec![FlipMean::default(); objects];
    for (p, &v) in map.iter().enumerate() {
        whole.add(v);
        if let Some(m) = ids.get(p).and_then(|&o| per.get_mut(o as usize)) {
            m.add(v);
        }
    }
    (whole, per)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(w: u32, h: u32, f: impl Fn(u32, u32) -> [f32; 3]) -> FloatImage {
        let mut rgba = Vec::new();
        for y in 0..h {
            for x in 0..w {
                let c = f(x, y);
                rgba.extend_from_slice(&[c[0], c[1], c[2], 1.0]);
            }
        }
        FloatImage { width: w, height: h, rgba }
    }

    #[test]
    fn flip_is_zero_for_equal_images_and_grows_with_the_difference() {
        let a = image(48, 32, |x, y| [x as f32 / 48.0, y as f32 / 32.0, 0.3]);
        let same = flip_map(&a, &a.clone()).expect("flip");
        assert_eq!(same.len(), 48 * 32);
        assert!(same.iter().all(|&v| v == 0.0));
        let slightly = image(48, 32, |x, y| [x as f32 / 48.0 * 0.97, y as f32 / 32.0, 0.3]);
        let very = image(48, 32, |x, y| [1.0 - x as f32 / 48.0, 0.0, 1.0 - y as f32 / 32.0]);
        let m =
            |t: &FloatImage| means(&flip_map(&a, t).expect("flip"), &[], 0).0.mean().expect("mean");
        let (s, v) = (m(&slightly), m(&very));
        assert!(s > 0.0 && s < v && v <= 1.0, "slight {s}, very {v}");
        assert!(flip_map(&a, &image(4, 4, |_, _| [0.0; 3])).is_err());
    }

    #[test]
    fn per_object_means_follow_the_ids() {
        let map = [0.5, 0.1, 0.3, 0.9];
        let ids = [0, 1, 0, u32::MAX];
        let (whole, per) = means(&map, &ids, 2);
        assert!((whole.mean().expect("mean") - 0.45).abs() < 1e-6);
        assert!((per[0].mean().expect("0") - 0.4).abs() < 1e-6);
        assert!((per[1].mean().expect("1") - 0.1).abs() < 1e-6);
    }
}
