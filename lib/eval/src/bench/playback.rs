//! Playback cost against quality: a container played by the player runtime
//! (`pis_play::Player`, offscreen) along the zig-zag path through every sample point, frame
//! times (request to drawn and read back: decoding, uploads, drawing) and PSNR against the
//! gold standard (`crate::compare`), per texture-resolution reduction factor.

use std::path::Path;
use std::sync::Arc;

use crate::baselines::path::zigzag;
use crate::compare::{compare_with_set, CompareOptions};
use anyhow::{anyhow, Result};
use pis_play::{CameraChoice, FrameRequest, Gpu, Player, PlayerOptions};

/// Samples per pixel of the harness's playback: one, as pis-pack's prediction draws (the
/// player's window and `pis-play` default to multisampling; `pis-play --msaa 4` measures it).
const BENCH_MSAA: u32 = 1;
use serde::Serialize;

/// One container at one reduction factor.
#[derive(Clone, Debug, Serialize)]
pub struct PlaybackRow {
    pub codec: String,
    pub reduction: u32,
    /// Whole-image PSNR of the played frames at the sample cameras.
    pub psnr_db: f64,
    /// The same over the pixels the objects cover.
    pub covered_psnr_db: f64,
    pub frame_ms_mean: f64,
    pub frame_ms_worst: f64,
    pub frames: usize,
}

/// The GPU, or why there is none.
pub fn gpu() -> Result<Arc<Gpu>> {
    Gpu::new().map(Arc::new).map_err(|e| anyhow!("no GPU adapter for the player: {e}"))
}

/// Plays `file` at each reduction factor: one walk along the zig-zag path from a cold
/// cache (every frame timed, the worst included), then the comparison with the set.
pub fn measure(
    gpu: &Arc<Gpu>,
    file: &Path,
    set_dir: &Path,
    codec: &str,
    reductions: &[u32],
) -> Result<Vec<PlaybackRow>> {
    let mut rows = Vec::new();
    for &reduction in reductions {
        let mut player = Player::open(
            gpu.clone(),
            file,
            PlayerOptions { reduction, msaa: BENCH_MSAA, ..Default::default() },
        )?;
        let dims: Vec<Vec<f32>> = player.dimensions().iter().map(|d| d.values.clone()).collect();
        let counts: Vec<u32> = dims.iter().map(|v| v.len() as u32).collect();
        let size = player.image_size();
        let mut times = Vec::new();
        for p in zigzag(&counts) {
            let point: Vec<f32> = p.iter().zip(&dims).map(|(&i, v)| v[i as usize]).collect();
            let stats =
                player.render_timed(&FrameRequest { point, camera: CameraChoice::Sample }, size)?;
            times.push(stats.frame_ms);
        }
        let c =
            compare_with_set(&mut player, set_dir, &CompareOptions { size: None }, &mut |_| {})?;
        let mean = times.iter().sum::<f64>() / times.len().max(1) as f64;
        let worst = times.iter().copied().fold(0.0, f64::max);
        eprintln!("pis-bench: playback: {codec} reduction {reduction}: {mean:.1} ms mean, {worst:.1} ms worst, {:.2} dB ({:.2} dB covered)", c.psnr_db, c.covered_psnr_db);
        rows.push(PlaybackRow {
            codec: codec.to_string(),
            reduction,
            psnr_db: c.psnr_db,
            covered_psnr_db: c.covered_psnr_db,
            frame_ms_mean: mean,
            frame_ms_worst: worst,
            frames: times.len(),
        });
    }
    Ok(rows)
}

/// PSNR of `file` played at every sample point against the set: (whole image, covered).
pub fn played_psnr(gpu: &Arc<Gpu>, file: &Path, set_dir: &Path) -> Result<(f64, f64)> {
    let mut player =
        Player::open(gpu.clone(), file, PlayerOptions { msaa: BENCH_MSAA, ..Default::default() })?;
    let c = compare_with_set(&mut player, set_dir, &CompareOptions { size: None }, &mut |_| {})?;
    Ok((c.psnr_db, c.covered_psnr_db))
}
