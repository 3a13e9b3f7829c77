//! What the PIS command-line tools share: exit codes and error reporting, the options
//! several tools take, and the player's window. The work is in the library crates:
//! pis-pack (pack), pis-eval (reencode, diff, inspect, the headless player, the benchmarks).

pub mod cli;
pub mod pack_args;
pub mod play;
pub mod play_window;
