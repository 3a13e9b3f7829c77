//! pis-play's window mode (thesis 1.4, third step; 5.9): the player's frames in a window,
//! with panels to move through the parameter space, play a path, switch blending and camera,
//! compare with the ray-traced gold standard, relight a relightable file, and watch the frame
//! rate.

pub mod app;
pub mod gold;
pub mod lights;
pub mod screenshot;
pub mod surface;
pub mod ui;

pub use app::{run_window, RunReport, WindowFailure, WindowOptions};

use crate::cli::{Exit, Failure};
use crate::play::args::{PathChoice, PlayArgs};

/// Frames drawn before `--screenshot` saves one when `--frames` is not given: egui lays a
/// new panel out on its first frame and shows it from the second.
pub const SCREENSHOT_FRAME: u32 = 3;

/// The window options of a pis-play command line.
pub fn window_options(args: &PlayArgs) -> Result<WindowOptions, Failure> {
    let (play, orbit) = match &args.path {
        None => (false, false),
        Some(PathChoice::Diagonal) => (true, false),
        Some(PathChoice::Orbit) => (false, true),
        Some(PathChoice::File(f)) => {
            return Err(Failure::new(
                Exit::Usage,
                anyhow::anyhow!(
                    "--path {}: a path file is played headless (--headless)",
                    f.display()
                ),
            ))
        }
    };
    let frames = match (args.frames, &args.screenshot) {
        (Some(n), _) => Some(u32::try_from(n).ok().filter(|&n| n > 0).ok_or_else(|| {
            Failure::new(Exit::Usage, anyhow::anyhow!("--frames {n}: expected 1 to {}", u32::MAX))
        })?),
        (None, Some(_)) => Some(SCREENSHOT_FRAME),
        (None, None) => None,
    };
    Ok(WindowOptions {
        file: args.file.clone(),
        size: args.size,
        set: args.set.clone(),
        screenshot: args.screenshot.clone(),
        frames,
        at: args.at.clone(),
        play,
        orbit,
        multilinear: args.blend == pis_play::Blend::Multilinear,
        hide_ui: args.hide_panels,
        show_gold: args.show_gold,
        vsync: !args.no_vsync,
        gpu: pis_play::GpuOptions::default(),
        player: args.player_options(),
        lights: args.lights.clone(),
    })
}

/// pis-play in a window: runs until the window is closed, or for `--frames` frames and then
/// prints the frame rate (JSON on stdout with `--json`).
pub fn run(args: &PlayArgs) -> Result<(), Failure> {
    try_run(args).map_err(Failure::from)
}

/// [`run`], telling apart a display that cannot be connected to (nothing opened).
pub fn try_run(args: &PlayArgs) -> Result<(), WindowFailure> {
    let report = run_window(window_options(args)?)?;
    if let Some(r) = report {
        if args.json {
            println!(
                "{}",
                serde_json::to_string_pretty(&r).map_err(|e| Failure::new(Exit::Runtime, e))?
            );
        }
        eprintln!(
            "pis-play: {} frames at {}×{} ({}) in {:.2} s: {:.1} fps (first frame left out); player {:.2} ms per frame (decode {:.2} ms, upload {:.2} ms, GPU rebuild {:.2} ms)",
            r.frames,
            r.frame_size[0],
            r.frame_size[1],
            pis_eval::headless::msaa_label(r.msaa_samples, r.msaa_requested),
            r.seconds,
            r.fps,
            r.frame_ms,
            r.decode_ms,
            r.upload_ms,
            r.rebuild_ms
        );
        if let Some(p) = &args.screenshot {
            eprintln!("pis-play: frame {} saved to {}", r.frames, p.display());
        }
    }
    Ok(())
}
