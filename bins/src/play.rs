//! pis-play: the player's command line. Headless mode draws offscreen (`headless`); the
//! arguments (`args`) are shared with a window mode.

pub mod args;
pub mod headless;

use crate::cli::{Exit, Failure};
pub use args::PlayArgs;

/// Whether a display server is reachable through the environment (X11 or Wayland).
pub fn has_display() -> bool {
    ["DISPLAY", "WAYLAND_DISPLAY"].iter().any(|v| std::env::var_os(v).is_some_and(|s| !s.is_empty()))
}

/// Runs pis-play: in a window where a display is set and no headless output (--out,
/// --compare) is asked for; else without a window: with `--headless`, or (with a note on
/// stderr) when no window can be opened.
pub fn run(args: &PlayArgs) -> Result<Exit, Failure> {
    let window_only = args.screenshot.is_some() || args.set.is_some();
    if !args.headless && args.out.is_none() && args.compare.is_none() {
        if has_display() {
            match crate::play_window::try_run(args) {
                Ok(()) => return Ok(Exit::Ok),
                Err(crate::play_window::WindowFailure::NoDisplay(m)) if !window_only => {
                    eprintln!("pis-play: note: {m}; drawing headless");
                }
                Err(e) => return Err(e.into()),
            }
        } else if window_only {
            return Err(Failure::new(Exit::Runtime, anyhow::anyhow!("--screenshot and --set need a window, and no display is set (DISPLAY / WAYLAND_DISPLAY): run under `xvfb-run -a`")));
        } else {
            eprintln!("pis-play: note: no display (DISPLAY / WAYLAND_DISPLAY unset); drawing headless");
        }
    } else if window_only {
        return Err(Failure::new(Exit::Usage, anyhow::anyhow!("--screenshot and --set are window options; they do not go with --headless, --out or --compare")));
    }
    headless::run(args)
}
