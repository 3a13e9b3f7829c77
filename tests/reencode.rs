//! pis-reencode end to end: lossless re-encoding reproduces the input's decoded textures bit
//! for bit; a lossy re-encoding meets its ratio, validates and reports its PSNR; from a
//! lossless master it gives what a direct pack at the new settings gives, and a lossless
//! round trip carrying the master gives the pack back; bad arguments, bad inputs and a
//! damaged master leave no output.

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::OnceLock;

use pis_format::PisReader;

fn repo(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join(rel)
}

/// demo1 traced at 40×30, 1 spp, once for every test.
fn set() -> &'static Path {
    static SET: OnceLock<(tempfile::TempDir, PathBuf)> = OnceLock::new();
    &SET.get_or_init(|| {
        let dir = common::fixture_tempdir();
        let set = dir.path().join("set");
        let out = Command::new(env!("CARGO_BIN_EXE_pis-trace"))
            .arg(repo("samples/demo1/scene.toml"))
            .arg("-o")
            .arg(&set)
            .args(["--resolution", "40x30", "--spp", "1"])
            .output()
            .expect("pis-trace runs");
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        (dir, set)
    })
    .1
}

/// The set packed with the wavelet codec and 32-texel textures, with `args`.
fn pack(name: &str, args: &[&str]) -> (tempfile::TempDir, PathBuf) {
    let dir = common::fixture_tempdir();
    let file = dir.path().join(name);
    let out = Command::new(env!("CARGO_BIN_EXE_pis-pack"))
        .arg(set())
        .arg("--scene")
        .arg(repo("samples/demo1/scene.toml"))
        .arg("-o")
        .arg(&file)
        .args(["--max-texture", "32"])
        .args(args)
        .output()
        .expect("pis-pack runs");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    (dir, file)
}

/// Packed at ratio 24, once for every test.
fn packed() -> &'static Path {
    static PACK: OnceLock<(tempfile::TempDir, PathBuf)> = OnceLock::new();
    &PACK.get_or_init(|| pack("demo1.pis", &["--ratio", "24"])).1
}

/// Packed at ratio 24 with the lossless master, once for every test.
fn mastered() -> &'static Path {
    static PACK: OnceLock<(tempfile::TempDir, PathBuf)> = OnceLock::new();
    &PACK.get_or_init(|| pack("mastered.pis", &["--ratio", "24", "--keep-master"])).1
}

/// Packed at ratio 24 with the lossless master and one texture placement per object (what
/// re-blocking needs), once for every test.
fn mastered_per_object() -> &'static Path {
    static PACK: OnceLock<(tempfile::TempDir, PathBuf)> = OnceLock::new();
    &PACK
        .get_or_init(|| {
            pack(
                "mastered-object.pis",
                &["--ratio", "24", "--keep-master", "--placement", "object"],
            )
        })
        .1
}

/// The max-MSE constraint a file's writer applied, as its provenance records it (what
/// pis-reencode applies again): a direct pack compared with a re-encoding is given the same,
/// since `auto` may choose otherwise at the new ratio.
fn recorded_max_mse(file: &Path) -> String {
    let c = PisReader::open(file).expect("file").load_all().expect("load");
    c.provenance
        .expect("provenance")
        .settings
        .iter()
        .find(|(k, _)| k == "max_mse_ratio")
        .map(|(_, v)| v.clone())
        .expect("max_mse_ratio recorded")
}

fn reencode(input: &Path, output: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_pis-reencode"))
        .arg(input)
        .arg("-o")
        .arg(output)
        .args(args)
        .arg("--json")
        .output()
        .expect("pis-reencode runs")
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
                let (x, y) = (
                    ra.texture(oi, li, &point).expect("decode a"),
                    rb.texture(oi, li, &point).expect("decode b"),
                );
                assert_eq!(x.layout, y.layout);
                let differ =
                    x.data.iter().zip(&y.data).filter(|(u, v)| u.to_bits() != v.to_bits()).count();
                assert_eq!(
                    differ, 0,
                    "object {} layer {li} point {point:?}: {differ} values differ",
                    o.name
                );
            }
        }
    }
}

