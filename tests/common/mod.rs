//! Helpers shared by the end-to-end tests (each test binary uses some of them).

#![allow(dead_code)]

pub mod auto;
pub mod hostile;

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// Copies samples/demo1 (scene.toml, glTF, buffers, textures) into `dir` with every
/// `(from, to)` edit applied to its scene.toml; returns the copy's scene.toml. Each `from` must
/// occur in demo1's scene.toml, so a change there fails here rather than quietly testing
/// another scene.
pub fn demo1_copy(dir: &Path, edits: &[(&str, &str)]) -> PathBuf {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("../samples/demo1");
    std::fs::create_dir_all(dir).expect("scene folder");
    for e in std::fs::read_dir(&src).expect("samples/demo1").filter_map(Result::ok) {
        if e.path().is_file() {
            std::fs::copy(e.path(), dir.join(e.file_name())).expect("copy demo1");
        }
    }
    let toml = dir.join("scene.toml");
    let mut text = std::fs::read_to_string(&toml).expect("scene.toml");
    for (from, to) in edits {
        assert!(text.contains(from), "demo1's scene.toml has no {from:?}: adapt the tests");
        text = text.replace(from, to);
    }
    std::fs::write(&toml, text).expect("write scene.toml");
    toml
}

/// Runs `program args` with the environment changes `env` (a value, or `None` to remove the
/// variable), killed after 120 s: a hang fails the test.
pub fn run(program: &str, args: &[&std::ffi::OsStr], env: &[(&str, Option<&str>)]) -> Output {
    let mut cmd = Command::new(program);
    cmd.args(args).stdout(Stdio::piped()).stderr(Stdio::piped());
    for (k, v) in env {
        match v {
            Some(v) => cmd.env(k, v),
            None => cmd.env_remove(k),
        };
    }
    let mut child = cmd.spawn().unwrap_or_else(|e| panic!("{program} runs: {e}"));
    let start = Instant::now();
    loop {
        if child.try_wait().expect("wait").is_some() {
            return child.wait_with_output().expect("output");
        }
        if start.elapsed() > Duration::from_secs(120) {
            let _ = child.kill();
            panic!("{program} {args:?} hung for 120 s");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

pub fn os<S: AsRef<std::ffi::OsStr> + ?Sized>(s: &S) -> &std::ffi::OsStr {
    s.as_ref()
}

/// Copies samples/NAME (without its cache) into `dir` with `edit` applied to its glTF JSON
/// (`NAME.gltf`); returns the copy's scene.toml.
#[allow(dead_code)]
pub fn sample_copy(
    name: &str,
    dir: &Path,
    edit: impl FnOnce(&mut serde_json::Value, &Path),
) -> PathBuf {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("../samples").join(name);
    std::fs::create_dir_all(dir).expect("scene folder");
    for e in std::fs::read_dir(&src).expect("the sample").filter_map(Result::ok) {
        if e.path().is_file() {
            std::fs::copy(e.path(), dir.join(e.file_name())).expect("copy the sample");
        }
    }
    let gltf = dir.join(format!("{name}.gltf"));
    let mut doc: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&gltf).expect("the glTF")).expect("glTF JSON");
    edit(&mut doc, dir);
    std::fs::write(&gltf, serde_json::to_vec(&doc).expect("JSON")).expect("write the glTF");
    dir.join("scene.toml")
}

/// Sets `key` of the glTF node named `node` (e.g. its `scale`).
#[allow(dead_code)]
pub fn set_node(doc: &mut serde_json::Value, node: &str, key: &str, value: serde_json::Value) {
    let n = doc["nodes"]
        .as_array_mut()
        .expect("nodes")
        .iter_mut()
        .find(|n| n["name"] == node)
        .unwrap_or_else(|| panic!("no node {node}"));
    n[key] = value;
}

/// A temporary folder for a fixture that every test of a binary shares. Such a fixture lives
/// in a `static`, which is never dropped, so its folder is never removed: it goes under the
/// target folder's tmp/ rather than the system's temporary folder, in a folder per test
/// binary that the binary's first fixture empties, so runs do not pile up.
pub fn fixture_tempdir() -> tempfile::TempDir {
    static CLEARED: std::sync::Once = std::sync::Once::new();
    let root = Path::new(env!("CARGO_TARGET_TMPDIR")).join(env!("CARGO_CRATE_NAME"));
    CLEARED.call_once(|| {
        let _ = std::fs::remove_dir_all(&root);
    });
    std::fs::create_dir_all(&root).expect("fixture folder");
    tempfile::tempdir_in(&root).expect("temp dir")
}

/// Runs pis-diff on `a` and `b` with `args`.
pub fn pis_diff(a: &Path, b: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_pis-diff"))
        .arg(a)
        .arg(b)
        .args(args)
        .output()
        .expect("pis-diff runs")
}

/// The entry named `name` of a JSON report's `objects` array.
pub fn report_object<'a>(report: &'a serde_json::Value, name: &str) -> &'a serde_json::Value {
    report["objects"]
        .as_array()
        .expect("objects")
        .iter()
        .find(|o| o["name"] == name)
        .unwrap_or_else(|| panic!("no object {name} in the report"))
}

/// A tool's `--json` report on standard output.
pub fn json_report(out: &Output) -> serde_json::Value {
    serde_json::from_slice(&out.stdout).unwrap_or_else(|e| {
        panic!(
            "JSON report ({e}): {}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        )
    })
}
