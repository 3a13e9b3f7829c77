//! A denoised set joined from two halves rendered apart (`pis-trace denoise`), as a renderer
//! that cannot keep its even and odd samples apart delivers them.

mod common;

use common::*;
use pis_scene::{Frame, Scene};
use pis_trace::layers::{LayerKind, PointImages};
use pis_trace::set::{denoise_halves, RaySet, SetWriter};
use pis_trace::{render_point, ShadingSeed, TraceError, TraceSettings};
use std::path::Path;

const RES: (u32, u32) = (64, 48);

/// Writes one half of the room: `spp` samples from sample stream `seed`, with the guides
/// and without denoised twins (a raw render).
fn write_half(dir: &Path, s: &Scene, f: &Frame, spp: u32, seed: u64) {
    let mut settings = TraceSettings::new(s.resolution, spp)
        .with_shading_seed(ShadingSeed::Sample)
        .with_seed(seed);
    settings.denoise = true;
    let mut r = render_point(s, f, &settings, &|| {}).expect("renders");
    let input = r.denoise_input.take().expect("a denoising render makes guides");
    r.images.layers.extend(input.guides);
    settings.denoise = false;
    let mut writer = SetWriter::create(dir, s, &settings).expect("a set");
    writer.write_point(s, 0, f, &r).expect("writes");
    writer.finish().expect("set.json");
}

fn combined(images: &PointImages) -> &[Vec<f32>] {
    &images.layer("combined").expect("combined").planes
}

#[test]
fn two_halves_join_into_their_mean_with_twins_nearer_the_converged_image() {
    let test = "two_halves_join_into_their_mean_with_twins_nearer_the_converged_image";
    if pis_trace::oidn::shared_or_skip(test).is_none() {
        return;
    }
    let (s, f) = room(RES, 2);
    let tmp = tempfile::tempdir().expect("a folder");
    let [even, odd, out] = ["even", "odd", "out"].map(|n| tmp.path().join(n));
    write_half(&even, &s, &f, 1, 1);
    write_half(&odd, &s, &f, 1, 2);
    let report = denoise_halves(&even, &odd, &out, &|_, _| {}).expect("joins");
    assert_eq!((report.points, report.spp), (1, 2));

    let joined = RaySet::open(&out).expect("a set");
    assert_eq!(joined.meta.spp, 2);
    assert!(joined.meta.denoiser.is_some() && joined.is_denoised());
    let halves = [&even, &odd].map(|d| RaySet::open(d).unwrap().read_point(0).unwrap());
    let raw = joined.clone().with_raw(true).read_point(0).expect("raw layers");
    for (c, plane) in combined(&raw).iter().enumerate() {
        for (i, &v) in plane.iter().enumerate() {
            let mean = 0.5 * (combined(&halves[0])[c][i] + combined(&halves[1])[c][i]);
            assert_eq!(v, mean, "raw combined channel {c} pixel {i} is the halves' mean");
        }
    }
    assert!(raw.layer("guide.albedo").is_some() && raw.layer("guide.normal").is_some());
    // An object's layer joins premultiplied: coverage × value is the halves' mean of it.
    let premultiplied = |im: &PointImages, i: usize| {
        let cov = im.object_layer("floor", LayerKind::Coverage).expect("coverage").planes[0][i];
        cov * im.object_layer("floor", LayerKind::Diffuse).expect("diffuse").planes[1][i]
    };
    for i in 0..(RES.0 * RES.1) as usize {
        let mean = 0.5 * (premultiplied(&halves[0], i) + premultiplied(&halves[1], i));
        let joined = premultiplied(&raw, i);
        assert!(
            (joined - mean).abs() <= 1e-5 * mean.abs().max(1.0),
            "pixel {i}: {joined} against {mean}"
        );
    }

    let converged = TraceSettings::new(s.resolution, 256).with_shading_seed(ShadingSeed::Sample);
    let reference = render_point(&s, &f, &converged, &|| {}).expect("renders").images;
    let denoised = joined.read_point(0).expect("denoised layers");
    for name in ["floor", "wall"] {
        let before = layer_error(&raw, &reference, name, LayerKind::Diffuse);
        let after = layer_error(&denoised, &reference, name, LayerKind::Diffuse);
        let db = 10.0 * (before / after).log10();
        eprintln!("{name} diffuse against 256 spp: {db:+.2} dB denoised");
        assert!(db > 3.0, "{name}: denoised {after:e} against raw {before:e}");
    }
}

#[test]
fn halves_that_are_not_one_set_are_refused_with_the_reason() {
    let test = "halves_that_are_not_one_set_are_refused_with_the_reason";
    if pis_trace::oidn::shared_or_skip(test).is_none() {
        return;
    }
    let (s, f) = room((16, 12), 2);
    let tmp = tempfile::tempdir().expect("a folder");
    let [even, odd, moved, out] = ["even", "odd", "moved", "out"].map(|n| tmp.path().join(n));
    write_half(&even, &s, &f, 2, 1);
    write_half(&odd, &s, &f, 2, 2);
    let mut other = f.clone();
    other.camera.world_from_camera.w_axis.x += 0.1;
    write_half(&moved, &s, &other, 2, 2);

    let err = denoise_halves(&even, &moved, &out, &|_, _| {}).unwrap_err();
    assert!(err.to_string().contains("camera differs"), "{err}");
    let err = denoise_halves(&even, &odd, &even, &|_, _| {}).unwrap_err();
    assert!(matches!(err, TraceError::InvalidInput(_)), "{err}");
    assert!(!out.join("set.json").exists(), "nothing written as a set");

    let joined = denoise_halves(&even, &odd, &out, &|_, _| {}).expect("joins");
    let again = denoise_halves(&out, &odd, &tmp.path().join("twice"), &|_, _| {}).unwrap_err();
    assert!(again.to_string().contains("denoised already"), "{again} ({joined:?})");
}
