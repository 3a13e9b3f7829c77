//! Reading an environment image: a Radiance HDR (`.hdr`) or OpenEXR (`.exr`) file to linear
//! RGB texels, rows top to bottom. The size is read from the header and bounded before any
//! texel is allocated.

use std::path::Path;

/// The widest or tallest environment image read.
pub const MAX_SIDE: u32 = 16384;
/// The most texels an environment image may have (8192 × 4096).
pub const MAX_TEXELS: u64 = 8192 * 4096;

/// A decoded image: width, height and texels (linear RGB, row after row from the top).
pub type Texels = (u32, u32, Vec<[f32; 3]>);

/// Reads `file` by its extension; the error says what is wrong with it (the caller names
/// the file and the field).
pub fn read(file: &Path) -> Result<Texels, String> {
    let ext = file.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("hdr") => read_hdr(file),
        Some("exr") => read_exr(file),
        _ => {
            Err("unsupported image format: expected a Radiance `.hdr` or an OpenEXR `.exr` file"
                .into())
        }
    }
}

/// Refuses a size that is empty or beyond [`MAX_SIDE`] / [`MAX_TEXELS`].
fn check_size(width: u64, height: u64) -> Result<(u32, u32), String> {
    if width == 0 || height == 0 {
        return Err(format!("the image is {width}x{height}: it has no texels"));
    }
    if width > u64::from(MAX_SIDE) || height > u64::from(MAX_SIDE) || width * height > MAX_TEXELS {
        return Err(format!("the image is {width}x{height}: at most {MAX_SIDE} texels a side and {MAX_TEXELS} texels (8192x4096) in all are read"));
    }
    Ok((width as u32, height as u32))
}

fn read_hdr(file: &Path) -> Result<Texels, String> {
    use image::ImageDecoder;
    let f = std::fs::File::open(file).map_err(|e| format!("cannot read file: {e}"))?;
    let decoder = image::codecs::hdr::HdrDecoder::new(std::io::BufReader::new(f))
        .map_err(|e| format!("not a Radiance HDR image: {e}"))?;
    let (w, h) = decoder.dimensions();
    let (w, h) = check_size(w.into(), h.into())?;
    if decoder.color_type() != image::ColorType::Rgb32F {
        return Err(format!("unexpected HDR colour type {:?}", decoder.color_type()));
    }
    let mut bytes = vec![0u8; w as usize * h as usize * 12];
    decoder
        .read_image(&mut bytes)
        .map_err(|e| format!("cannot decode the Radiance HDR image: {e}"))?;
    let texels = bytes
        .chunks_exact(12)
        .map(|b| {
            let c =
                |k: usize| f32::from_ne_bytes([b[4 * k], b[4 * k + 1], b[4 * k + 2], b[4 * k + 3]]);
            [c(0), c(1), c(2)]
        })
        .collect();
    Ok((w, h, texels))
}

fn read_exr(file: &Path) -> Result<Texels, String> {
    use exr::prelude::*;
    let meta = exr::meta::MetaData::read_from_file(file, false)
        .map_err(|e| format!("not a readable OpenEXR image: {e}"))?;
    for header in meta.headers.iter() {
        check_size(header.layer_size.width() as u64, header.layer_size.height() as u64)?;
    }
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .rgba_channels(
            |size, _| (size.width(), vec![[0.0f32; 3]; size.area()]),
            |(w, px): &mut (usize, Vec<[f32; 3]>),
             at: Vec2<usize>,
             (r, g, b, _): (f32, f32, f32, f32)| px[at.y() * *w + at.x()] = [r, g, b],
        )
        .first_valid_layer()
        .all_attributes()
        .from_file(file)
        .map_err(|e| {
            format!("cannot decode the OpenEXR image (it needs R, G and B channels): {e}")
        })?;
    let size = image.layer_data.size;
    let (w, h) = check_size(size.width() as u64, size.height() as u64)?;
    Ok((w, h, image.layer_data.channel_data.pixels.1))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_beyond_the_bounds_are_refused_before_reading() {
        assert!(check_size(8192, 4096).is_ok());
        let e = check_size(16384, 4096).unwrap_err();
        assert!(e.contains("16384x4096"), "{e}");
        assert!(check_size(20000, 1).is_err());
        assert!(check_size(0, 4).is_err());
    }
}
