//! One skeleton for every tool: documented exit codes, errors printed once as
//! `tool: message`, machine output on stdout, everything else on stderr.

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

/// The help text's table of exit codes.
pub const EXIT_CODES_HELP: &str = "Exit codes: 0 ok, 1 bad arguments, 2 I/O error, 3 invalid file, 4 runtime error, 5 not supported";

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

/// Parses arguments with clap, mapping usage errors to exit code 1 (help and version to 0).
pub fn parse<T: clap::Parser>() -> Result<T, ExitCode> {
    T::try_parse().map_err(|e| {
        let _ = e.print();
        if e.use_stderr() {
            Exit::Usage.into()
        } else {
            Exit::Ok.into()
        }
    })
}

/// Runs a tool's body and turns its result into an exit code, printing a failure once.
pub fn finish(tool: &str, result: Result<Exit, Failure>) -> ExitCode {
    match result {
        Ok(code) => code.into(),
        Err(f) => {
            eprintln!("{tool}: {:#}", f.error);
            f.exit.into()
        }
    }
}
