//! Scenes for PIS: a glTF 2.0 scene plus `scene.toml` (resolution, samples per pixel, the
//! parameter space, object roles), evaluated at any point of the parameter space.
//!
//! The types in [`model`] are the contract between scene loading and the tracer: the tracer
//! consumes a [`Scene`] and, per parameter point, a [`Frame`].

pub mod model;

pub use model::*;
pub use pis_format::{DimensionKind, ObjectRole};
