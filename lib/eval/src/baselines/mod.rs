//! Baselines a user would pick instead of PIS (thesis 4.8, figures 4.9–4.13): video codecs
//! through ffmpeg, fed along a zig-zag path through the parameter space.

pub mod path;
pub mod video;
