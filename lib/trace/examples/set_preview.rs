//! Writes PNG previews (sRGB, clamped) of every layer of one point of a ray-traced set:
//! `cargo run --release -p pis-trace --example set_preview -- SET_DIR POINT OUT_DIR`.

use pis_trace::set::RaySet;
use std::path::PathBuf;

fn srgb(x: f32) -> u8 {
    let x = x.clamp(0.0, 1.0);
    let s = if x <= 0.003_130_8 { 12.92 * x } else { 1.055 * x.powf(1.0 / 2.4) - 0.055 };
    (s * 255.0 + 0.5) as u8
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    if args.len() != 4 {
        return Err("usage: preview SET_DIR POINT OUT_DIR".into());
    }
    let set = RaySet::open(&args[1])?;
    let point: usize = args[2].parse()?;
    let out = PathBuf::from(&args[3]);
    std::fs::create_dir_all(&out)?;
    let images = set.read_point(point)?;
    for layer in &images.layers {
        let (w, h) = (layer.width, layer.height);
        let mut img = image::RgbImage::new(w, h);
        for y in 0..h {
            for x in 0..w {
                let px = if layer.channels.len() == 1 {
                    let v = srgb(layer.value(&layer.channels[0], x, y));
                    [v; 3]
                } else {
                    let c = layer.rgb(x, y);
                    [srgb(c.x), srgb(c.y), srgb(c.z)]
                };
                img.put_pixel(x, y, image::Rgb(px));
            }
        }
        img.save(out.join(format!("{}.png", layer.name)))?;
    }
    Ok(())
}
