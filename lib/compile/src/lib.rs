//! Texture inference by inverse rendering (thesis ch. 3): a software model of the player's
//! GPU pipeline that yields the render matrix A of an object at a parameter point, and the
//! least-squares solver that finds the texture x with A·x ≈ b (the ray-traced layer).
//!
//! The types in this file are the contract between the hardware model (which builds
//! [`RenderMatrix`]es analytically), the player's probe mode (which measures them through
//! wgpu, in `pis-play`) and the solver (which consumes them).

pub mod layout;
pub mod matrix;
pub mod sampler;

pub use layout::TextureLayout;
pub use matrix::RenderMatrix;
pub use sampler::{Address, Filter, Sampler};
