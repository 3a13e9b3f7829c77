//! Drawing a frame (`frame.wgsl`): a pass that writes depth and the object index of every
//! pixel's nearest surface, then one additive draw per object, layer and parameter sample,
//! with the block's texture transform (branch cuts, then the affine map) in the vertex
//! shader and the hardware model's LOD and sampler in the fragment shader, and one additive
//! draw of the reflection term per reflective object and parameter sample
//! (`reflection.wgsl`: the environment-map shells looked up as the hardware model
//! does, composited "over", times Fresnel), and of both terms of each lens object per
//! parameter sample (`hybrid.wgsl`: the cube-map vectors of the rays traced through it at its
//! vertices). Layers and terms add in linear space (SPEC.md 9:
//! surface layers combine by addition, radiance = surface + F · reflection). With more than
//! one sample per pixel (`multisample.rs`) depth and object indices are kept per sample and
//! the colour is resolved into the target: by the hardware's average of each pixel's own
//! samples, or, given the ray-traced set's display filter, by the display-filter resolve
//! (`resolve.rs`).
//!
//! One file per stage, each importing only those below it: `draw.rs` (what a frame draws),
//! `additive.rs` (the additive pass's pipeline pieces), `translucent.rs` (the translucent
//! objects' pipelines and composite), `reflection.rs` and `hybrid.rs` (the reflection and
//! lens terms' uniforms and bind groups), `resolve.rs`, `pipelines.rs`, `targets.rs`,
//! `encode.rs` (recording the passes), `readback.rs`, and `lens_term.rs` (one lens term drawn
//! through the frame on its own).

mod additive;
mod draw;
mod encode;
pub mod hybrid;
mod lens_term;
mod pipelines;
pub(crate) mod readback;
pub mod reflection;
pub mod resolve;
mod targets;
mod translucent;

pub use draw::{LayerDraw, MeshGpu, ObjectDraw, ID_FORMAT, NO_OBJECT};
pub use encode::{encode, FrameDraws, FrameTarget};
pub use lens_term::render_lens_term;
pub use pipelines::{FramePipelines, SHADER};
pub use readback::{colour_image, map_read, Readback};
pub use reflection::{ReflectionDraw, TermShell, MAX_TERM_SHELLS};
pub use targets::{offscreen_format, Targets};
