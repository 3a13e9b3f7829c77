//! `pis-bench` evaluations that chart accuracy against size and speed: the rate–distortion
//! sweep of PIS against the baselines a user would pick instead (thesis 4.8, figures
//! 4.9–4.13), and the files every evaluation writes.

pub mod all;
pub mod camera_path;
pub mod hybrid;
pub mod mpeg_texture;
pub mod output;
pub mod playback;
pub mod rd;
pub mod reference;
pub mod reflective;
pub mod speed;
pub mod stability;
pub mod view_video;
