//! pis-play: plays a `.pis` file on the GPU (thesis 4.7). Headless: frames drawn offscreen,
//! written as sRGB PNGs and timed, or compared with a ray-traced set's gold standard.
//!
//! Exit codes: 0 ok, 1 bad arguments, 2 I/O, 3 invalid file, 4 runtime error (no GPU
//! adapter: install Mesa's lavapipe), 5 not supported.

use std::process::ExitCode;

use pis::cli;
use pis::play::PlayArgs;

fn main() -> ExitCode {
    match cli::parse::<PlayArgs>() {
        Ok(args) => cli::finish("pis-play", pis::play::run(&args)),
        Err(code) => code,
    }
}
