//! Image export: linear float data to OpenEXR (linear) and PNG (sRGB), each written to a
//! temporary file and renamed into place.

use std::path::{Path, PathBuf};

use anyhow::Context;

pub use pis_codec::display::srgb_encode;

fn temp_beside(path: &Path) -> PathBuf {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    path.with_file_name(format!(".{name}.tmp"))
}

fn rename_into_place(tmp: &Path, path: &Path) -> anyhow::Result<()> {
    std::fs::rename(tmp, path)
        .with_context(|| format!("cannot move {} to {}", tmp.display(), path.display()))
}

/// Writes `width × height × channels` (3 or 4) linear values as an f32 OpenEXR file.
pub fn write_exr(
    path: &Path,
    width: u32,
    height: u32,
    channels: u32,
    data: &[f32],
) -> anyhow::Result<()> {
    use exr::prelude::*;
    let tmp = temp_beside(path);
    let (w, h, c) = (width as usize, height as usize, channels as usize);
    let at = |x: usize, y: usize, k: usize| data[(y * w + x) * c + k];
    let result = if c == 4 {
        write_rgba_file(&tmp, w, h, |x, y| (at(x, y, 0), at(x, y, 1), at(x, y, 2), at(x, y, 3)))
    } else {
        write_rgb_file(&tmp, w, h, |x, y| (at(x, y, 0), at(x, y, 1), at(x, y, 2)))
    };
    if let Err(e) = result {
        let _ = std::fs::remove_file(&tmp);
        return Err(e).with_context(|| format!("cannot write {}", path.display()));
    }
    rename_into_place(&tmp, path)
}

/// Writes linear values as an 8-bit sRGB PNG (alpha stays linear).
pub fn write_png(
    path: &Path,
    width: u32,
    height: u32,
    channels: u32,
    data: &[f32],
) -> anyhow::Result<()> {
    let c = channels as usize;
    let bytes: Vec<u8> = data
        .chunks_exact(c)
        .flat_map(|px| {
            (0..c).map(move |k| {
                let v = if k == 3 { px[k].clamp(0.0, 1.0) } else { srgb_encode(px[k]) };
                (v * 255.0 + 0.5) as u8
            })
        })
        .collect();
    let tmp = temp_beside(path);
    let color =
        if c == 4 { image::ExtendedColorType::Rgba8 } else { image::ExtendedColorType::Rgb8 };
    if let Err(e) =
        image::save_buffer_with_format(&tmp, &bytes, width, height, color, image::ImageFormat::Png)
    {
        let _ = std::fs::remove_file(&tmp);
        return Err(e).with_context(|| format!("cannot write {}", path.display()));
    }
    rename_into_place(&tmp, path)
}
