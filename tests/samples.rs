//! Every bundled sample, traced at its own (CI) size and packed with pis-pack's defaults:
//! the pack makes a valid file at the default ratio, gives every object storage, and
//! predicts at least what it predicted when measured (the samples once failed here with
//! "the smallest encodings need N bytes, over the budget of M").

use std::path::{Path, PathBuf};
use std::process::Command;

fn samples() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../samples")
}

/// Copies a sample's folder (without its cache) into `dir`.
fn copy_sample(name: &str, dir: &Path) -> PathBuf {
    let from = samples().join(name);
    let to = dir.join(name);
    std::fs::create_dir_all(&to).unwrap();
    for e in std::fs::read_dir(&from).unwrap() {
        let e = e.unwrap();
        if e.file_type().unwrap().is_file() {
            std::fs::copy(e.path(), to.join(e.file_name())).unwrap();
        }
    }
    to.join("scene.toml")
}

/// Packs `name` at its scene.toml's size with the defaults; returns the JSON report.
fn pack_default(name: &str) -> serde_json::Value {
    let dir = tempfile::tempdir().expect("temp dir");
    let scene = copy_sample(name, dir.path());
    let file = dir.path().join(format!("{name}.pis"));
    let out = Command::new(env!("CARGO_BIN_EXE_pis-pack"))
        .arg(&scene)
        .arg("-o")
        .arg(&file)
        .arg("--json")
        .output()
        .expect("pis-pack runs");
    assert!(out.status.success(), "{name}: {}", String::from_utf8_lossy(&out.stderr));
    let v = Command::new(env!("CARGO_BIN_EXE_pis-inspect"))
        .arg("--validate")
        .arg(&file)
        .output()
        .expect("pis-inspect runs");
    assert_eq!(v.status.code(), Some(0), "{name}: {}", String::from_utf8_lossy(&v.stdout));
    serde_json::from_slice(&out.stdout).expect("JSON report")
}

/// The default ratio (384:1) is met, every object gets bytes, and the predicted PSNR is at
/// least `floor_db` (measured at the sample's CI size, 4 spp, less 1 dB).
fn check(name: &str, floor_db: f64) {
    let r = pack_default(name);
    let ratio = r["ratio_without_geometry"].as_f64().expect("ratio_without_geometry");
    assert!((ratio / 384.0 - 1.0).abs() < 0.05, "{name}: ratio {ratio}, default 384");
    let psnr = r["psnr_db"].as_f64().expect("psnr_db");
    assert!(psnr >= floor_db, "{name}: predicted {psnr:.2} dB, below {floor_db} dB");
    for o in r["objects"].as_array().expect("objects") {
        assert!(
            o["bytes"].as_u64().expect("bytes") > 0,
            "{name}: object {} got no storage at the default ratio",
            o["name"]
        );
    }
}

#[test]
fn demo1_packs_at_the_default_ratio() {
    check("demo1", 24.5);
}

#[test]
fn demo2_packs_at_the_default_ratio() {
    check("demo2", 24.4);
}

#[test]
fn teapot_pem_packs_at_the_default_ratio() {
    check("teapot-pem", 19.4);
}

#[test]
fn glass_packs_at_the_default_ratio() {
    check("glass", 17.5);
}
