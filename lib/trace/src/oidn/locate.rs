//! Finding and loading the OIDN library.
//!
//! Search order:
//! 1. the environment variable [`ENV_LIBRARY`]: the library file, or a directory holding
//!    [`LIBRARY_NAME`]. When it is set, it is the only candidate: if it is unusable, that is
//!    the error.
//! 2. [`LIBRARY_NAME`] through the system loader's own search (`LD_LIBRARY_PATH`, the
//!    ldconfig cache, the default directories).
//! 3. the Python package `pyoidn`, whose wheel ships the library (and the core, CPU device
//!    and TBB libraries beside it) in `pyoidn/oidn/lib`. Its directory is found by asking
//!    `python3` for the package's import location, without importing it.

use std::ffi::{OsStr, OsString};
use std::fmt;
use std::path::{Path, PathBuf};
use std::process::Command;

use libloading::Library;

use super::ffi::Api;

/// The environment variable that names the OIDN library to load (a file or a directory).
pub const ENV_LIBRARY: &str = "PIS_OIDN_LIBRARY";

/// The file name of the OIDN 2.x library.
#[cfg(target_os = "windows")]
pub const LIBRARY_NAME: &str = "OpenImageDenoise.dll";
/// The file name of the OIDN 2.x library.
#[cfg(target_os = "macos")]
pub const LIBRARY_NAME: &str = "libOpenImageDenoise.2.dylib";
/// The file name of the OIDN 2.x library.
#[cfg(not(any(target_os = "windows", target_os = "macos")))]
pub const LIBRARY_NAME: &str = "libOpenImageDenoise.so.2";

/// The folder of the `pyoidn` package that holds the library.
#[cfg(target_os = "windows")]
const PYOIDN_LIBRARY_DIR: &str = "oidn/bin";
/// The folder of the `pyoidn` package that holds the library.
#[cfg(not(target_os = "windows"))]
const PYOIDN_LIBRARY_DIR: &str = "oidn/lib";

/// Prints the `pyoidn` package's directory, or an empty line when it is not installed.
const PYOIDN_QUERY: &str = "import importlib.util as u; s=u.find_spec('pyoidn'); \
                            print(s.submodule_search_locations[0] if s else '')";

/// One candidate that was tried, and what became of it.
#[derive(Debug, Clone)]
struct Attempt {
    candidate: String,
    outcome: String,
}

/// Why OIDN cannot be used: every candidate tried and what went wrong with it.
#[derive(Debug, Clone)]
pub struct OidnUnavailable {
    tried: Vec<Attempt>,
    /// A failure after a library was loaded (device creation, version).
    problem: Option<String>,
}

impl OidnUnavailable {
    /// A failure with the library at `library`, after it was found and loaded.
    pub(crate) fn after_load(library: &Path, problem: String) -> OidnUnavailable {
        OidnUnavailable {
            tried: Vec::new(),
            problem: Some(format!("{}: {problem}", library.display())),
        }
    }
}

impl fmt::Display for OidnUnavailable {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Intel Open Image Denoise 2.x (OIDN) is not available")?;
        match &self.problem {
            Some(problem) => write!(f, ": {problem}")?,
            None => write!(f, "; tried:")?,
        }
        for attempt in &self.tried {
            write!(f, "\n  {}: {}", attempt.candidate, attempt.outcome)?;
        }
        write!(
            f,
            "\nInstall it with `pip install pyoidn` (ships OIDN 2.5.1) or a system OIDN 2.x \
             package providing {LIBRARY_NAME}, or set {ENV_LIBRARY} to the library file or the \
             directory holding it."
        )
    }
}

impl std::error::Error for OidnUnavailable {}

/// A loaded OIDN library with its entry points resolved.
pub(crate) struct Located {
    pub api: Api,
    /// The file that was loaded.
    pub path: PathBuf,
}

/// Finds and loads OIDN, reading the override from [`ENV_LIBRARY`].
pub(crate) fn locate() -> Result<Located, OidnUnavailable> {
    let override_path = std::env::var_os(ENV_LIBRARY).filter(|value| !value.is_empty());
    locate_with(override_path.as_deref())
}

/// Finds and loads OIDN; `override_path` takes the place of the [`ENV_LIBRARY`] value.
pub(crate) fn locate_with(override_path: Option<&OsStr>) -> Result<Located, OidnUnavailable> {
    let mut tried = Vec::new();
    if let Some(value) = override_path {
        let candidate = format!("{ENV_LIBRARY}={}", Path::new(value).display());
        return match override_file(value) {
            Ok(file) => load_file(&file).map_err(|outcome| {
                tried.push(Attempt { candidate, outcome });
                OidnUnavailable { tried, problem: None }
            }),
            Err(outcome) => {
                tried.push(Attempt { candidate, outcome });
                Err(OidnUnavailable { tried, problem: None })
            }
        };
    }

    match load_by_system_search() {
        Ok(located) => return Ok(located),
        Err(outcome) => tried.push(Attempt {
            candidate: format!("{LIBRARY_NAME} through the system loader's search"),
            outcome,
        }),
    }

    let candidate = "the Python package pyoidn".to_string();
    match pyoidn_dir() {
        Ok(dir) => {
            let file = dir.join(PYOIDN_LIBRARY_DIR).join(LIBRARY_NAME);
            match load_file(&file) {
                Ok(located) => return Ok(located),
                Err(outcome) => tried.push(Attempt { candidate, outcome }),
            }
        }
        Err(outcome) => tried.push(Attempt { candidate, outcome }),
    }
    Err(OidnUnavailable { tried, problem: None })
}

