//! The toolchain's outcomes: what every tool's work ends in (an exit code) and the error
//! that carries the code it maps to. Library calls return [`Failure`]; a binary prints it
//! and exits with its code.

use std::process::ExitCode;

/// The toolchain's exit codes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Exit {
    /// Success.
    Ok = 0,
    /// Bad arguments.
    Usage = 1,
    /// A file could not be read or written.
    Io = 2,
    /// An input file is invalid.
    Invalid = 3,
    /// Something failed while working.
    Runtime = 4,
    /// The input uses something this build does not support.
    NotSupported = 5,
    /// Two inputs differ, or a quality gate failed (pis-diff).
    Different = 7,
}

impl From<Exit> for ExitCode {
    fn from(e: Exit) -> Self {
        ExitCode::from(e as u8)
    }
}

/// An error with the exit code it maps to.
#[derive(Debug)]
pub struct Failure {
    pub exit: Exit,
    pub error: anyhow::Error,
}

impl Failure {
    pub fn new(exit: Exit, error: impl Into<anyhow::Error>) -> Self {
        Failure {
            exit,
            error: error.into(),
        }
    }
}

impl From<pis_format::Error> for Failure {
    fn from(e: pis_format::Error) -> Self {
        let exit = match &e {
            pis_format::Error::Io { .. } => Exit::Io,
            pis_format::Error::Invalid(_) => Exit::Invalid,
            pis_format::Error::NotSupported(_) => Exit::NotSupported,
            pis_format::Error::Request(_) => Exit::Usage,
            pis_format::Error::InvalidModel(_) => Exit::Runtime,
        };
        Failure::new(exit, e)
    }
}

impl std::fmt::Display for Failure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{:#}", self.error)
    }
}

impl std::error::Error for Failure {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        self.error.source()
    }
}
