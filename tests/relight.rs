//! Relighting end to end (Wong et al. on the thesis's textures): still-life's relight scene
//! traced small over 24 sun directions × 2 views, packed with the surface layers as
//! spherical-harmonic coefficients (`--relight on`) and with the light sampled (`off`), and
//! both played at 7 directions the set does not hold (`--preset held`-style: another count
//! of the same spherical Fibonacci set); the relit file then played under two coloured
//! lights and under an HDR sky, against the same views traced with exactly those lights.

mod common;

use std::path::{Path, PathBuf};

use common::{json_report, os, run};

const TRACE: &str = env!("CARGO_BIN_EXE_pis-trace");
const PACK: &str = env!("CARGO_BIN_EXE_pis-pack");
const BENCH: &str = env!("CARGO_BIN_EXE_pis-bench");

/// still-life's relight scene `name` (relight.toml, relight-two.toml, …) at 48×36, `spp`
/// samples a pixel, 2 views and, where it has the sun dimension and `suns` is given, that
/// many sun directions.
fn scene(dir: &Path, name: &str, suns: Option<u32>, spp: u32) -> PathBuf {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("../samples/wild/still-life");
    std::fs::create_dir_all(dir).unwrap();
    for e in std::fs::read_dir(&src).unwrap().filter_map(Result::ok) {
        std::fs::copy(e.path(), dir.join(e.file_name())).unwrap();
    }
    let mut text = std::fs::read_to_string(dir.join(name)).unwrap();
    let mut edits = vec![
        ("resolution = [160, 120]\nspp = 16", format!("resolution = [48, 36]\nspp = {spp}")),
        ("driver = \"orbit\"\nsamples = 4", "driver = \"orbit\"\nsamples = 2".to_string()),
    ];
    if let Some(n) = suns {
        edits.push(("light = \"Sun\"\nsamples = 64", format!("light = \"Sun\"\nsamples = {n}")));
    }
    for (from, to) in edits {
        assert!(text.contains(from), "{name} has no {from:?}: adapt the test");
        text = text.replace(from, &to);
    }
    let toml = dir.join(name);
    std::fs::write(&toml, text).unwrap();
    toml
}

