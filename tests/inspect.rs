//! pis-inspect on the bundled sample and on damaged copies of it.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn repo(rel: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..").join(rel)
}

fn inspect(args: &[&str], file: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_pis-inspect"))
        .args(args)
        .arg(file)
        .output()
        .expect("pis-inspect runs")
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

#[test]
fn summary_names_what_the_file_holds() {
    let out = inspect(&[], &repo("samples/tiny.pis"));
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let s = text(&out.stdout);
    for needle in [
        "2 dimensions, 4 points",
        "ball (reflective): 63 vertices with normals",
        "shading: f0 (0.9, 0.85, 0.8), ior 1.5, absorption (0, 0, 0)",
        "env_distant",
        "sphere shell",
        "lossless",
        "Compression ratio",
    ] {
        assert!(s.contains(needle), "missing {needle:?} in\n{s}");
    }
}

#[test]
fn json_has_the_documented_fields() {
    let out = inspect(&["--json"], &repo("samples/tiny.pis"));
    assert_eq!(out.status.code(), Some(0));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("valid JSON");
    let dims = v["dimensions"].as_array().unwrap();
    assert_eq!(dims.len(), 2);
    assert_eq!(dims[0]["name"], "view");
    assert_eq!(dims[0]["kind"], "view");
    assert_eq!(dims[0]["samples"], 2);
    assert_eq!(dims[1]["kind"], "light");
    let obj = &v["objects"][0];
    assert_eq!(obj["name"], "ball");
    assert_eq!(obj["role"], "reflective");
    assert_eq!(obj["f0"], serde_json::json!([0.9, 0.85, 0.8]));
    assert_eq!(obj["ior"], 1.5);
    assert_eq!(obj["absorption"], serde_json::json!([0.0, 0.0, 0.0]));
    assert_eq!(obj["normals"], true);
    assert_eq!(obj["layers"].as_array().unwrap().len(), 2);
    assert_eq!(obj["layers"][1]["shell"], "sphere");
    let size = std::fs::metadata(repo("samples/tiny.pis")).unwrap().len();
    assert_eq!(v["bytes"]["total"], size);
    let parts: u64 = [
        "header",
        "parameter_space",
        "cameras",
        "objects",
        "geometry",
        "layer_index",
        "codestreams",
        "provenance",
        "other",
    ]
    .iter()
    .map(|k| v["bytes"][k].as_u64().unwrap())
    .sum();
    assert_eq!(parts, size, "the byte kinds add up to the file");
    let ratio = v["ratio"].as_f64().unwrap();
    assert!((ratio - (4.0 * 32.0 * 24.0 * 3.0) / size as f64).abs() < 1e-9);
    assert!(v["ratio_without_geometry"].as_f64().unwrap() > ratio);
}

#[test]
fn validate_accepts_the_sample() {
    let out = inspect(&["--validate"], &repo("samples/tiny.pis"));
    assert_eq!(out.status.code(), Some(0), "{}{}", text(&out.stdout), text(&out.stderr));
    let out = inspect(&["--validate", "--json"], &repo("samples/tiny.pis"));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["valid"], true);
}

#[test]
fn validate_reports_numbered_errors_and_exits_3() {
    let dir = tempfile::tempdir().unwrap();
    let good = std::fs::read(repo("samples/tiny.pis")).unwrap();
    // A flipped byte in the middle of the geometry: a chunk checksum mismatch.
    let mut bad = good.clone();
    bad[1000] ^= 0x20;
    let path = dir.path().join("flipped.pis");
    std::fs::write(&path, &bad).unwrap();
    let out = inspect(&["--validate"], &path);
    assert_eq!(out.status.code(), Some(3));
    assert!(text(&out.stdout).contains("error-3004"), "{}", text(&out.stdout));
    // Truncated: a clear message, exit 3, for the summary too.
    let path = dir.path().join("truncated.pis");
    std::fs::write(&path, &good[..good.len() / 2]).unwrap();
    let out = inspect(&[], &path);
    assert_eq!(out.status.code(), Some(3));
    let err = text(&out.stderr);
    assert!(err.starts_with("pis-inspect: error-1003"), "{err}");
    assert!(!err.contains("panicked"));
}

#[test]
fn chunks_lists_offsets_and_checksums() {
    let out = inspect(&["--chunks", "--json"], &repo("samples/tiny.pis"));
    assert_eq!(out.status.code(), Some(0));
    let rows: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let types: Vec<&str> =
        rows.as_array().unwrap().iter().map(|r| r["type"].as_str().unwrap()).collect();
    assert_eq!(types, ["PSPC", "CAMS", "OBJS", "MESH", "LAYR", "CSTR", "PROV"]);
    assert!(rows.as_array().unwrap().iter().all(|r| r["checksum"] == "ok"));
}

