//! A lens object's depth shell (`pis-pack --lens-shell depth`, SPEC.md 8.5): one shell about
//! the glass teapot's centroid whose radius in every direction is the distance to the other
//! objects, so that the player marches each vertex's exit ray to the surface it meets and
//! looks the radiance up there, instead of the layered shells fitted to the ray records' hit
//! distances.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use common::{json_report, os, report_object};

/// Runs `tool args`, which must succeed; its `--json` report.
fn run_json(tool: &str, args: &[&std::ffi::OsStr]) -> serde_json::Value {
    let o = Command::new(tool).args(args).output().expect("the tool runs");
    assert!(o.status.success(), "{tool}: {}", String::from_utf8_lossy(&o.stderr));
    json_report(&o)
}

/// The glass sample's scene.toml (its files copied into `dir`) and its set traced there.
fn glass_set(dir: &Path) -> (PathBuf, PathBuf) {
    let sample = Path::new(env!("CARGO_MANIFEST_DIR")).join("../samples/glass");
    for e in std::fs::read_dir(&sample).expect("samples/glass").filter_map(Result::ok) {
        if e.path().is_file() {
            std::fs::copy(e.path(), dir.join(e.file_name())).expect("copy");
        }
    }
    let (scene, set) = (dir.join("scene.toml"), dir.join("SET"));
    run_json(
        env!("CARGO_BIN_EXE_pis-trace"),
        &[scene.as_os_str(), os("-o"), set.as_os_str(), os("--json")],
    );
    (scene, set)
}

/// The glass teapot's lens layers (`env_shell`) in `file`, as pis-inspect describes them.
fn lens_layers(file: &Path) -> Vec<serde_json::Value> {
    let j = run_json(env!("CARGO_BIN_EXE_pis-inspect"), &[file.as_os_str(), os("--json")]);
    report_object(&j, "GlassTeapot")["layers"]
        .as_array()
        .expect("layers")
        .iter()
        .filter(|l| l["kind"] == "env_shell")
        .cloned()
        .collect()
}

/// The glass teapot's PSNR as the player draws `file` at the set's samples, one sample per
/// pixel as pis-pack predicts; the player must stay within 0.3 dB of the prediction.
fn played(file: &Path, set: &Path) -> f64 {
    let args = [file.as_os_str(), set.as_os_str()];
    let flags = ["--msaa", "1", "--max-psnr-drop", "0.3", "--json"];
    let args: Vec<&std::ffi::OsStr> = args.into_iter().chain(flags.iter().map(os)).collect();
    let d = run_json(env!("CARGO_BIN_EXE_pis-diff"), &args);
    report_object(&d, "GlassTeapot")["psnr_db"].as_f64().expect("the teapot's PSNR")
}

/// Layered shells, one depth shell solved over the views and one solved per sample
/// (lossless, so that the shells are compared, not their coding). The depth shell is the
/// teapot's one lens layer, its map depending on no dimension (one map for the four views)
/// or, per sample, on the view; both play as pis-pack predicted, and the shared depth shell
/// draws the teapot nearer the traced set at its samples than the layered shells do
/// (20.97 against 20.58 dB here, per sample 21.32).
#[test]
fn a_lens_objects_depth_shell_is_marched_and_plays_as_predicted() {
    let dir = tempfile::tempdir().expect("temp dir");
    let (scene, set) = glass_set(dir.path());
    let pack = |lens_shell: &str| {
        let out = dir.path().join(format!("{lens_shell}.pis"));
        let flags = ["--representation", "pem", "--codec", "lossless", "--lens-shell", lens_shell];
        let mut args = vec![set.as_os_str(), os("--scene"), scene.as_os_str(), os("-o")];
        args.push(out.as_os_str());
        args.extend(flags.iter().map(os));
        args.push(os("--json"));
        let r = run_json(env!("CARGO_BIN_EXE_pis-pack"), &args);
        let why = report_object(&r, "GlassTeapot")["why"].as_str().expect("why").to_string();
        (out, why)
    };
    let (layered, layered_why) = pack("layered");
    let (shared, shared_why) = pack("depth");
    let (each, each_why) = pack("depth-per-sample");
    assert!(layered_why.contains("shell(s) from the ray records' hit distances"), "{layered_why}");
    assert!(shared_why.contains("a depth shell about its centroid, one map over the views"));
    assert!(each_why.contains("a depth shell about its centroid, a map per sample"), "{each_why}");
    for (file, depends_on) in
        [(&shared, serde_json::json!([])), (&each, serde_json::json!(["view"]))]
    {
        let layers = lens_layers(file);
        assert_eq!(layers.len(), 1, "{layers:?}");
        assert_eq!(layers[0]["shell"], "depth", "{}", layers[0]);
        assert_eq!(layers[0]["depends_on"], depends_on, "{}", layers[0]);
    }
    let (l, s, e) = (played(&layered, &set), played(&shared, &set), played(&each, &set));
    eprintln!("the glass teapot played at the samples: layered {l:.2}, depth {s:.2}, per sample {e:.2} dB");
    assert!(s > l && e > l, "layered {l}, depth {s}, per sample {e}");
}
