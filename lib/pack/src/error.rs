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
        Failure { exit, error: error.into() }
    }
}

/// The exit code of a container error.
pub fn format_exit(e: &pis_format::Error) -> Exit {
    match e {
        pis_format::Error::Io { .. } => Exit::Io,
        pis_format::Error::Invalid(_) => Exit::Invalid,
        pis_format::Error::NotSupported(_) => Exit::NotSupported,
        pis_format::Error::Request(_) => Exit::Usage,
        pis_format::Error::InvalidModel(_) => Exit::Runtime,
    }
}

impl From<pis_format::Error> for Failure {
    fn from(e: pis_format::Error) -> Self {
        Failure::new(format_exit(&e), e)
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

/// The exit code of a ray-traced set's or a trace's error, the same in every tool: a file
/// that cannot be read (a missing set.json or glTF) is an I/O error, a damaged one (a
/// truncated EXR, a malformed set.json or scene) an invalid file, work larger than the
/// machine's memory not supported.
pub fn trace_exit(e: &pis_trace::TraceError) -> Exit {
    use pis_trace::TraceError;
    match e {
        TraceError::Io { .. } => Exit::Io,
        TraceError::Exr { .. } | TraceError::InvalidSet { .. } => Exit::Invalid,
        TraceError::Scene(s) => scene_exit(s),
        TraceError::InvalidInput(_) | TraceError::Denoise(_) => Exit::Runtime,
        TraceError::Memory(_) => Exit::NotSupported,
    }
}

/// The exit code of a scene's error: unreadable files are I/O errors, a parameter point
/// outside the space a runtime error, anything else an invalid file.
pub fn scene_exit(e: &pis_scene::SceneError) -> Exit {
    use pis_scene::SceneError;
    match e {
        SceneError::Io { .. } => Exit::Io,
        SceneError::PointOutOfRange { .. } => Exit::Runtime,
        _ => Exit::Invalid,
    }
}

/// The exit code of an error by the first cause that says which (a trace, scene, container
/// or I/O error); `otherwise` when none does.
pub fn exit_of(e: &anyhow::Error, otherwise: Exit) -> Exit {
    for cause in e.chain() {
        if let Some(t) = cause.downcast_ref::<pis_trace::TraceError>() {
            return trace_exit(t);
        }
        if let Some(s) = cause.downcast_ref::<pis_scene::SceneError>() {
            return scene_exit(s);
        }
        if let Some(f) = cause.downcast_ref::<pis_format::Error>() {
            return format_exit(f);
        }
        if cause.downcast_ref::<std::io::Error>().is_some() {
            return Exit::Io;
        }
    }
    otherwise
}

impl From<pis_trace::TraceError> for Failure {
    fn from(e: pis_trace::TraceError) -> Self {
        Failure::new(trace_exit(&e), e)
    }
}

impl From<pis_scene::SceneError> for Failure {
    fn from(e: pis_scene::SceneError) -> Self {
        Failure::new(scene_exit(&e), e)
    }
}
