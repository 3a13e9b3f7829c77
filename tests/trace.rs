//! pis-trace end to end: a tiny generated glTF scene, and samples/demo1 when present.

use pis_trace::set::RaySet;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn trace(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_pis-trace")).args(args).output().expect("pis-trace runs")
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

fn base64(bytes: &[u8]) -> String {
    const T: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::new();
    for c in bytes.chunks(3) {
        let n = (c[0] as u32) << 16
            | (*c.get(1).unwrap_or(&0) as u32) << 8
            | *c.get(2).unwrap_or(&0) as u32;
        for k in 0..4 {
            if k <= c.len() {
                s.push(T[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                s.push('=');
            }
        }
    }
    s
}

/// A floor, a mirror panel and a glass block lit by a sphere light, with a 2-sample orbit.
fn tiny_scene(dir: &Path) -> PathBuf {
    let quad = |c: [f32; 3], u: [f32; 3], v: [f32; 3]| -> Vec<f32> {
        let mut p = Vec::new();
        for (a, b) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
            for k in 0..3 {
                p.push(c[k] + a * u[k] + b * v[k]);
            }
        }
        p
    };
    let meshes = [
        quad([0.0, 0.0, 0.0], [0.0, 0.0, 2.0], [2.0, 0.0, 0.0]),
        quad([0.0, 0.6, -0.8], [0.6, 0.0, 0.0], [0.0, 0.6, 0.0]),
        quad([0.5, 0.3, 0.3], [0.2, 0.0, 0.0], [0.0, 0.3, 0.0]),
    ];
    let mut buf = Vec::new();
    let mut views = Vec::new();
    let mut accessors = Vec::new();
    for m in &meshes {
        let off = buf.len();
        for x in m {
            buf.extend_from_slice(&x.to_le_bytes());
        }
        views.push(format!(r#"{{"buffer":0,"byteOffset":{off},"byteLength":48}}"#));
        let (mut lo, mut hi) = ([f32::MAX; 3], [f32::MIN; 3]);
        for v in m.chunks(3) {
            for k in 0..3 {
                lo[k] = lo[k].min(v[k]);
                hi[k] = hi[k].max(v[k]);
            }
        }
        accessors.push(format!(
            r#"{{"bufferView":{},"componentType":5126,"count":4,"type":"VEC3","min":{lo:?},"max":{hi:?}}}"#,
            views.len() - 1
        ));
        let off = buf.len();
        for i in [0u16, 1, 2, 0, 2, 3] {
            buf.extend_from_slice(&i.to_le_bytes());
        }
        views.push(format!(r#"{{"buffer":0,"byteOffset":{off},"byteLength":12}}"#));
        accessors.push(format!(
            r#"{{"bufferView":{},"componentType":5123,"count":6,"type":"SCALAR"}}"#,
            views.len() - 1
        ));
    }
    let gltf = format!(
        r#"{{
  "asset": {{"version": "2.0"}},
  "extensionsUsed": ["KHR_lights_punctual", "KHR_materials_transmission"],
  "extensions": {{"KHR_lights_punctual": {{"lights": [{{"name": "Key", "type": "point", "intensity": 6, "extras": {{"radius": 0.1}}}}]}}}},
  "scene": 0,
  "scenes": [{{"nodes": [0, 1, 2, 3]}}],
  "nodes": [
    {{"name": "Floor", "mesh": 0}},
    {{"name": "Mirror", "mesh": 1}},
    {{"name": "Glass", "mesh": 2}},
    {{"name": "KeyNode", "translation": [0.5, 2.0, 1.0], "extensions": {{"KHR_lights_punctual": {{"light": 0}}}}}}
  ],
  "meshes": [
    {{"primitives": [{{"attributes": {{"POSITION": 0}}, "indices": 1, "material": 0}}]}},
    {{"primitives": [{{"attributes": {{"POSITION": 2}}, "indices": 3, "material": 1}}]}},
    {{"primitives": [{{"attributes": {{"POSITION": 4}}, "indices": 5, "material": 2}}]}}
  ],
  "materials": [
    {{"name": "Matte", "pbrMetallicRoughness": {{"baseColorFactor": [0.7, 0.6, 0.5, 1], "metallicFactor": 0, "roughnessFactor": 1}}}},
    {{"name": "Chrome", "pbrMetallicRoughness": {{"metallicFactor": 1, "roughnessFactor": 0}}}},
    {{"name": "Glass", "pbrMetallicRoughness": {{"metallicFactor": 0, "roughnessFactor": 0}}, "extensions": {{"KHR_materials_transmission": {{"transmissionFactor": 1}}}}}}
  ],
  "accessors": [{}],
  "bufferViews": [{}],
  "buffers": [{{"byteLength": {}, "uri": "data:application/octet-stream;base64,{}"}}]
}}"#,
        accessors.join(","),
        views.join(","),
        buf.len(),
        base64(&buf)
    );
    std::fs::write(dir.join("tiny.gltf"), gltf).unwrap();
    let toml = r#"name = "tiny"
gltf = "tiny.gltf"
resolution = [24, 16]
spp = 2

[[dimension]]
name = "view"
driver = "orbit"
samples = 2
target = [0, 0.3, 0]
radius = 3
elevation_deg = 25
azimuth_deg = [-10, 10]
"#;
    let path = dir.join("scene.toml");
    std::fs::write(&path, toml).unwrap();
    path
}

fn dir_bytes(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut v: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| {
            let e = e.unwrap();
            (e.file_name().to_string_lossy().into_owned(), std::fs::read(e.path()).unwrap())
        })
        .collect();
    v.sort();
    v
}

#[test]
fn traces_a_scene_into_a_set_deterministically() {
    let tmp = tempfile::tempdir().unwrap();
    let scene = tiny_scene(tmp.path());
    let (a, b) = (tmp.path().join("a"), tmp.path().join("b"));
    let out = trace(&[scene.to_str().unwrap(), "-o", a.to_str().unwrap(), "--json"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let report: serde_json::Value =
        serde_json::from_slice(&out.stdout).expect("--json prints JSON");
    assert_eq!(report["points"], 2);
    assert!(report["rays_per_second"].as_f64().unwrap() > 0.0);
    assert!(report["ms_per_point"].as_f64().unwrap() > 0.0);

    let set = RaySet::open(&a).unwrap();
    assert_eq!(set.meta.resolution, [24, 16]);
    assert_eq!(set.len(), 2);
    let roles: Vec<&str> = set.meta.objects.iter().map(|o| o.role.as_str()).collect();
    assert_eq!(roles, ["diffuse", "reflective", "refractive"]);
    let img = set.read_point(1).unwrap();
    assert!(
        img.layer("object.Mirror.distant").is_some()
            && img.layer("object.Glass.refraction_confidence").is_some()
    );
    assert!(img.layer("combined").unwrap().planes[0].iter().any(|&v| v > 0.0));

    let out = trace(&[scene.to_str().unwrap(), "-o", b.to_str().unwrap(), "--threads", "1"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert!(text(&out.stderr).contains("rays/s"));
    assert_eq!(dir_bytes(&a), dir_bytes(&b), "a second run gives other bytes");
}

/// `--shading-seed sample` (a gold standard) is recorded in set.json and the report, and
/// gives other pixels than the default seeding per surface cell.
#[test]
fn shading_seeded_per_sample_is_recorded() {
    let tmp = tempfile::tempdir().unwrap();
    let scene = tiny_scene(tmp.path());
    let (cell, sample) = (tmp.path().join("cell"), tmp.path().join("sample"));
    let out =
        trace(&[scene.to_str().unwrap(), "-o", cell.to_str().unwrap(), "--points", "1", "--json"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(report["shading_seed"], "cell");
    let out = trace(&[
        scene.to_str().unwrap(),
        "-o",
        sample.to_str().unwrap(),
        "--points",
        "1",
        "--shading-seed",
        "sample",
        "--json",
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(report["shading_seed"], "sample");
    let settings =
        |dir: &Path| RaySet::open(dir).unwrap().meta.renderer.and_then(|r| r.settings).unwrap();
    assert_eq!(settings(&sample).coherence_cell, Some(0.0));
    assert_eq!(settings(&cell).coherence_cell, None);
    let combined = |dir: &Path| {
        RaySet::open(dir).unwrap().read_point(0).unwrap().layer("combined").unwrap().planes[0]
            .clone()
    };
    assert_ne!(combined(&cell), combined(&sample));
    let out = trace(&[
        scene.to_str().unwrap(),
        "-o",
        tmp.path().join("x").to_str().unwrap(),
        "--shading-seed",
        "pixel",
    ]);
    assert_eq!(out.status.code(), Some(1), "{}", text(&out.stderr));
}

#[test]
fn a_sample_stream_is_recorded_and_changes_the_noise() {
    let tmp = tempfile::tempdir().unwrap();
    let scene = tiny_scene(tmp.path());
    let s = scene.to_str().unwrap();
    let dir = |n: &str| tmp.path().join(n);
    for (name, extra) in
        [("default", &[][..]), ("zero", &["--seed", "0"][..]), ("one", &["--seed", "1"][..])]
    {
        let o = dir(name);
        let mut args = vec![
            s,
            "-o",
            o.to_str().unwrap(),
            "--points",
            "1",
            "--shading-seed",
            "sample",
            "--json",
        ];
        args.extend_from_slice(extra);
        let out = trace(&args);
        assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
        let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(report["seed"], if name == "one" { 1 } else { 0 });
    }
    let combined = |n: &str| {
        RaySet::open(dir(n)).unwrap().read_point(0).unwrap().layer("combined").unwrap().planes[0]
            .clone()
    };
    assert_eq!(combined("default"), combined("zero"));
    assert_ne!(combined("default"), combined("one"));
    let settings =
        |n: &str| RaySet::open(dir(n)).unwrap().meta.renderer.and_then(|r| r.settings).unwrap();
    assert_eq!(settings("one").seed, 1);
    assert_eq!(settings("zero").seed, 0);
    // The default stream leaves set.json as it was before streams were recorded.
    let json = std::fs::read_to_string(dir("zero").join("set.json")).unwrap();
    assert!(!json.contains("\"seed\""), "{json}");
    let out = trace(&[s, "-o", dir("bad").to_str().unwrap(), "--seed", "-1"]);
    assert_eq!(out.status.code(), Some(1), "{}", text(&out.stderr));
}

#[test]
fn errors_have_documented_exit_codes() {
    let tmp = tempfile::tempdir().unwrap();
    let scene = tiny_scene(tmp.path());
    let o = tmp.path().join("o");
    let s = scene.to_str().unwrap();
    let cases: [(&[&str], i32); 4] = [
        (&[s, "-o", o.to_str().unwrap(), "--resolution", "12by8"], 1),
        (&["missing/scene.toml", "-o", o.to_str().unwrap()], 2),
        (&[s, "-o", o.to_str().unwrap(), "--preset", "nope"], 3),
        (&[s, "-o", o.to_str().unwrap(), "--spp", "0"], 3),
    ];
    for (args, code) in cases {
        let out = trace(args);
        assert_eq!(out.status.code(), Some(code), "{args:?}: {}", text(&out.stderr));
        if code != 1 {
            let err = text(&out.stderr);
            assert!(err.starts_with("pis-trace: ") && err.lines().count() == 1, "{err}");
        }
    }
}

/// The acceptance run of samples/demo1.
#[test]
fn demo1_at_80x60_gives_identical_bytes_twice() {
    let scene = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../samples/demo1/scene.toml");
    if !scene.exists() {
        eprintln!("samples/demo1 is not in the tree; skipped");
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let mut dirs = Vec::new();
    for run in ["a", "b"] {
        let d = tmp.path().join(run);
        let out = trace(&[
            scene.to_str().unwrap(),
            "-o",
            d.to_str().unwrap(),
            "--resolution",
            "80x60",
            "--spp",
            "4",
        ]);
        assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
        dirs.push(d);
    }
    let set = RaySet::open(&dirs[0]).unwrap();
    for i in 0..set.len() {
        set.read_point(i).unwrap();
    }
    assert_eq!(dir_bytes(&dirs[0]), dir_bytes(&dirs[1]));
}

/// A resolution within the file's limit but beyond this machine's memory once aborted on
/// allocation: refused before any point, with the figures.
#[test]
fn a_point_larger_than_memory_is_refused_before_tracing() {
    if pis_trace::memory::available_memory().is_none_or(|m| m > 1 << 40) {
        return; // no figure to compare with, or a machine with a terabyte
    }
    let dir = tempfile::tempdir().unwrap();
    let scene = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../samples/demo1/scene.toml");
    let out = Command::new(env!("CARGO_BIN_EXE_pis-trace"))
        .arg(&scene)
        .arg("-o")
        .arg(dir.path().join("set"))
        .args(["--resolution", "65536x65536"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(5), "{err}");
    assert!(
        err.contains("a point of 65536x65536 pixels needs about") && err.contains("are available"),
        "{err}"
    );
    assert!(!dir.path().join("set").join("set.json").exists());
}

fn trace_with(args: &[&str], env: &[(&str, &str)]) -> Output {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_pis-trace"));
    cmd.args(args);
    for (k, v) in env {
        cmd.env(k, v);
    }
    cmd.output().expect("pis-trace runs")
}

/// Where Open Image Denoise is not found the trace says once how to install it and writes
/// raw layers; `--denoise on` refuses instead.
#[test]
fn without_open_image_denoise_a_set_is_raw_and_the_trace_says_how_to_install_it() {
    let tmp = tempfile::tempdir().unwrap();
    let scene = tiny_scene(tmp.path());
    let missing = tmp.path().join("no-such-dir/libOpenImageDenoise.so.2");
    let env = [("PIS_OIDN_LIBRARY", missing.to_str().unwrap())];
    let out_dir = tmp.path().join("raw");
    let out =
        trace_with(&[scene.to_str().unwrap(), "-o", out_dir.to_str().unwrap(), "--json"], &env);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let stderr = text(&out.stderr);
    assert_eq!(stderr.matches("pip install pyoidn").count(), 1, "{stderr}");
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(report.get("denoiser").is_none(), "{report}");
    let set = RaySet::open(&out_dir).unwrap();
    assert_eq!((set.meta.denoiser.as_deref(), set.is_denoised()), (None, false));
    let img = set.read_point(0).unwrap();
    assert!(img
        .layers
        .iter()
        .all(|l| !l.name.starts_with("denoised.") && !l.name.starts_with("guide.")));

    let on = tmp.path().join("on");
    let out =
        trace_with(&[scene.to_str().unwrap(), "-o", on.to_str().unwrap(), "--denoise", "on"], &env);
    assert_ne!(out.status.code(), Some(0));
    assert!(text(&out.stderr).contains("pip install pyoidn"), "{}", text(&out.stderr));
    assert!(!on.join("set.json").exists());
}

/// An adaptive, denoised set records each pixel's samples and error, the guides, and the
/// denoised twins that a reader takes in place of the raw layers.
#[test]
fn an_adaptive_denoised_set_records_samples_guides_and_twins() {
    if pis_trace::oidn::shared_or_skip("an_adaptive_denoised_set_records_samples_guides_and_twins")
        .is_none()
    {
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let scene = tiny_scene(tmp.path());
    let dir = tmp.path().join("set");
    let args = ["--spp", "4", "--noise-threshold", "0.05", "--min-spp", "2", "--json"];
    let out = trace(&[&[scene.to_str().unwrap(), "-o", dir.to_str().unwrap()], &args[..]].concat());
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let mean = report["mean_spp"].as_f64().unwrap();
    assert!((2.0..=4.0).contains(&mean), "{report}");
    assert!(report["denoiser"].as_str().is_some_and(|d| d.starts_with("Open Image Denoise 2.")));
    let set = RaySet::open(&dir).unwrap();
    assert!(set.is_denoised() && set.meta.denoiser.is_some());
    let denoise = set.meta.points[0].denoise.as_ref().expect("the point says what was denoised");
    assert!(denoise.layers.iter().any(|l| l == "combined"));
    let raw = RaySet::open(&dir).unwrap().with_raw(true).read_point(0).unwrap();
    let clean = set.read_point(0).unwrap();
    for name in ["samples", "error", "guide.albedo", "guide.normal"] {
        assert!(raw.layer(name).is_some(), "layer {name}");
    }
    let samples = &raw.layer("samples").unwrap().planes[0];
    assert!(samples.iter().all(|&n| (2.0..=4.0).contains(&n)));
    assert_ne!(raw.layer("combined"), clean.layer("combined"), "the twin is read in its place");
    assert!(clean.layers.iter().all(|l| !l.name.starts_with("denoised.")));
}

/// A scene.toml given to pis-pack is traced as pis-trace traces it by default: denoised
/// where Open Image Denoise loads, into a cache of its own (`-denoised`), the report saying
/// so; raw with `--denoise off`, and raw, with a warning, where the library is missing.
#[test]
fn a_scene_toml_given_to_pis_pack_is_denoised_as_pis_trace_denoises_it() {
    let found = pis_trace::oidn::shared().is_ok();
    assert!(found || std::env::var_os("PIS_REQUIRE_OIDN").is_none(), "PIS_REQUIRE_OIDN is set");
    let tmp = tempfile::tempdir().unwrap();
    let scene = tiny_scene(tmp.path());
    let pack = |denoise: &str, file: &str| {
        let out = Command::new(env!("CARGO_BIN_EXE_pis-pack"))
            .arg(&scene)
            .args(["--resolution", "24x18", "--spp", "2", "--ratio", "8", "--denoise", denoise])
            .arg("-o")
            .arg(tmp.path().join(file))
            .output()
            .expect("pis-pack runs");
        assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
        text(&out.stderr)
    };
    let cache = scene.parent().unwrap().join(".pis-cache");
    let name = |suffix: &str| {
        let s = pis_scene::load(&scene, None).unwrap();
        cache.join(format!("{}-24x18-spp2{suffix}", s.name))
    };
    let report = pack("auto", "auto.pis");
    let dir = if found { name("-denoised") } else { name("") };
    let set = RaySet::open(&dir).unwrap_or_else(|e| panic!("{}: {e}\n{report}", dir.display()));
    assert_eq!(set.meta.denoiser.is_some(), found, "{report}");
    let says = if found { "(denoised by Open Image Denoise 2." } else { "pip install pyoidn" };
    assert!(report.contains(says), "{report}");
    let report = pack("off", "off.pis");
    let raw = RaySet::open(name("")).unwrap();
    assert!(raw.meta.denoiser.is_none(), "{report}");
    // Where the library is missing, the raw set traced above is the one taken again.
    assert_eq!(report.contains("(raw layers)"), found, "{report}");
}
