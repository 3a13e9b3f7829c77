//! What the PIS command-line tools share: exit codes, error reporting, and the pieces of
//! each tool that are more than argument parsing.

pub mod bench;
pub mod cli;
pub mod diff;
pub mod images;
pub mod infer;
pub mod inspect;
pub mod pack;
pub mod pack_args;
pub mod play;
pub mod reencode;
pub mod play_window;