fn validate(file: &Path) {
    let out = Command::new(env!("CARGO_BIN_EXE_pis-inspect"))
        .arg("--validate")
        .arg(file)
        .output()
        .expect("pis-inspect runs");
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
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
    assert!(
        r["ratio_before"].as_f64().expect("before") > 0.0
            && r["bytes_after"].as_u64().expect("bytes") > 0
    );
    let psnr = r["psnr_db"].as_f64().expect("PSNR");
    // Against the input's own decoded textures: the second coding's error only.
    assert!(psnr > 25.0, "PSNR {psnr}");
    assert_eq!(r["exact"], false);
    for o in r["objects"].as_array().expect("objects") {
        assert!(
            o["psnr_db"].as_f64().is_some() && o["area_px"].as_f64().expect("area") >= 1.0,
            "{o}"
        );
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
        assert_eq!(
            (&x.name, &x.mesh, &x.stagger, &x.transforms),
            (&y.name, &y.mesh, &y.stagger, &y.transforms)
        );
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
        let left: Vec<_> = std::fs::read_dir(dir.path())
            .expect("dir")
            .filter_map(Result::ok)
            .map(|e| e.file_name())
            .filter(|n| n != "bad.pis")
            .collect();
        assert!(left.is_empty(), "{args:?} left {left:?}");
    }
    let o = reencode(packed(), &dir.path().join("no/such/folder/out.pis"), &[]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("does not exist"));
}

/// Level images (codecs, codestream bytes), geometry, transforms and every other part a
/// player reads, equal in both files.
fn same_player_content(a: &Path, b: &Path) {
    let (x, y) = (PisReader::open(a).expect("a"), PisReader::open(b).expect("b"));
    let (cx, cy) = (x.load_all().expect("a codestreams"), y.load_all().expect("b codestreams"));
    assert_eq!((&cx.space, &cx.cameras), (&cy.space, &cy.cameras));
    assert_eq!(cx.objects, cy.objects, "{} and {} differ", a.display(), b.display());
}

#[test]
fn reencoding_from_the_master_gives_a_direct_pack() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("from-master.pis");
    let r = json(&reencode(mastered(), &out, &["--ratio", "48"]));
    validate(&out);
    assert_eq!(r["source"], "master", "{r}");
    let master = r["master_bytes_before"].as_u64().expect("master bytes");
    assert!(master > 0 && r["master_bytes_after"] == 0, "{r}");
    // The ratio counts what a player uses, not the master.
    let (raw, bytes) =
        (r["raw_image_bytes"].as_f64().expect("raw"), r["bytes_before"].as_f64().expect("bytes"));
    assert!(
        (r["ratio_before"].as_f64().expect("ratio") - raw / (bytes - master as f64)).abs() < 1e-9
    );
    let before = r["psnr_master_before_db"].as_f64().expect("PSNR of the input against the master");
    let after = r["psnr_master_after_db"].as_f64().expect("PSNR of the output against the master");
    assert!(
        after < before
            && (r["psnr_change_db"].as_f64().expect("change") - (after - before)).abs() < 1e-9,
        "{r}"
    );
    // A direct pack at ratio 48: the same level images, byte for byte, hence the same PSNR.
    let (_d, direct) =
        pack("direct.pis", &["--ratio", "48", "--max-mse-ratio", &recorded_max_mse(mastered())]);
    same_player_content(&out, &direct);
    // Geometry and transforms are the input's.
    let (a, b) =
        (PisReader::open(mastered()).expect("input"), PisReader::open(&out).expect("output"));
    for (x, y) in a.container().objects.iter().zip(&b.container().objects) {
        assert_eq!(
            (&x.name, &x.mesh, &x.stagger, &x.transforms),
            (&y.name, &y.mesh, &y.stagger, &y.transforms)
        );
    }
    // pis-diff: the same level images with and without the master, the master counted apart.
    let d = Command::new(env!("CARGO_BIN_EXE_pis-diff"))
        .arg(mastered())
        .arg(packed())
        .arg("--json")
        .output()
        .expect("pis-diff runs");
    let v: serde_json::Value = serde_json::from_slice(&d.stdout).expect("pis-diff JSON");
    assert_eq!(v["textures_identical"], true, "{v}");
    assert!(
        v["structure"]
            .as_array()
            .expect("structure")
            .iter()
            .any(|l| l == "lossless master only in the first file"),
        "{v}"
    );
    assert_eq!(
        (v["bytes"]["a"]["master"].as_u64(), v["bytes"]["b"]["master"].as_u64()),
        (Some(master), Some(0))
    );
    // Without a master the same request codes the decoded textures: other level images.
    let decoded = dir.path().join("from-decoded.pis");
    let r = json(&reencode(packed(), &decoded, &["--ratio", "48"]));
    assert_eq!(r["source"], "decoded textures");
    assert!(r["psnr_master_after_db"].is_null() && r["master_bytes_before"] == 0);
    let (x, y) = (
        PisReader::open(&decoded).expect("decoded").load_all().expect("load"),
        PisReader::open(&direct).expect("direct").load_all().expect("load"),
    );
    assert_ne!(x.objects, y.objects);
}

