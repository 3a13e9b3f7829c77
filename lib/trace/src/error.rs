//! The errors of pis-trace.

use std::path::PathBuf;

/// Everything that can go wrong while tracing or reading and writing a ray-traced set.
#[derive(Debug, thiserror::Error)]
pub enum TraceError {
    /// Reading or writing a file failed.
    #[error("{path}: {error}")]
    Io { path: PathBuf, error: std::io::Error },
    /// An EXR file could not be written or read.
    #[error("{path}: OpenEXR: {message}")]
    Exr { path: PathBuf, message: String },
    /// A ray-traced set on disk is malformed.
    #[error("{path}: {message}")]
    InvalidSet { path: PathBuf, message: String },
    /// The scene could not be loaded or evaluated at a parameter point.
    #[error(transparent)]
    Scene(#[from] pis_scene::SceneError),
    /// The scene or the settings cannot be rendered.
    #[error("invalid render input: {0}")]
    InvalidInput(String),
    /// The work would need more memory than the machine has available.
    #[error("{0}")]
    Memory(String),
    /// The denoiser failed on an image.
    #[error("denoising: {0}")]
    Denoise(String),
}

impl TraceError {
    /// An I/O error on `path`.
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> TraceError {
        TraceError::Io { path: path.into(), error: source }
    }
}
