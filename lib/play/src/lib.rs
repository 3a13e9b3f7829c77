//! The PIS player over wgpu. So far: the textured-object pipeline (`textured.rs` +
//! `textured.wgsl`), which draws an object exactly as pis-compile's hardware model says,
//! offscreen into a float target; and probe mode (thesis 3.4.3), which measures an object's
//! render matrix through that pipeline.
//!
//! Without a GPU, wgpu runs on Mesa's lavapipe: `apt-get install -y mesa-vulkan-drivers`.

pub mod error;
pub mod gpu;
pub mod image;
pub mod probe;
pub mod textured;

pub use error::{PlayError, ADAPTER_HINT};
pub use gpu::{Gpu, GpuOptions};
pub use image::FloatImage;
pub use probe::probe_render_matrix;
pub use textured::{render_object, ObjectScene, ObjectTexture, TexturedPipeline};
