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

/// How pis-bench traces a scene.toml it is given (rd, speed, stability, all): raw, so its
/// charts measure the pack and the codecs on the tracer's own samples, whether or not Open
/// Image Denoise is on the machine; a denoised set from `pis-trace` is given as a set.
pub const TRACE_DENOISE: pis_trace::settings::DenoiseMode = pis_trace::settings::DenoiseMode::Off;

/// pis-pack's defaults as pis-bench packs with them (a scene.toml traced as
/// [`TRACE_DENOISE`] says).
pub fn pack_defaults() -> pis_pack::PackSettings {
    pis_pack::PackSettings { denoise: TRACE_DENOISE, ..pis_pack::PackSettings::new() }
}
