use std::path::PathBuf;

use crate::Issue;

/// Why a container could not be read or written.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The file system failed.
    #[error("{path}: {source}")]
    Io { path: PathBuf, source: std::io::Error },
    /// The file breaks a rule of the spec.
    #[error("{0}")]
    Invalid(Issue),
    /// The file is valid but uses something this build cannot do (a reserved codec).
    #[error("not supported: {0}")]
    NotSupported(String),
    /// A caller asked for something the file does not hold (object, layer or sample index).
    #[error("{0}")]
    Request(String),
    /// The model handed to the writer is not a valid container.
    #[error("cannot write an invalid container: {0}")]
    InvalidModel(Issue),
}

impl Error {
    /// The validation rule at fault, if any.
    pub fn issue(&self) -> Option<&Issue> {
        match self {
            Error::Invalid(i) | Error::InvalidModel(i) => Some(i),
            _ => None,
        }
    }
}

impl From<Issue> for Error {
    fn from(i: Issue) -> Self {
        Error::Invalid(i)
    }
}
