//! Environment-map shells (thesis ch. 5): the hardware model of an object drawn with a
//! layered environment map. [`geometry`] intersects reflection rays with a shell (sphere,
//! ellipsoid, box, cylinder: SPEC.md 7.3), [`cube`] looks the hit up in a cube map (SPEC.md
//! 8.2) with the LOD and trilinear, seamless filtering the player uses, and [`model`] builds
//! a shell's render matrix A, which the chapter 3 solver inverts as for a surface texture.

pub mod cube;
pub mod depth;
pub mod geometry;
pub mod model;

pub use depth::DepthCube;
pub use geometry::{fresnel, lookup_direction, Shell, ShellShape};
pub use model::{shell_fresnel, shell_render_matrix, ShellObject};
