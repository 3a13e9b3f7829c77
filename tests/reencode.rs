//! pis-reencode end to end: lossless re-encoding reproduces the input's decoded textures bit
//! for bit; a lossy re-encoding meets its ratio, validates and reports its PSNR; bad
//! arguments and bad inputs leave no output.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::OnceLock;

use pis_format::PisReader;

fn repo(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join(rel)
}

/// demo1 traced at 40×30, 1 spp, packed with the wavelet codec at ratio 24 and 32-texel
/// textures, once for every test.
fn packed() -> &'static Path {
    static PACK: OnceLock<(tempfile::TempDir, PathBuf)> = OnceLock::new();
    &PACK.get_or_init(|| {
        let dir = tempfile::tempdir().expect("temp dir");
        let set = dir.path().join("set");
        let out = Command::new(env!("CARGO_BIN_EXE_pis-trace"))
            .arg(repo("samples/demo1/scene.toml")).arg("-o").arg(&set)
            .args(["--resolution", "40x30", "--spp", "1"]).output().expect("pis-trace runs");
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let file = dir.path().join("demo1.pis");
        let out = Command::new(env!("CARGO_BIN_EXE_pis-pack"))
            .arg(&set).arg("--scene").arg(repo("samples/demo1/scene.toml")).arg("-o").arg(&file)
            .args(["--ratio", "24", "--max-texture", "32"]).output().expect("pis-pack runs");
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        (dir, file)
    }).1
}

fn reencode(input: &Path, output: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_pis-reencode")).arg(input).arg("-o").arg(output).args(args).arg("--json").output().expect("pis-reencode runs")
}

fn json(out: &Output) -> serde_json::Value {
    assert!(out.status.success(), "pis-reencode failed: {}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).expect("JSON report")
}

/// Every texture of every object and layer at every parameter point, bit for bit.
fn same_textures(a: &Path, b: &Path) {
    let (ra, rb) = (PisReader::open(a).expect("a"), PisReader::open(b).expect("b"));
    let space = &ra.container().space;
    for (oi, o) in ra.container().objects.iter().enumerate() {
        for li in 0..o.layers.len() {
            for p in 0..space.point_count() {
                let point = space.point(p);
                let (x, y) = (ra.texture(oi, li, &point).expect("decode a"), rb.texture(oi, li, &point).expect("decode b"));
                assert_eq!(x.layout, y.layout);
                let differ = x.data.iter().zip(&y.data).filter(|(u, v)| u.to_bits() != v.to_bits()).count();
                assert_eq!(differ, 0, "object {} layer {li} point {point:?}: {differ} values differ", o.name);
            }
        }
    }
}

fn validate(file: &Path) {
    let out = Command::new(env!("CARGO_BIN_EXE_pis-inspect")).arg("--validate").arg(file).output().expect("pis-inspect runs");
    assert_eq!(out.status.code(), Some(0), "{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
}

#[test]
fn lossless_reproduces_the_decoded_textures_of_a_lossy_pack() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("lossless.pis");
    let r = json(&reencode(packed(), &out, &["--codec", "lossless"]));
    validate(&out);
    assert_eq!(r["exact"], true, "{r}");
    assert!(r["psnr_db"].is_null());
    assert_eq!(r["gamma"].as_f64(), Some(1.0));
    same_textures(packed(), &out);
}

#[test]
fn lossless_reproduces_the_sample_with_stored_mips_and_gamma() {
    // tiny.pis: a gamma-2.2 surface layer and a shell layer with stored MIP residuals.
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("tiny.pis");
    let r = json(&reencode(&repo("samples/tiny.pis"), &out, &["--codec", "lossless"]));
    validate(&out);
    assert_eq!(r["exact"], true, "{r}");
    same_textures(&repo("samples/tiny.pis"), &out);
    let raw = dir.path().join("raw.pis");
    json(&reencode(&out, &raw, &["--codec", "raw"]));
    same_textures(&repo("samples/tiny.pis"), &raw);
}

#[test]
fn dct_reencoding_meets_its_ratio_and_records_provenance() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("dct.pis");
    let r = json(&reencode(packed(), &out, &["--codec", "dct", "--ratio", "48"]));
    validate(&out);
    let ratio = r["ratio_without_geometry_after"].as_f64().expect("ratio");
    assert!((ratio / 48.0 - 1.0).abs() < 0.1, "ratio {ratio}, target 48");
    assert!(r["ratio_before"].as_f64().expect("before") > 0.0 && r["bytes_after"].as_u64().expect("bytes") > 0);
    let psnr = r["psnr_db"].as_f64().expect("PSNR");
    // Against the input's own decoded textures: the second coding's error only.
    assert!(psnr > 25.0, "PSNR {psnr}");
    assert_eq!(r["exact"], false);
    for o in r["objects"].as_array().expect("objects") {
        assert!(o["psnr_db"].as_f64().is_some() && o["area_px"].as_f64().expect("area") >= 1.0, "{o}");
    }
    let c = PisReader::open(&out).expect("output");
    let p = c.container().provenance.clone().expect("provenance");
    assert!(p.tool.starts_with("pis-reencode"));
    let setting = |k: &str| p.settings.iter().find(|(key, _)| key == k).map(|(_, v)| v.clone());
    assert_eq!(setting("codec").as_deref(), Some("dct"));
    assert_eq!(setting("source_codec").as_deref(), Some("wavelet"));
    assert_eq!(setting("reencoded_from"), Some(packed().display().to_string()));
    // Geometry and parameter space are copied.
    let a = PisReader::open(packed()).expect("input");
    assert_eq!(a.container().space, c.container().space);
    assert_eq!(a.container().cameras, c.container().cameras);
    for (x, y) in a.container().objects.iter().zip(&c.container().objects) {
        assert_eq!((&x.name, &x.mesh, &x.stagger, &x.transforms), (&y.name, &y.mesh, &y.stagger, &y.transforms));
    }
}

#[test]
fn bad_arguments_and_inputs_leave_no_output() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("out.pis");
    let bad_input = dir.path().join("bad.pis");
    std::fs::write(&bad_input, b"\x89PIS\r\n\x1a\nnot really").expect("write");
    let cases: [(&Path, &[&str], i32, &str); 7] = [
        (packed(), &["--ratio", "0.5"], 1, "--ratio"),
        (packed(), &["--psnr", "-3"], 1, "--psnr"),
        (packed(), &["--gamma", "0"], 1, "--gamma"),
        (packed(), &["--codec", "lossless", "--ratio", "10"], 1, "lossless"),
        (packed(), &["--codec", "jpeg"], 1, "jpeg"),
        (Path::new("/no/such/input.pis"), &[], 2, "/no/such/input.pis"),
        (&bad_input, &[], 3, "bad.pis"),
    ];
    for (input, args, code, message) in cases {
        let o = reencode(input, &out, args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(code), "{args:?}: {err}");
        assert!(err.contains(message), "{args:?}: {err}");
        assert!(!err.contains("panicked"));
        let left: Vec<_> = std::fs::read_dir(dir.path()).expect("dir").filter_map(Result::ok).map(|e| e.file_name()).filter(|n| n != "bad.pis").collect();
        assert!(left.is_empty(), "{args:?} left {left:?}");
    }
    let o = reencode(packed(), &dir.path().join("no/such/folder/out.pis"), &[]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("does not exist"));
}