#[test]
fn extract_writes_exr_and_png_per_texture_and_face() {
    let dir = tempfile::tempdir().unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_pis-inspect"))
        .args(["--extract"])
        .arg(dir.path())
        .args(["--at", "5,0.9"])
        .arg(repo("samples/tiny.pis"))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let mut names: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    // One diffuse texture and six shell faces, each as EXR and PNG; no temporary files.
    assert_eq!(names.len(), 14, "{names:?}");
    assert!(names.contains(&"ball.0-diffuse.exr".to_string()));
    assert!(names.contains(&"ball.1-env_distant.pz.png".to_string()));
    // The EXR holds the decoded linear texture: texel (0,0) of the diffuse layer at light
    // sample 1 is 0.8 × 1.0 in red.
    let img = image_red(&dir.path().join("ball.0-diffuse.exr"));
    assert!((img - 0.8).abs() < 1e-5, "{img}");
    // A point with the wrong number of values is a usage error.
    let out = Command::new(env!("CARGO_BIN_EXE_pis-inspect"))
        .args(["--extract"])
        .arg(dir.path())
        .args(["--at", "5"])
        .arg(repo("samples/tiny.pis"))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
}

/// `--extract` once left the files it wrote before an error: a damaged codestream of the
/// last layer (the shell) fails with exit 3 and leaves no file and no folder.
#[test]
fn extract_leaves_nothing_when_a_texture_fails() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.pis");
    let mut bytes = std::fs::read(repo("samples/tiny.pis")).unwrap();
    // the last byte of CSTR (chunk 5: offset 4160, 855 bytes): the shell's last codestream
    bytes[4160 + 855 - 1] ^= 0xff;
    std::fs::write(&bad, &bytes).unwrap();
    let out_dir = dir.path().join("textures");
    let out = Command::new(env!("CARGO_BIN_EXE_pis-inspect"))
        .args(["--extract"])
        .arg(&out_dir)
        .args(["--at", "5,0.9"])
        .arg(&bad)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(3), "{}", text(&out.stderr));
    assert!(text(&out.stderr).contains("error-8003"), "{}", text(&out.stderr));
    assert!(!out_dir.exists(), "no folder, no partial textures");
    // into a folder that exists: it stays, empty
    std::fs::create_dir(&out_dir).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_pis-inspect"))
        .args(["--extract"])
        .arg(&out_dir)
        .args(["--at", "5,0.9"])
        .arg(&bad)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(3));
    assert_eq!(std::fs::read_dir(&out_dir).unwrap().count(), 0, "no partial textures");
}

fn image_red(path: &Path) -> f32 {
    use exr::prelude::*;
    let img = read_first_rgba_layer_from_file(
        path,
        |res, _| vec![vec![(0.0f32, 0.0f32, 0.0f32, 0.0f32); res.width()]; res.height()],
        |px, pos, (r, g, b, a): (f32, f32, f32, f32)| px[pos.y()][pos.x()] = (r, g, b, a),
    )
    .unwrap();
    img.layer_data.channel_data.pixels[0][0].0
}

#[test]
fn missing_file_is_an_io_error() {
    let out = inspect(&[], Path::new("/no/such.pis"));
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("/no/such.pis"));
    let out = Command::new(env!("CARGO_BIN_EXE_pis-inspect")).arg("--bogus").output().unwrap();
    assert_eq!(out.status.code(), Some(1));
}

/// `--validate` names the rule whose field is wrong where that field decides how the rest
/// of `LAYR` is laid out: a layer's mask naming a missing dimension (5002, once reported as
/// 6000 or 8004) and a block count other than the layer's grid (6005, once reported as
/// 6000, 3006 or 7001).
#[test]
fn validate_names_the_layer_mask_and_block_count_rules() {
    let dir = tempfile::tempdir().unwrap();
    let c = pis_format::samples::tiny().unwrap();
    let (good, spans) = pis_format::to_bytes_labelled(&c).unwrap();
    for (label, value, id) in [
        ("layer 0 dependency mask", 0b101u32, 5002),
        ("layer 1 dependency mask", 0b100, 5002),
        ("layer 0 block count", 2, 6005),
        ("layer 1 block count", 3, 6005),
    ] {
        let mut bad = good.clone();
        let at = spans.iter().find(|s| s.label.starts_with(label)).unwrap().start;
        bad[at..at + 4].copy_from_slice(&value.to_le_bytes());
        pis_format::chunk::reseal(&mut bad);
        let path = dir.path().join("bad.pis");
        std::fs::write(&path, &bad).unwrap();
        let out = inspect(&["--validate"], &path);
        assert_eq!(out.status.code(), Some(3));
        let lines: Vec<String> = text(&out.stdout).lines().map(str::to_string).collect();
        assert_eq!(lines.len(), 1, "{label} = {value}: {lines:?}");
        assert!(lines[0].starts_with(&format!("error-{id}: ")), "{label} = {value}: {lines:?}");
    }
}
