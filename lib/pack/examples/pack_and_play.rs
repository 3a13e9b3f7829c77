//! The pipeline through the library API alone: demo1's scene traced into a set
//! (pis-trace), the set packed into a container (pis-pack), and one frame of it played on
//! the GPU (pis-play) and measured against the ray-traced gold standard.
//!
//!     cargo run --release -p pis-pack --example pack_and_play -- OUT_DIR
//!
//! Writes OUT_DIR/demo1-set, OUT_DIR/demo1.pis and OUT_DIR/frame.png. Needs a GPU adapter
//! (on a machine without one, Mesa's lavapipe: `apt-get install -y mesa-vulkan-drivers`).

use std::error::Error;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use pis_pack::{NoProgress, PackSettings};
use pis_play::{CameraChoice, FrameRequest, Gpu, Player, PlayerOptions};
use pis_scene::LoadOptions;
use pis_trace::set::RaySet;
use pis_trace::TraceSettings;

fn main() -> Result<(), Box<dyn Error>> {
    let out = std::env::args_os()
        .nth(1)
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("pack_and_play"));
    std::fs::create_dir_all(&out)?;

    // scene → set: demo1 at 80×60, 2 samples per pixel.
    let scene_toml = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../samples/demo1/scene.toml");
    let scene = pis_scene::load_with(
        &scene_toml,
        &LoadOptions { resolution: Some((80, 60)), spp: Some(2), ..LoadOptions::default() },
    )?;
    let set_dir = out.join("demo1-set");
    let traced = pis_trace::render_set(
        &scene,
        &set_dir,
        &TraceSettings::new(scene.resolution, scene.spp),
        None,
        &pis_trace::NoProgress,
    )?;
    println!("traced {} points of {}x{}", traced.points, scene.resolution.0, scene.resolution.1);

    // set → file: pis-pack's defaults at 48:1.
    let file = out.join("demo1.pis");
    let report =
        pis_pack::pack(&set_dir, &file, &PackSettings::new().with_ratio(48.0), &NoProgress)?;
    println!(
        "packed {} bytes at {:.0}:1, predicted {:.2} dB",
        report.bytes, report.ratio_without_geometry, report.psnr_db
    );

    // file → frame: the set's first point, drawn with the sample camera.
    let set = RaySet::open(&set_dir)?;
    let point = &set.meta.points[0];
    let mut player = Player::open(Arc::new(Gpu::new()?), &file, PlayerOptions::default())?;
    let size = player.image_size();
    let (frame, stats) = player.render_image(
        &FrameRequest { point: point.values.clone(), camera: CameraChoice::Sample },
        size,
    )?;
    pis_pack::images::write_png(&out.join("frame.png"), frame.width, frame.height, 4, &frame.rgba)?;

    // frame against the gold standard, on display values.
    let gold = set.read_point(point.index)?;
    let combined = gold.layer("combined").ok_or("the set has no combined layer")?;
    let psnr = psnr_display(&frame.rgba, &combined.planes);
    println!(
        "played point {:?} in {:.1} ms: {psnr:.2} dB against the gold standard",
        point.values, stats.frame_ms
    );
    Ok(())
}

/// PSNR (dB, peak 1) of an RGBA frame against RGB planes, both linear radiance, compared
/// as sRGB display values clamped to [0, 1].
fn psnr_display(rgba: &[f32], planes: &[Vec<f32>]) -> f64 {
    let frame: Vec<f32> = rgba.chunks_exact(4).flat_map(|px| [px[0], px[1], px[2]]).collect();
    let gold: Vec<f32> =
        (0..planes[0].len()).flat_map(|p| [0, 1, 2].map(|c| planes[c][p])).collect();
    pis_codec::display::psnr_display(&frame, &gold)
}
