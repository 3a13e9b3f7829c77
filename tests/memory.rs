//! A pack that streams through its scratch file (`pis-pack --memory GB` below what the set
//! needs in memory) writes the file a pack in memory writes, byte for byte, whatever the
//! representation, codec or texture placement; it says so in its report, and leaves no
//! scratch file behind, whether it succeeds or fails. And a valid file whose textures are
//! as large as the spec's limits allow (`common::hostile`) is refused by every tool that
//! would have to hold them (exit 5, naming the texture and the sizes) before it allocates
//! them, and read by pis-inspect, which does not.

mod common;

use std::path::Path;
use std::process::Output;

use common::{demo1_copy, os, run};
use serde_json::Value;

const TRACE: &str = env!("CARGO_BIN_EXE_pis-trace");
const PACK: &str = env!("CARGO_BIN_EXE_pis-pack");
const PLAY: &str = env!("CARGO_BIN_EXE_pis-play");
const DIFF: &str = env!("CARGO_BIN_EXE_pis-diff");
const REENCODE: &str = env!("CARGO_BIN_EXE_pis-reencode");
const INSPECT: &str = env!("CARGO_BIN_EXE_pis-inspect");

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
    // Environment-map shells and hybrid rendering (demo1's vase, table top and glass cup),
    // and under `auto` the objects its screen solves again, each against its textures.
    held_and_streamed(dir.path(), set, "demo1-pem", &["--representation", "pem", "--ratio", "100"]);
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

/// Runs `program args`; returns its exit code and its stderr.
fn code_and_stderr(program: &str, args: &[&str]) -> (Option<i32>, String) {
    let args: Vec<&std::ffi::OsStr> = args.iter().map(|a| os(*a)).collect();
    let out = run(program, &args, &[]);
    (out.status.code(), String::from_utf8_lossy(&out.stderr).into_owned())
}

/// Asserts that a tool refused a file as not supported, with a message that names every
/// string of `names` and one of `limits` (the budget or adapter limit it went beyond),
/// instead of running out of memory (exit 101 or 134, a signal).
fn assert_refused(tool: &str, (code, err): (Option<i32>, String), names: &[&str], limits: &[&str]) {
    assert_eq!(code, Some(5), "{tool} refuses the file (exit 5): {err}");
    for n in names {
        assert!(err.contains(n), "{tool}'s message names {n:?}: {err}");
    }
    assert!(
        limits.iter().any(|l| err.contains(l)),
        "{tool}'s message names one of {limits:?}: {err}"
    );
    assert!(!err.contains("panicked"), "{tool} does not panic: {err}");
}

#[test]
fn the_largest_valid_file_is_refused_before_its_textures_are_allocated() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("largest.pis");
    let size = common::hostile::write_largest(&file);
    assert!(size < 600_000, "the file is small: {size} bytes");
    let f = file.to_str().unwrap();
    // The file is valid: pis-inspect reads its metadata in bounded memory.
    let (code, err) = code_and_stderr(INSPECT, &[f]);
    assert_eq!(code, Some(0), "pis-inspect reads the file: {err}");
    // 16384² RGB with its MIP chain, f32: 4 GiB per texture, 64 GiB in all.
    let gib =
        format!("{:.1} GiB", common::hostile::huge_image_bytes() as f64 / (1u64 << 30) as f64);
    assert_eq!(gib, "4.0 GiB");
    let names = ["16384×16384", "layer 0", &gib];
    // Beyond lavapipe's largest buffer (2 GiB) as well as the cache budget (512 MiB).
    let play = code_and_stderr(PLAY, &[f, "--headless", "--frames", "1"]);
    assert_refused("pis-play", play, &names, &["--cache-mb", "the adapter's largest buffer"]);
    let diff = code_and_stderr(DIFF, &[f, f]);
    assert_refused("pis-diff", diff, &names, &["16.0 GiB at once", "--memory"]);
    let diff = code_and_stderr(DIFF, &[f, f, "--memory", "15"]);
    assert_refused("pis-diff", diff, &names, &["budget, 15.0 GiB"]);
    let out = dir.path().join("out.pis");
    let o = out.to_str().unwrap();
    let reencode = code_and_stderr(REENCODE, &[f, "-o", o]);
    assert_refused("pis-reencode", reencode, &names, &["80.0 GiB at once", "--memory"]);
    assert!(!out.exists(), "no output on refusal");
}

#[test]
fn the_player_refuses_a_frame_beyond_its_cache_budget() {
    let dir = tempfile::tempdir().unwrap();
    // Two 8192² textures with their MIP chains: 1 GiB each, within lavapipe's buffers.
    let file = dir.path().join("two.pis");
    common::hostile::write_with(&file, 8192, 2);
    let f = file.to_str().unwrap();
    let names = ["8192×8192", "layer 0", "1.0 GiB"];
    let play = code_and_stderr(PLAY, &[f, "--headless", "--frames", "1"]);
    assert_refused(
        "pis-play",
        play,
        &names,
        &["cache budget for decoded level images, 512.0 MiB (pis-play --cache-mb)"],
    );
    // In a window (under Xvfb, where it is installed; CI has it) the player opens the same way.
    let xvfb = std::process::Command::new("xvfb-run").arg("--help").output().is_ok();
    if xvfb || std::env::var_os("CI").is_some_and(|v| !v.is_empty()) {
        // The X authority file the test's own, so xvfb-run removes no folder of its own
        // after pis-play exits (a failure there is its own exit 5).
        let auth = dir.path().join("Xauthority");
        std::fs::File::create(&auth).unwrap();
        let auth = auth.to_str().unwrap();
        let window = code_and_stderr("xvfb-run", &["-a", "-f", auth, PLAY, f, "--frames", "1"]);
        assert_refused("pis-play (window)", window, &names, &["(pis-play --cache-mb)"]);
    } else {
        eprintln!("xvfb-run is not installed: the window's refusal is not checked");
    }
    // Each texture fits 1.5 GiB, the frame's two do not.
    let play = code_and_stderr(PLAY, &[f, "--headless", "--frames", "1", "--cache-mb", "1536"]);
    assert_refused(
        "pis-play",
        play,
        &["one frame decodes 2.0 GiB", "3 layers", "the largest, object 'quad' layer 0"],
        &["1.5 GiB (pis-play --cache-mb)"],
    );
}

/// Writes the largest valid file where `PIS_LARGEST_FILE` says (for measuring the tools on
/// it: docs/benchmarks/scale.md); `PIS_LARGEST_SIDE` and `PIS_LARGEST_LAYERS` write a
/// smaller one (`common::hostile::container`).
#[test]
#[ignore]
fn write_the_largest_valid_file() {
    let path = std::env::var("PIS_LARGEST_FILE").expect("PIS_LARGEST_FILE=PATH");
    let var = |name: &str, default: usize| {
        std::env::var(name).map_or(default, |v| v.parse().expect("a number"))
    };
    let side = var("PIS_LARGEST_SIDE", common::hostile::SIDE as usize) as u32;
    let layers = var("PIS_LARGEST_LAYERS", common::hostile::HUGE_LAYERS);
    let size = common::hostile::write_with(Path::new(&path), side, layers);
    eprintln!("{path}: {size} bytes");
}
