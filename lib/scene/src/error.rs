//! The one error type of scene loading and evaluation.

use std::path::PathBuf;

/// Everything that can go wrong while loading a scene or evaluating it at a parameter point.
///
/// Every variant names the file at fault and, where there is one, the field (a TOML key path
/// such as `dimension[1].samples` or a glTF JSON path such as
/// `meshes[0].primitives[2].attributes.POSITION`).
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// A file could not be read.
    #[error("{path}: cannot read file: {source}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// scene.toml is not valid TOML or does not match the schema (unknown key, wrong type).
    #[error("{path}: {message}")]
    Toml { path: PathBuf, message: String },
    /// The glTF file could not be parsed or failed the glTF validation.
    #[error("{path}: invalid glTF: {message}")]
    Gltf { path: PathBuf, message: String },
    /// The input uses a feature PIS does not support.
    #[error("{path}: field `{field}`: unsupported: {what}")]
    Unsupported { path: PathBuf, field: String, what: String },
    /// A buffer or value holds NaN or infinity.
    #[error("{path}: field `{field}`: non-finite value (NaN or infinity) at element {element}")]
    NonFinite { path: PathBuf, field: String, element: usize },
    /// A parameter dimension has no samples.
    #[error("{path}: field `{field}`: dimension `{dimension}` has zero samples")]
    ZeroSamples { path: PathBuf, field: String, dimension: String },
    /// A name in scene.toml matches nothing in the glTF (camera, light, animation, object) or
    /// in scene.toml itself (preset, dimension).
    #[error("{path}: field `{field}`: unknown {what} `{name}`; known: [{known}]")]
    UnknownName {
        path: PathBuf,
        field: String,
        /// "camera", "light", "animation", "object", "preset", "dimension".
        what: &'static str,
        name: String,
        /// The names that exist, comma-separated.
        known: String,
    },
    /// A value is present and well-typed but not acceptable (out of range, inconsistent).
    #[error("{path}: field `{field}`: {message}")]
    Invalid { path: PathBuf, field: String, message: String },
    /// A parameter point that does not belong to the parameter space.
    #[error("scene `{scene}`: parameter point {point:?} is outside the space with sample counts {counts:?}")]
    PointOutOfRange { scene: String, point: Vec<u32>, counts: Vec<u32> },
}

impl SceneError {
    /// Shorthand for [`SceneError::Invalid`].
    pub(crate) fn invalid(
        path: impl Into<PathBuf>,
        field: impl Into<String>,
        message: impl Into<String>,
    ) -> Self {
        SceneError::Invalid { path: path.into(), field: field.into(), message: message.into() }
    }

    /// Shorthand for [`SceneError::Unsupported`].
    pub(crate) fn unsupported(
        path: impl Into<PathBuf>,
        field: impl Into<String>,
        what: impl Into<String>,
    ) -> Self {
        SceneError::Unsupported { path: path.into(), field: field.into(), what: what.into() }
    }

    /// Shorthand for [`SceneError::UnknownName`].
    pub(crate) fn unknown<'a>(
        path: impl Into<PathBuf>,
        field: impl Into<String>,
        what: &'static str,
        name: &str,
        known: impl IntoIterator<Item = &'a str>,
    ) -> Self {
        let known: Vec<&str> = known.into_iter().collect();
        SceneError::UnknownName {
            path: path.into(),
            field: field.into(),
            what,
            name: name.to_owned(),
            known: known.join(", "),
        }
    }
}
