//! Texture decoding: glTF images to linear RGBA f32 texels.

use gltf::image::{Data, Format};

use crate::model::TextureImage;

/// The sRGB electro-optical transfer function: an encoded value in [0, 1] to linear.
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// The most texels a texture may have: 8192 × 8192 (1 GiB as linear RGBA `f32`). A larger
/// image is refused, naming it, before its texels are converted.
pub const MAX_TEXTURE_TEXELS: u64 = 8192 * 8192;

/// Decodes an image to linear RGBA. `srgb` says the colour channels are sRGB-encoded (base
/// colour and emissive textures, 8- and 16-bit formats); alpha and float formats are linear.
/// Missing channels are filled as glTF samplers do: grey for R, alpha 1. An image of more
/// than [`MAX_TEXTURE_TEXELS`] texels, or whose pixel data does not match its size, is
/// refused with the reason.
pub fn decode(image: &Data, srgb: bool) -> Result<TextureImage, String> {
    let (channels, bytes) = match image.format {
        Format::R8 => (1, 1),
        Format::R8G8 => (2, 1),
        Format::R8G8B8 => (3, 1),
        Format::R8G8B8A8 => (4, 1),
        Format::R16 => (1, 2),
        Format::R16G16 => (2, 2),
        Format::R16G16B16 => (3, 2),
        Format::R16G16B16A16 => (4, 2),
        Format::R32G32B32FLOAT => (3, 4),
        Format::R32G32B32A32FLOAT => (4, 4),
    };
    let texels = image.width as u64 * image.height as u64;
    if texels > MAX_TEXTURE_TEXELS {
        return Err(format!(
            "{}x{} texels: PIS reads textures of at most {MAX_TEXTURE_TEXELS} texels (8192x8192); downscale it",
            image.width, image.height
        ));
    }
    if image.pixels.len() as u64 != texels * channels * bytes {
        return Err(format!(
            "{} bytes of pixel data for {}x{} texels of {channels} channel(s) of {bytes} byte(s)",
            image.pixels.len(),
            image.width,
            image.height
        ));
    }
    let float = bytes == 4;
    let to_linear = |c: f32| if srgb && !float { srgb_to_linear(c) } else { c };
    let value = |b: &[u8]| match bytes {
        1 => b[0] as f32 / 255.0,
        2 => u16::from_ne_bytes([b[0], b[1]]) as f32 / 65535.0,
        _ => f32::from_ne_bytes([b[0], b[1], b[2], b[3]]),
    };
    let texels = image
        .pixels
        .chunks_exact((channels * bytes) as usize)
        .map(|p| {
            let mut c = [0.0f32; 4];
            for (k, v) in p.chunks_exact(bytes as usize).enumerate() {
                c[k] = value(v);
            }
            match channels {
                1 => [to_linear(c[0]), to_linear(c[0]), to_linear(c[0]), 1.0],
                2 => [to_linear(c[0]), to_linear(c[0]), to_linear(c[0]), c[1]],
                3 => [to_linear(c[0]), to_linear(c[1]), to_linear(c[2]), 1.0],
                _ => [to_linear(c[0]), to_linear(c[1]), to_linear(c[2]), c[3]],
            }
        })
        .collect();
    Ok(TextureImage { width: image.width, height: image.height, texels })
}

impl TextureImage {
    /// The mean RGBA of the texels; white for an empty texture or one whose texels do not
    /// fill its size (the tracer reads such a texture as white).
    pub fn mean(&self) -> [f32; 4] {
        let n = self.width as usize * self.height as usize;
        if n == 0 || self.texels.len() < n {
            return [1.0; 4];
        }
        let sum = self.texels[..n].iter().fold([0.0f64; 4], |mut s, t| {
            s.iter_mut().zip(t).for_each(|(s, v)| *s += *v as f64);
            s
        });
        sum.map(|s| (s / n as f64) as f32)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_curve_endpoints_and_midpoint() {
        assert_eq!(srgb_to_linear(0.0), 0.0);
        assert!((srgb_to_linear(1.0) - 1.0).abs() < 1e-6);
        // 0.5 encoded is about 0.214 linear.
        assert!((srgb_to_linear(0.5) - 0.21404).abs() < 1e-4);
    }

    #[test]
    fn decodes_rgb8_to_linear_rgba() {
        let data = Data {
            pixels: vec![255, 0, 128, 0, 0, 0],
            format: Format::R8G8B8,
            width: 2,
            height: 1,
        };
        let t = decode(&data, true).unwrap();
        assert_eq!(t.texels.len(), 2);
        assert!((t.texels[0][0] - 1.0).abs() < 1e-6);
        assert!((t.texels[0][2] - srgb_to_linear(128.0 / 255.0)).abs() < 1e-6);
        assert_eq!(t.texels[0][3], 1.0);
        let lin = decode(&data, false).unwrap();
        assert!((lin.texels[0][2] - 128.0 / 255.0).abs() < 1e-6);
    }

    #[test]
    fn pixel_data_short_of_the_size_is_refused() {
        let data = Data { pixels: vec![0; 5], format: Format::R8G8B8, width: 2, height: 1 };
        let e = decode(&data, true).unwrap_err();
        assert!(e.contains("5 bytes") && e.contains("2x1"), "{e}");
    }

    #[test]
    fn a_texture_over_the_texel_limit_is_refused_before_conversion() {
        let data = Data { pixels: vec![], format: Format::R8, width: 100_000, height: 100_000 };
        let e = decode(&data, false).unwrap_err();
        assert!(e.contains("100000x100000") && e.contains("at most"), "{e}");
    }

    #[test]
    fn mean_of_texels() {
        let t = TextureImage {
            width: 2,
            height: 1,
            texels: vec![[1.0, 0.0, 0.5, 1.0], [0.0, 0.0, 0.5, 0.0]],
        };
        assert_eq!(t.mean(), [0.5, 0.0, 0.5, 0.5]);
        assert_eq!(TextureImage { width: 2, height: 2, texels: vec![] }.mean(), [1.0; 4]);
    }
}
