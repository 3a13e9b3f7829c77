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

/// Runs pis-play without a window: with `--headless`, or (with a note on stderr) when no
/// window can be opened.
pub fn run(args: &PlayArgs) -> Result<Exit, Failure> {
    if !args.headless {
        if has_display() {
            eprintln!("pis-play: note: window mode is not available in this build; drawing headless");
        } else {
            eprintln!("pis-play: note: no display (DISPLAY / WAYLAND_DISPLAY unset); drawing headless");
        }
    }
    headless::run(args)
}
