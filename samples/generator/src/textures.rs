//! Procedural textures written as PNG (sRGB-encoded 8-bit, as glTF base colour expects).

use std::io;
use std::path::Path;

use image::{ImageFormat, Rgb, RgbImage};

fn save(img: &RgbImage, path: &Path) -> io::Result<()> {
    let mut bytes = io::Cursor::new(Vec::new());
    img.write_to(&mut bytes, ImageFormat::Png).map_err(io::Error::other)?;
    std::fs::write(path, bytes.into_inner())
}

/// A checkerboard of `checks × checks` squares alternating two sRGB colours.
pub fn checker(path: &Path, size: u32, checks: u32, a: [u8; 3], b: [u8; 3]) -> io::Result<()> {
    let cell = (size / checks).max(1);
    let img = RgbImage::from_fn(size, size, |x, y| {
        if ((x / cell) + (y / cell)).is_multiple_of(2) {
            Rgb(a)
        } else {
            Rgb(b)
        }
    });
    save(&img, path)
}

/// Wallpaper: vertical stripes of two colours with a thin darker line between them (the
/// green wallpaper of the seed's demo scenes).
pub fn wallpaper(path: &Path, size: u32, stripes: u32, a: [u8; 3], b: [u8; 3]) -> io::Result<()> {
    let width = (size / stripes).max(2);
    let img = RgbImage::from_fn(size, size, |x, _| {
        let k = x % width;
        if k == 0 {
            Rgb([a[0] / 2, a[1] / 2, a[2] / 2])
        } else if (x / width).is_multiple_of(2) {
            Rgb(a)
        } else {
            Rgb(b)
        }
    });
    save(&img, path)
}

/// An image of `size × size` texels from `texel(x, y)` (bytes as stored: sRGB for colour
/// maps, linear for metallic-roughness and normal maps).
pub fn from_fn(path: &Path, size: u32, texel: impl Fn(u32, u32) -> [u8; 3]) -> io::Result<()> {
    save(&RgbImage::from_fn(size, size, |x, y| Rgb(texel(x, y))), path)
}