#[test]
fn a_lossless_round_trip_carrying_the_master_gives_the_pack_back() {
    let dir = tempfile::tempdir().expect("temp dir");
    let lossless = dir.path().join("lossless.pis");
    let r = json(&reencode(mastered(), &lossless, &["--codec", "lossless", "--keep-master"]));
    validate(&lossless);
    assert_eq!(
        (&r["source"], &r["master_bytes_after"]),
        (&serde_json::json!("master"), &r["master_bytes_before"]),
        "{r}"
    );
    assert_eq!(
        PisReader::open(&lossless).expect("lossless").masters().expect("master"),
        PisReader::open(mastered()).expect("input").masters().expect("master")
    );
    let back = dir.path().join("back.pis");
    let r = json(&reencode(&lossless, &back, &["--ratio", "24", "--keep-master"]));
    validate(&back);
    assert_eq!(r["source"], "master");
    same_player_content(&back, mastered());
    // The PSNR against the master is the pack's again.
    let first =
        json(&reencode(mastered(), &dir.path().join("again.pis"), &["--codec", "lossless"]));
    let (p0, p1) = (
        first["psnr_master_before_db"].as_f64().expect("pack"),
        r["psnr_master_after_db"].as_f64().expect("round trip"),
    );
    assert!((p0 - p1).abs() < 0.1, "{p0} dB → {p1} dB");
}

#[test]
fn keep_master_needs_a_master_or_an_exact_input() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("out.pis");
    let o = reencode(packed(), &out, &["--keep-master"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("carries no master") && !out.exists(), "{err}");
    // From a lossless file: the decoded textures become the master.
    let lossless = dir.path().join("lossless.pis");
    json(&reencode(packed(), &lossless, &["--codec", "lossless"]));
    let made = dir.path().join("made.pis");
    let r = json(&reencode(&lossless, &made, &["--codec", "lossless", "--keep-master"]));
    validate(&made);
    assert_eq!(r["source"], "decoded textures");
    assert!(r["master_bytes_after"].as_u64() > Some(0));
    let m = PisReader::open(&made).expect("made");
    let masters = m.masters().expect("master");
    let c = m.container();
    for o in &masters {
        let obj = &c.objects[o.object as usize];
        for (li, l) in obj.layers.iter().enumerate() {
            for s in 0..c.space.table_len(l.depends_on) as usize {
                let point = pis_format::master::sample_point(c, l, s as u64);
                let want = m.texture(o.object as usize, li, &point).expect("texture").data;
                let got = o.texture(c, li, s).expect("master texture");
                assert!(
                    got.len() == want.len()
                        && got.iter().zip(&want).all(|(a, b)| a.to_bits() == b.to_bits())
                );
            }
        }
    }
}

