//! A pack that streams through its scratch file (`pis-pack --memory GB` below what the set
//! needs in memory) writes the file a pack in memory writes, byte for byte, whatever the
//! representation, codec or texture placement; it says so in its report, and leaves no
//! scratch file behind, whether it succeeds or fails.

mod common;

use std::path::Path;
use std::process::Output;

use common::{demo1_copy, os, run};
use serde_json::Value;

const TRACE: &str = env!("CARGO_BIN_EXE_pis-trace");
const PACK: &str = env!("CARGO_BIN_EXE_pis-pack");

fn ok(program: &str, args: &[&str]) -> Output {
    let args: Vec<&std::ffi::OsStr> = args.iter().map(|a| os(*a)).collect();
    let out = run(program, &args, &[]);
    assert!(out.status.success(), "{program} {args:?}: {}", String::from_utf8_lossy(&out.stderr));
    out
}

fn report(out: &Output) -> Value {
    serde_json::from_slice(&out.stdout)
        .unwrap_or_else(|e| panic!("JSON report: {e}: {}", String::from_utf8_lossy(&out.stdout)))
}

/// Files in `dir` whose names say they are scratch files.
fn scratch_files(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .filter_map(Result::ok)
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains(".scratch"))
        .collect()
}

/// Packs `set` into `dir/NAME-held.pis` and, streamed under a budget far below what it
/// needs, into `dir/NAME-streamed.pis`, with `flags`; checks the two files are the same.
fn held_and_streamed(dir: &Path, set: &str, name: &str, flags: &[&str]) {
    let held = dir.join(format!("{name}-held.pis"));
    let streamed = dir.join(format!("{name}-streamed.pis"));
    let mut args = vec![set, "-o", held.to_str().unwrap(), "--json"];
    args.extend(flags);
    let r = report(&ok(PACK, &args));
    assert_eq!(r["memory"]["streamed"], false, "{name}: a small set packs in memory");
    args[2] = streamed.to_str().unwrap();
    args.extend(["--memory", "0.0001"]);
    let s = report(&ok(PACK, &args));
    assert_eq!(s["memory"]["streamed"], true, "{name}: {}", s["memory"]);
    assert_eq!(s["memory"]["budget_asked"], true);
    assert!(
        s["memory"]["scratch_bytes"].as_u64().unwrap() > 0,
        "{name}: the images went to the scratch file"
    );
    assert!(s["memory"]["why"].as_str().unwrap().starts_with("streamed"));
    let (a, b) = (std::fs::read(&held).unwrap(), std::fs::read(&streamed).unwrap());
    assert!(
        a == b,
        "{name} {flags:?}: the streamed pack wrote other bytes ({} against {})",
        b.len(),
        a.len()
    );
    assert_eq!(r["psnr_db"], s["psnr_db"]);
    assert_eq!(scratch_files(dir), Vec::<String>::new(), "{name}: the scratch file is removed");
}

#[test]
fn a_streamed_pack_writes_the_bytes_of_a_pack_in_memory() {
    let dir = tempfile::tempdir().unwrap();
    // demo1 at 64×48 over 4 × 4 points, blocks of 2 samples: several texture placements
    // per object, each with its own render matrices.
    let scene = demo1_copy(
        &dir.path().join("demo1"),
        &[("resolution = [160, 120]", "resolution = [64, 48]"), ("spp = 4", "spp = 1")],
    );
    let set = dir.path().join("demo1-set");
    ok(TRACE, &[scene.to_str().unwrap(), "-o", set.to_str().unwrap()]);
    let set = set.to_str().unwrap();
    held_and_streamed(dir.path(), set, "demo1", &["--block", "2"]);
    held_and_streamed(
        dir.path(),
        set,
        "demo1-lossless",
        &["--block", "2", "--codec", "lossless", "--keep-master"],
    );
    // Environment-map shells and hybrid rendering under `auto` (demo1's vase and glass
    // cup), each against its surface textures.
    held_and_streamed(
        dir.path(),
        set,
        "demo1-auto",
        &["--representation", "auto", "--ratio", "100"],
    );
}

#[test]
fn a_streamed_pack_that_fails_leaves_no_file() {
    let dir = tempfile::tempdir().unwrap();
    let scene = demo1_copy(
        &dir.path().join("demo1"),
        &[("resolution = [160, 120]", "resolution = [32, 24]"), ("spp = 4", "spp = 1")],
    );
    let set = dir.path().join("set");
    ok(TRACE, &[scene.to_str().unwrap(), "-o", set.to_str().unwrap()]);
    let out = dir.path().join("out.pis");
    // A PSNR no coding reaches fails at the allocation, after the set was streamed.
    let args: Vec<&std::ffi::OsStr> =
        [set.to_str().unwrap(), "-o", out.to_str().unwrap(), "--psnr", "200", "--memory", "0.0001"]
            .into_iter()
            .map(os)
            .collect();
    let failed = run(PACK, &args, &[]);
    assert!(!failed.status.success());
    let err = String::from_utf8_lossy(&failed.stderr);
    assert!(err.contains("streamed"), "the progress says the set is streamed: {err}");
    assert!(!out.exists(), "no output on failure");
    assert_eq!(scratch_files(dir.path()), Vec::<String>::new(), "no scratch file on failure");
    // A budget that is not a size is refused before any work.
    let bad: Vec<&std::ffi::OsStr> =
        [set.to_str().unwrap(), "-o", out.to_str().unwrap(), "--memory", "0"]
            .into_iter()
            .map(os)
            .collect();
    let refused = run(PACK, &bad, &[]);
    assert_eq!(
        refused.status.code(),
        Some(1),
        "a usage error: {}",
        String::from_utf8_lossy(&refused.stderr)
    );
    assert!(String::from_utf8_lossy(&refused.stderr).contains("memory budget"));
}
