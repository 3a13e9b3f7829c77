//! Scenes for PIS: a glTF 2.0 scene plus `scene.toml` (resolution, samples per pixel, the
//! parameter space, object roles), evaluated at any point of the parameter space.
//!
//! The types in [`model`] are the contract between scene loading and the tracer: the tracer
//! calls [`load`] (or [`load_with`]) once and then [`Scene::frame`] per parameter point.
//! scene.toml is documented key by key in docs/SCENE.md.

pub mod animation;
mod error;
mod frame;
mod gltf_load;
pub mod light_path;
mod load;
#[cfg(test)]
mod load_tests;
pub mod manifest;
pub mod material;
pub mod model;
pub mod orbit;
pub mod rig;
mod space;
pub mod texture;

pub use error::SceneError;
pub use load::{load, load_with, LoadOptions};
pub use model::*;
pub use pis_format::{DimensionKind, ObjectRole};
pub use rig::Rig;
pub use space::sample_values;
