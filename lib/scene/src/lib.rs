//! Scenes for PIS: a glTF 2.0 scene plus `scene.toml` (resolution, samples per pixel, the
//! parameter space, object roles), evaluated at any point of the parameter space.
//!
//! The types in [`model`] are the contract between scene loading and the tracer: the tracer
//! calls [`load`] (or [`load_with`]) once and then [`Scene::frame`] per parameter point.
//! scene.toml is documented key by key in docs/SCENE.md.
//!
//! ```no_run
//! use std::path::Path;
//! use pis_scene::{load_with, LoadOptions};
//!
//! let options = LoadOptions { preset: Some("paper".into()), spp: Some(4), ..LoadOptions::default() };
//! let scene = load_with(Path::new("samples/demo1/scene.toml"), &options)?;
//! for index in 0..scene.space.point_count() {
//!     let point = scene.space.point(index); // one sample index per dimension
//!     let frame = scene.frame(&point)?; // camera, lights, one instance per object
//!     let _eye = frame.camera.world_from_camera.w_axis;
//! }
//! # Ok::<(), pis_scene::SceneError>(())
//! ```

mod accessor_check;
pub mod animation;
pub mod distribution;
mod env_image;
pub mod environment;
#[cfg(test)]
mod environment_tests;
mod error;
pub mod extensions;
mod frame;
mod gltf_files;
mod gltf_images;
mod gltf_load;
pub mod lens_tree;
mod light;
pub mod light_direction;
#[cfg(test)]
mod light_direction_tests;
pub mod light_path;
mod load;
#[cfg(test)]
mod load_tests;
pub mod manifest;
pub mod material;
#[cfg(test)]
mod material_load_tests;
mod material_textures;
pub mod model;
pub mod optics;
pub mod orbit;
pub mod rig;
mod space;
pub mod texture;
mod texture_ref;
pub mod toml_lights;

pub use env_image::{
    read as read_environment_image, MAX_SIDE as MAX_ENVIRONMENT_SIDE,
    MAX_TEXELS as MAX_ENVIRONMENT_TEXELS,
};
pub use environment::{Environment, EnvironmentRadiance, LatLongImage};
pub use error::SceneError;
pub use load::{load, load_with, LoadOptions};
pub use model::*;
pub use pis_format::{DimensionKind, ObjectRole};
pub use rig::Rig;
pub use space::sample_values;