#[test]
fn a_damaged_master_is_an_error_without_output() {
    let dir = tempfile::tempdir().expect("temp dir");
    let damaged = dir.path().join("damaged.pis");
    let mut bytes = std::fs::read(mastered()).expect("read");
    let r = PisReader::open(mastered()).expect("input");
    let e = r.chunks().iter().find(|e| &e.fourcc == b"MSTR").expect("an MSTR chunk").clone();
    bytes[(e.offset + e.length / 3) as usize] ^= 0x40;
    std::fs::write(&damaged, bytes).expect("write");
    let out = dir.path().join("out.pis");
    let o = reencode(&damaged, &out, &["--ratio", "48"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(3), "{err}");
    assert!(
        err.contains("damaged.pis") && err.contains("error-3004") && err.contains("MSTR"),
        "{err}"
    );
    assert!(!out.exists() && !err.contains("panicked"));
    let v = Command::new(env!("CARGO_BIN_EXE_pis-inspect"))
        .arg("--validate")
        .arg(&damaged)
        .output()
        .expect("pis-inspect runs");
    assert_eq!(v.status.code(), Some(3));
    assert!(
        String::from_utf8_lossy(&v.stdout).contains("error-3004")
            || String::from_utf8_lossy(&v.stderr).contains("error-3004")
    );
}

#[test]
fn reblocking_from_the_master_gives_a_direct_pack_with_those_blocks() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("reblocked.pis");
    let r = json(&reencode(mastered_per_object(), &out, &["--ratio", "48", "--block", "2"]));
    validate(&out);
    assert_eq!(r["source"], "master", "{r}");
    let (_d, direct) = pack(
        "direct-block2.pis",
        &[
            "--ratio",
            "48",
            "--block",
            "2",
            "--placement",
            "object",
            "--max-mse-ratio",
            &recorded_max_mse(mastered_per_object()),
        ],
    );
    // The same blocks, origins, pyramids and level images, byte for byte.
    same_player_content(&out, &direct);
    let c = PisReader::open(&out).expect("output").load_all().expect("load");
    assert!(c.space.dims.iter().all(|d| d.block_size == 2));
    let before = PisReader::open(mastered_per_object()).expect("input").load_all().expect("load");
    let blocks = |c: &pis_format::Container| {
        c.objects.iter().flat_map(|o| &o.layers).map(|l| l.blocks.len()).sum::<usize>()
    };
    assert!(blocks(&c) > blocks(&before), "smaller blocks, more of them");
    for (x, y) in before.objects.iter().zip(&c.objects) {
        assert_eq!(
            (&x.mesh, &x.transforms),
            (&y.mesh, &y.transforms),
            "geometry and transforms are kept"
        );
    }
    let prov = c.provenance.expect("provenance");
    assert!(prov.settings.iter().any(|(k, v)| k == "block" && v == "2x2"), "{:?}", prov.settings);
}

