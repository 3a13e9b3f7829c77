//! Texture inference by inverse rendering (thesis ch. 3): a software model of the player's
//! GPU pipeline that yields the render matrix A of an object at a parameter point, and the
//! least-squares solver that finds the texture x with A·x ≈ b (the ray-traced layer).
//!
//! The types in `layout`, `matrix` and `sampler` are the contract between the hardware
//! model (which builds [`RenderMatrix`]es analytically), the player's probe mode (which
//! measures them through wgpu, in `pis-play`) and the solver (which consumes them).
//!
//! The solver: [`solve`] (one view), [`solve_view_independent`] (eq. 3.7), settings in
//! [`SolveSettings`]; `cg` (conjugate gradient with exact line search), `normal_equations`
//! (the A and AᵀA forms), `regularize` (eqs. 3.8 and 3.9).

pub mod cg;
pub mod error;
pub mod layout;
pub mod matrix;
pub mod normal_equations;
pub mod regularize;
pub mod sampler;
pub mod solve;
pub mod sparse;
pub mod synthetic;
pub mod texcoord;

pub use error::CompileError;
pub use layout::TextureLayout;
pub use matrix::RenderMatrix;
pub use normal_equations::Form;
pub use sampler::{Address, Filter, Sampler};
pub use solve::{render, solve, solve_view_independent, FormChoice, Solution, SolveSettings, View};

#[cfg(test)]
mod solve_tests;
