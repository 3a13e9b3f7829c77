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
//! `lib/play/src/textured.wgsl` and the files it is composed with): [`transform`] (vertex
//! shader, clipping, viewport), [`raster`] (coverage with the top-left rule, depth),
//! [`interpolate`] (perspective-correct (s, t) and fine derivatives), [`lod`] (the Vulkan
//! LOD), [`filter`] (sampler weights), [`model`] (the render matrix), [`mod@antialias`]
//! (thesis 3.4.4).
//!
//! The solver (thesis 3.5): [`solve()`] (one view), [`solve_view_independent`] (eq. 3.7;
//! [`solve_view_source`] with the views read one at a time, [`stacked`]),
//! settings in [`SolveSettings`]; [`cg`] (conjugate gradient with exact line search),
//! [`normal_equations`] (the A and AᵀA forms), [`regularize`] (eqs. 3.8 and 3.9),
//! [`sparse`] (deterministic parallel sparse products), [`decimation`] (the player's MIP
//! chain as a linear map of level 0, for [`MipSolve::Decimated`]).
//!
//! Texture-coordinate optimization (thesis 3.2): [`texcoord`]. Render matrices for a known
//! screen→texture map, for tests and benchmarks: [`synthetic`].

pub mod antialias;
pub mod baseline;
pub mod bounded;
pub mod cg;
pub mod decimation;
pub mod error;
pub mod filter;
pub mod hybrid;
pub mod interpolate;
pub mod layout;
pub mod lod;
pub mod matrix;
pub mod model;
pub mod normal_equations;
pub mod raster;
pub mod regularize;
pub mod relight;
pub mod sampler;
pub mod shell;
pub mod solve;
pub mod sparse;
pub mod stacked;
pub mod synthetic;
pub mod texcoord;
pub mod transform;
pub mod view;

pub use antialias::{antialias, antialiased_render_matrix, DisplayFilter};
pub use error::CompileError;
pub use layout::TextureLayout;
pub use matrix::RenderMatrix;
pub use model::{render_matrix, scene_depth, ModelError, TexturedObject};
pub use normal_equations::Form;
pub use raster::DepthBuffer;
pub use sampler::{Address, Filter, Sampler, MAX_ANISOTROPY};
pub use solve::{
    render, solve, solve_view_independent, solve_view_source, FormChoice, MipSolve, Solution,
    SolveSettings, View,
};
pub use stacked::ViewSource;
pub use transform::{DrawMesh, TextureTransform, Viewport};

#[cfg(test)]
mod solve_tests;
