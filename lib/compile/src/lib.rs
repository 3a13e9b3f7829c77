//! Texture inference by inverse rendering (thesis ch. 3): a software model of the player's
//! GPU pipeline that yields the render matrix A of an object at a parameter point, and the
//! least-squares solver that finds the texture x with A·x ≈ b (the ray-traced layer).
//!
//! The types [`TextureLayout`], [`Sampler`] and [`RenderMatrix`] are the contract between
//! the hardware model (which builds [`RenderMatrix`]es analytically: [`model::render_matrix`]),
//! the player's probe mode (which measures them through wgpu, in `pis-play`) and the solver
//! (which consumes them).
//!
//! The hardware model, stage by stage (each the twin of a function in the player's WGSL,
//! `lib/play/src/textured.wgsl`): [`transform`] (vertex shader, clipping, viewport),
//! [`raster`] (coverage with the top-left rule, depth), [`interpolate`] (perspective-correct
//! (s, t) and fine derivatives), [`lod`] (the Vulkan LOD), [`filter`] (sampler weights),
//! [`model`] (the render matrix), [`mod@antialias`] (thesis 3.4.4).

pub mod antialias;
pub mod filter;
pub mod interpolate;
pub mod layout;
pub mod lod;
pub mod matrix;
pub mod model;
pub mod raster;
pub mod sampler;
pub mod transform;

pub use antialias::{antialias, antialiased_render_matrix, DisplayFilter};
pub use layout::TextureLayout;
pub use matrix::RenderMatrix;
pub use model::{render_matrix, scene_depth, ModelError, TexturedObject};
pub use raster::DepthBuffer;
pub use sampler::{Address, Filter, Sampler};
pub use transform::{DrawMesh, TextureTransform, Viewport};