#[test]
fn reblocking_textures_placed_per_block_is_refused_without_output() {
    // pis-pack's default places each block's texture for its own views. With blocks of 2
    // over the 4 × 4 points (demo1's 4 samples fit in the default block of 8: one block per
    // object, which re-blocks), some layer's blocks differ, and a new block could gather
    // samples of two placements.
    let (_d, small) =
        pack("mastered-block2.pis", &["--ratio", "24", "--keep-master", "--block", "2"]);
    let c = PisReader::open(&small).expect("input").load_all().expect("load");
    let differs = c.objects.iter().flat_map(|o| &o.layers).any(|l| {
        l.blocks
            .iter()
            .any(|b| b.placement != l.blocks[0].placement || b.width != l.blocks[0].width)
    });
    assert!(differs, "a pack in blocks of 2 places some layer's blocks differently");
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("reblocked.pis");
    let o = reencode(&small, &out, &["--block", "4"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(5), "{err}");
    assert!(err.contains("--placement object") && !out.exists(), "{err}");
}

#[test]
fn lossless_reblocking_keeps_every_texture() {
    let dir = tempfile::tempdir().expect("temp dir");
    let (lossless, reblocked, back) = (
        dir.path().join("lossless.pis"),
        dir.path().join("block3.pis"),
        dir.path().join("back.pis"),
    );
    json(&reencode(mastered_per_object(), &lossless, &["--codec", "lossless"]));
    json(&reencode(&lossless, &reblocked, &["--codec", "lossless", "--block", "3x1"]));
    validate(&reblocked);
    same_textures(&lossless, &reblocked);
    json(&reencode(&reblocked, &back, &["--codec", "lossless", "--block", "8"]));
    same_textures(&lossless, &back);
    // A bad size is a usage error, and nothing is written.
    let bad = dir.path().join("bad.pis");
    let out = reencode(&lossless, &bad, &["--codec", "lossless", "--block", "2x2x2"]);
    assert_eq!(out.status.code(), Some(1), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(!bad.exists());
}

/// samples/tiny.pis with its diffuse texture made 1024 × 1024 texels of one colour, coded
/// losslessly: a valid file (DEFLATE holds each 12 MiB level image in about 12 KB), whose
/// level images need at least 1536 bytes of codestream (SPEC.md section 12: a level image
/// decodes to at most 8192 times the codestream bytes of the file).
fn flat_large_texture(dir: &Path) -> PathBuf {
    use pis_format::{samples, Block, CodecId};
    let mut c = samples::tiny().expect("tiny");
    let layer = c.objects[0].layers[0].clone();
    let counts: Vec<Vec<u32>> = layer.blocks[0].levels.iter().map(|l| l.counts.clone()).collect();
    let extent = counts.last().expect("a finest level").clone();
    let block = Block { width: 1024, height: 1024, levels: vec![], ..layer.blocks[0].clone() };
    let textures = vec![vec![0.25f32; 1024 * 1024 * 3]; extent.iter().product::<u32>() as usize];
    let block =
        samples::encode_block(&layer, block, &extent, &counts, &textures, CodecId::Lossless)
            .expect("encode");
    c.objects[0].layers[0].blocks = vec![block];
    let path = dir.join("flat.pis");
    pis_format::write(&path, &c).expect("a valid input");
    validate(&path);
    path
}

/// The folder holds only `input` (no output, no temporary file).
fn only_input(dir: &Path) {
    let names: Vec<_> =
        std::fs::read_dir(dir).expect("dir").map(|e| e.expect("entry").file_name()).collect();
    assert_eq!(names, ["flat.pis"], "{names:?}");
}

/// A ratio whose byte budget cannot hold codestreams large enough for the textures they
/// decode to (SPEC.md section 12) is refused with the reason before anything is encoded:
/// the re-encoding once ran and failed at the write with error-6009.
#[test]
fn a_budget_too_small_for_the_textures_is_refused_before_encoding() {
    let dir = tempfile::tempdir().expect("temp dir");
    let input = flat_large_texture(dir.path());
    let out =
        reencode(&input, &dir.path().join("out.pis"), &["--codec", "wavelet", "--ratio", "10"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("SPEC.md section 12") && err.contains("a ratio of at most"), "{err}");
    assert!(!err.contains("pis-reencode: encode"), "refused before encoding: {err}");
    only_input(dir.path());
}

/// A codec that codes a large flat texture in a few bytes, whatever the budget, gives
/// codestreams too small for section 12's limits: refused before anything is written.
#[test]
fn codestreams_too_small_for_their_textures_are_refused_before_writing() {
    let dir = tempfile::tempdir().expect("temp dir");
    let input = flat_large_texture(dir.path());
    let out = reencode(&input, &dir.path().join("out.pis"), &["--codec", "wavelet"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("SPEC.md section 12") && err.contains("nothing was written"), "{err}");
    assert!(!err.contains("pis-reencode: write"), "{err}");
    only_input(dir.path());
}

/// A ratio so high that every level image gets no byte: every codestream is empty (SPEC.md
/// 11.2, decoding to zeros), and section 12 counts such a file's codestreams as 1024 bytes,
/// so the output is written and valid; it was once refused with error-6009 (8192 × 0 bytes).
#[test]
fn an_output_whose_codestreams_are_all_empty_is_valid() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("empty.pis");
    let r = json(&reencode(
        &repo("samples/tiny.pis"),
        &out,
        &["--codec", "wavelet", "--ratio", "1000000"],
    ));
    assert_eq!(r["texture_bytes_after"], 0, "{r}");
    validate(&out);
}