/// The library file named by an override: the path itself, or [`LIBRARY_NAME`] inside it
/// when it is a directory.
fn override_file(value: &OsStr) -> Result<PathBuf, String> {
    let path = Path::new(value);
    let path = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
    match std::fs::metadata(&path) {
        Ok(meta) if meta.is_dir() => {
            let file = path.join(LIBRARY_NAME);
            if file.exists() {
                Ok(file)
            } else {
                Err(format!("{} does not exist", file.display()))
            }
        }
        Ok(_) => Ok(path),
        Err(error) => Err(format!("{}: {error}", path.display())),
    }
}

/// Loads the library at `file` (a path, not searched for) and resolves its entry points.
fn load_file(file: &Path) -> Result<Located, String> {
    if !file.exists() {
        return Err(format!("{} does not exist", file.display()));
    }
    let api = open(file.as_os_str()).map_err(|error| format!("{}: {error}", file.display()))?;
    Ok(Located { api, path: file.to_path_buf() })
}

/// Loads [`LIBRARY_NAME`] wherever the system loader finds it.
fn load_by_system_search() -> Result<Located, String> {
    let api = open(OsStr::new(LIBRARY_NAME))?;
    let path = loaded_file(api.new_device as usize).unwrap_or_else(|| PathBuf::from(LIBRARY_NAME));
    Ok(Located { api, path })
}

/// Loads a library by name or path and resolves the OIDN entry points in it.
fn open(name: &OsStr) -> Result<Api, String> {
    // SAFETY: loading runs the library's initialisers; OIDN's only set up its own state.
    let library = unsafe { Library::new(name) }.map_err(|error| error.to_string())?;
    // SAFETY: a library that provides these OIDN 2.x names follows OIDN 2.x's signatures.
    unsafe { Api::resolve(library) }
}

/// The file mapped at `address` in this process, read from `/proc/self/maps`.
fn loaded_file(address: usize) -> Option<PathBuf> {
    let maps = std::fs::read_to_string("/proc/self/maps").ok()?;
    maps.lines().find_map(|line| {
        // address perms offset dev inode path (the path may hold spaces)
        let mut fields = line.splitn(6, ' ');
        let (start, end) = fields.next()?.split_once('-')?;
        let start = usize::from_str_radix(start, 16).ok()?;
        let end = usize::from_str_radix(end, 16).ok()?;
        if !(start..end).contains(&address) {
            return None;
        }
        let path = fields.nth(4)?.trim_start();
        path.starts_with('/').then(|| PathBuf::from(path))
    })
}

/// The directory of the `pyoidn` package, as `python3` finds it.
fn pyoidn_dir() -> Result<PathBuf, String> {
    let output = Command::new("python3")
        .args(["-c", PYOIDN_QUERY])
        .output()
        .map_err(|error| format!("could not run python3: {error}"))?;
    if !output.status.success() {
        return Err(format!(
            "python3 failed looking for it ({}): {}",
            output.status,
            String::from_utf8_lossy(&output.stderr).trim()
        ));
    }
    let dir = trim_line(output.stdout);
    if dir.is_empty() {
        return Err("not installed for python3".to_string());
    }
    Ok(PathBuf::from(dir))
}

/// The output of a command without its trailing line break.
fn trim_line(mut bytes: Vec<u8>) -> OsString {
    while matches!(bytes.last(), Some(b'\n' | b'\r')) {
        bytes.pop();
    }
    #[cfg(unix)]
    {
        use std::os::unix::ffi::OsStringExt;
        OsString::from_vec(bytes)
    }
    #[cfg(not(unix))]
    {
        OsString::from(String::from_utf8_lossy(&bytes).into_owned())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn override_to_a_missing_path_is_the_error_and_says_how_to_install() {
        let missing = std::env::temp_dir().join("pis-oidn-missing/none/libOpenImageDenoise.so.2");
        let error = match locate_with(Some(missing.as_os_str())) {
            Ok(_) => panic!("a missing override path must not load"),
            Err(error) => error,
        };
        let text = error.to_string();
        assert!(text.contains(&missing.display().to_string()), "{text}");
        assert!(text.contains(ENV_LIBRARY), "{text}");
        assert!(text.contains("pip install pyoidn"), "{text}");
        // The override is the only candidate: no fall-through to the other searches.
        assert_eq!(error.tried.len(), 1, "{text}");
    }

    #[test]
    fn override_to_a_directory_without_the_library_names_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let error = match locate_with(Some(dir.path().as_os_str())) {
            Ok(_) => panic!("an empty directory must not load"),
            Err(error) => error,
        };
        let text = error.to_string();
        assert!(text.contains(&dir.path().join(LIBRARY_NAME).display().to_string()), "{text}");
        assert_eq!(error.tried.len(), 1, "{text}");
    }

    #[test]
    fn override_to_a_file_that_is_not_a_library_fails_to_load() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join(LIBRARY_NAME);
        std::fs::write(&file, b"not a shared library").unwrap();
        let error = match locate_with(Some(dir.path().as_os_str())) {
            Ok(_) => panic!("a file that is not a library must not load"),
            Err(error) => error,
        };
        let text = error.to_string();
        assert!(text.contains(&file.display().to_string()), "{text}");
        assert!(text.contains("pip install pyoidn"), "{text}");
    }

    #[test]
    fn trim_line_drops_only_the_line_break() {
        assert_eq!(trim_line(b"/a b/c\r\n".to_vec()), OsString::from("/a b/c"));
        assert_eq!(trim_line(b"\n".to_vec()), OsString::new());
    }
}
