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

/// Decodes an image to linear RGBA. `srgb` says the colour channels are sRGB-encoded (base
/// colour and emissive textures, 8- and 16-bit formats); alpha and float formats are linear.
/// Missing channels are filled as glTF samplers do: grey for R, alpha 1.
pub fn decode(image: &Data, srgb: bool) -> TextureImage {
    let channels = match image.format {
        Format::R8 | Format::R16 => 1,
        Format::R8G8 | Format::R16G16 => 2,
        Format::R8G8B8 | Format::R16G16B16 | Format::R32G32B32FLOAT => 3,
        Format::R8G8B8A8 | Format::R16G16B16A16 | Format::R32G32B32A32FLOAT => 4,
    };
    let raw: Vec<f32> = match image.format {
        Format::R8 | Format::R8G8 | Format::R8G8B8 | Format::R8G8B8A8 => {
            image.pixels.iter().map(|&b| b as f32 / 255.0).collect()
        }
        Format::R16 | Format::R16G16 | Format::R16G16B16 | Format::R16G16B16A16 => image
            .pixels
            .chunks_exact(2)
            .map(|b| u16::from_ne_bytes([b[0], b[1]]) as f32 / 65535.0)
            .collect(),
        Format::R32G32B32FLOAT | Format::R32G32B32A32FLOAT => image
            .pixels
            .chunks_exact(4)
            .map(|b| f32::from_ne_bytes([b[0], b[1], b[2], b[3]]))
            .collect(),
    };
    let float = matches!(
        image.format,
        Format::R32G32B32FLOAT | Format::R32G32B32A32FLOAT
    );
    let to_linear = |c: f32| if srgb && !float { srgb_to_linear(c) } else { c };
    let texels = raw
        .chunks_exact(channels)
        .map(|p| match *p {
            [r] => [to_linear(r), to_linear(r), to_linear(r), 1.0],
            [r, a] => [to_linear(r), to_linear(r), to_linear(r), a],
            [r, g, b] => [to_linear(r), to_linear(g), to_linear(b), 1.0],
            [r, g, b, a, ..] => [to_linear(r), to_linear(g), to_linear(b), a],
            [] => [0.0, 0.0, 0.0, 1.0],
        })
        .collect();
    TextureImage {
        width: image.width,
        height: image.height,
        texels,
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
        let t = decode(&data, true);
        assert_eq!(t.texels.len(), 2);
        assert!((t.texels[0][0] - 1.0).abs() < 1e-6);
        assert!((t.texels[0][2] - srgb_to_linear(128.0 / 255.0)).abs() < 1e-6);
        assert_eq!(t.texels[0][3], 1.0);
        let lin = decode(&data, false);
        assert!((lin.texels[0][2] - 128.0 / 255.0).abs() < 1e-6);
    }
}
