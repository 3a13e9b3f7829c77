//! The crate's error type.

use thiserror::Error;

/// What can go wrong while inferring textures.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum CompileError {
    /// An input value is NaN or infinite.
    #[error("{what} holds a non-finite value ({value}) at index {index}")]
    NonFinite {
        /// Which input: "b", "A", "initial guess", ...
        what: String,
        index: usize,
        value: f32,
    },
    /// Two inputs disagree on a size.
    #[error("{what}: expected {expected}, found {found}")]
    Size { what: String, expected: usize, found: usize },
    /// A render matrix is malformed (row pointers, column indices).
    #[error("render matrix: {0}")]
    Matrix(String),
    /// A setting is out of range.
    #[error("invalid setting: {0}")]
    Setting(String),
    /// A view could not be read from where a [`crate::ViewSource`] keeps it.
    #[error("reading a view: {0}")]
    Source(String),
    /// Geometry that texture-coordinate optimization cannot work with.
    #[error("object {object}: {message}")]
    Geometry { object: String, message: String },
}

/// Fails with [`CompileError::NonFinite`] at the first NaN or infinity in `v`.
pub fn check_finite(what: &str, v: &[f32]) -> Result<(), CompileError> {
    match v.iter().position(|x| !x.is_finite()) {
        None => Ok(()),
        Some(index) => {
            Err(CompileError::NonFinite { what: what.to_string(), index, value: v[index] })
        }
    }
}
