//! The PIS player over wgpu: the textured-object pipeline (`textured.rs` + `textured.wgsl`),
//! which draws an object exactly as pis-compile's hardware model says, offscreen into a
//! float target; probe mode (thesis 3.4.3), which measures an object's render matrix through
//! that pipeline; and the runtime (thesis 4.7, [`Player`]): random-access reading of a
//! `.pis`, decoding on worker threads through a level-image cache with lifetimes, GPU MIP
//! chains, and frames of every object with its surface layers and, for reflective objects,
//! its reflection term (environment-map shells, `shell.rs`, looked up as the hardware model
//! does, composited "over", times Fresnel), for lens objects both terms of hybrid rendering
//! (`frame/hybrid.rs`: vertex rays traced through the object each frame), multisampled on
//! silhouettes (`multisample.rs`)
//! and resolved with the ray-traced set's display filter (`frame/resolve.rs`).
//!
//! Without a GPU, wgpu runs on Mesa's lavapipe: `apt-get install -y mesa-vulkan-drivers`.

pub mod blend;
pub mod cache;
pub mod camera;
pub mod cube_atlas;
pub mod cube_border;
pub mod decode;
pub mod error;
pub mod frame;
pub mod gpu;
pub mod hybrid;
pub mod image;
pub mod lens_rays;
pub mod memory;
pub mod mip;
pub mod multisample;
pub mod player;
pub mod probe;
pub mod rebuild;
pub mod relit;
pub mod shell;
pub mod textured;
pub mod window;

pub use blend::Blend;
pub use camera::{CameraChoice, ViewCamera};
pub use error::{PlayError, ADAPTER_HINT};
pub use gpu::{Gpu, GpuOptions};
pub use hybrid::{render_hybrid, HybridPipeline};
pub use image::FloatImage;
pub use multisample::Multisample;
pub use player::{
    check_depth_steps, DirectionalLight, FrameRequest, FrameStats, LensRays, Lights, Player,
    PlayerOptions, PrecisionChoice, Rebuild, Relight, TexturePrecision,
};
pub use probe::{probe, probe_render_matrix, Probe};
pub use shell::{render_shell, ShellPipeline, ShellTexture};
pub use textured::{render_object, ObjectScene, ObjectTexture, TexturedPipeline};