fn trace(toml: &Path, out: &Path) {
    let o = run(TRACE, &[os(toml), os("-o"), os(out), os("--denoise"), os("off")], &[]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

fn pack(set: &Path, out: &Path, relight: &str) -> serde_json::Value {
    let args = [
        os(set),
        os("-o"),
        os(out),
        os("--codec"),
        os("lossless"),
        os("--relight"),
        os(relight),
        os("--json"),
    ];
    let o = run(PACK, &args, &[]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    json_report(&o)
}

/// pis-bench relight of the relightable file `on` and the sampled file `off` at `held`'s
/// points: each one's whole-image PSNR (dB), relit and at the nearest sampled direction.
fn relit_and_nearest(on: &Path, off: &Path, held: &Path) -> (f64, f64) {
    let args = [os("relight"), os(on), os(off), os("--held"), os(held), os("--json")];
    let o = run(BENCH, &args, &[]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let bench = json_report(&o);
    let played = bench["played"].as_array().unwrap();
    assert!(played[0]["relightable"] == true && played[1]["relightable"] == false);
    (played[0]["psnr_db"].as_f64().unwrap(), played[1]["psnr_db"].as_f64().unwrap())
}

#[test]
fn relit_textures_light_directions_between_the_samples_better_than_the_nearest_sample() {
    let dir = tempfile::tempdir().unwrap();
    let (set, held) = (dir.path().join("set"), dir.path().join("held"));
    trace(&scene(&dir.path().join("s"), "relight.toml", Some(24), 4), &set);
    trace(&scene(&dir.path().join("h"), "relight.toml", Some(7), 4), &held);
    let (on, off) = (dir.path().join("on.pis"), dir.path().join("off.pis"));
    let report = pack(&set, &on, "on");
    pack(&set, &off, "off");
    for o in report["objects"].as_array().unwrap() {
        let r = o["representation"].as_str().unwrap();
        assert!(r.contains("relightable over sun"), "{r}");
        assert!(o["why"].as_str().unwrap().contains("over the light: band"), "{o}");
    }
    // Played as the pack predicted it at the set's own points.
    let diff = json_report(&common::pis_diff(&on, &set, &["--json"]));
    assert!(diff["psnr_drop_db"].as_f64().unwrap().abs() < 0.05, "{diff}");
    // Between the samples: relit against the nearest sampled direction, whole image.
    let (relit, nearest) = relit_and_nearest(&on, &off, &held);
    println!("held-out directions: relit {relit:.2} dB, nearest sample {nearest:.2} dB");
    // Measured at this size: relit 19.06 dB, nearest 18.45 dB (at CI size with 64
    // directions the margin is 1.0 dB, docs/benchmarks/relight.md).
    assert!(relit > nearest + 0.3, "relit {relit:.2} dB, nearest sample {nearest:.2} dB");
    under_other_lights(dir.path(), &set, &on, &off);
}

/// relight-soft.toml: a sphere light as large as the scene, unseen by camera rays, turned
/// over its 64 directions (16 spp: its penumbrae are noisier than the sun's shadows). Its
/// soft shadows and wide highlights are what a few bands hold, so the relit file passes the
/// nearest sampled direction by far more than under the sun (0.6 dB at this size).
#[test]
fn a_light_as_large_as_the_scene_relights_far_better_than_the_nearest_sample() {
    let dir = tempfile::tempdir().unwrap();
    let (set, held) = (dir.path().join("set"), dir.path().join("held"));
    trace(&scene(&dir.path().join("s"), "relight-soft.toml", None, 16), &set);
    trace(&scene(&dir.path().join("h"), "relight-soft.toml", Some(7), 16), &held);
    let (on, off) = (dir.path().join("on.pis"), dir.path().join("off.pis"));
    pack(&set, &on, "on");
    pack(&set, &off, "off");
    let (relit, nearest) = relit_and_nearest(&on, &off, &held);
    println!("sphere light, held-out directions: relit {relit:.2} dB, nearest {nearest:.2} dB");
    // Measured at this size: relit 29.19 dB, nearest 25.79 dB (at CI size 32.48 and 25.41,
    // docs/benchmarks/relight.md).
    assert!(relit > nearest + 2.5, "relit {relit:.2} dB, nearest sample {nearest:.2} dB");
    // The same light placed from two directions in two colours (relight-soft-two.toml):
    // placed as the set's light (--fitted), relit by superposition.
    let two = dir.path().join("two");
    trace(&scene(&dir.path().join("t"), "relight-soft-two.toml", None, 16), &two);
    let args =
        [os("relight"), os(&on), os("--held"), os(&two), os("--fitted"), os(&set), os("--json")];
    let o = run(BENCH, &args, &[]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let relit = json_report(&o)["played"][0]["psnr_db"].as_f64().unwrap();
    println!("two coloured sphere lights: relit {relit:.2} dB");
    // Measured at this size: 31.96 dB (at CI size 36.84, docs/benchmarks/relight.md).
    assert!(relit >= 28.0, "two coloured sphere lights: relit {relit:.2} dB");
    // Without --fitted the lights cannot be placed: refused, saying how.
    let o = run(BENCH, &args[..5], &[]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success() && err.contains("--fitted"), "{err}");
}

/// The relit file under two coloured directional lights and under an HDR sky, against the
/// same views traced with exactly those lights (relight-two.toml, relight-sky.toml); the
/// file that samples the light cannot show them.
fn under_other_lights(dir: &Path, set: &Path, on: &Path, off: &Path) {
    // Measured at this size: two lights 25.46 dB (the fit's own ceiling at band 2: 27.5),
    // the sky 26.55 dB (28.7); at CI size 28.1 and 32.2 dB, docs/benchmarks/relight.md.
    for (toml, at_least) in [("relight-two.toml", 24.0), ("relight-sky.toml", 25.0)] {
        let reference = dir.join(toml.replace(".toml", ""));
        trace(&scene(&dir.join(format!("{toml}-scene")), toml, None, 4), &reference);
        let args = [
            os("relight"),
            os(on),
            os(off),
            os("--held"),
            os(&reference),
            os("--fitted"),
            os(set),
            os("--bands"),
            os("2"),
            os("--json"),
        ];
        let o = run(BENCH, &args, &[]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let bench = json_report(&o);
        let played = bench["played"].as_array().unwrap();
        let relit = played[0]["psnr_db"].as_f64().unwrap();
        let ceiling = bench["ceiling"][0]["held_out_db"].as_f64().unwrap();
        println!("{toml}: relit {relit:.2} dB, the fit's ceiling at band 2 {ceiling:.2} dB");
        assert!(relit >= at_least, "{toml}: relit {relit:.2} dB");
        assert!(played[1]["psnr_db"].is_null(), "{toml}: {}", played[1]);
    }
}
