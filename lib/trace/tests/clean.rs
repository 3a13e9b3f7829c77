//! Clean sets: adaptive sampling and denoised layers, measured against a converged render.

mod common;

use common::*;
use glam::Vec3;
use pis_scene::{Frame, ObjectRole, Scene};
use pis_trace::denoise::{denoise_point, prefer_denoised};
use pis_trace::layers::{LayerKind, PointImages};
use pis_trace::{render_point, PointRender, ShadingSeed, TraceSettings};

/// A matte floor and back wall, a mirror ball and a glass ball, lit by a small sphere.
fn room(res: (u32, u32), spp: u32) -> (Scene, Frame) {
    let s = scene(
        vec![
            object(
                "floor",
                ObjectRole::Diffuse,
                vec![quad(Vec3::new(-2.0, 0.0, -2.0), Vec3::Z * 4.0, Vec3::X * 4.0, 0)],
            ),
            object(
                "wall",
                ObjectRole::Diffuse,
                vec![quad(Vec3::new(-2.0, 0.0, -1.5), Vec3::X * 4.0, Vec3::Y * 3.0, 1)],
            ),
            object(
                "ball",
                ObjectRole::Reflective,
                vec![sphere(Vec3::new(-0.5, 0.5, 0.0), 0.5, 12, 24, 2, false)],
            ),
        ],
        vec![matte([0.7, 0.6, 0.5]), matte([0.3, 0.5, 0.7]), metal([0.9, 0.8, 0.6], 0.0)],
        res,
        spp,
    );
    let f = frame(
        &s,
        camera(Vec3::new(0.3, 1.3, 3.2), Vec3::new(0.0, 0.5, 0.0), 45.0),
        vec![sphere_light("key", Vec3::new(1.0, 2.5, 1.5), [12.0; 3], 0.2)],
    );
    (s, f)
}

fn render(s: &Scene, f: &Frame, settings: &TraceSettings, threads: usize) -> PointRender {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("a pool");
    pool.install(|| render_point(s, f, settings, &|| {})).expect("renders")
}

#[test]
fn an_adaptive_render_is_the_same_on_any_thread_count_and_stops_only_converged_pixels() {
    let (s, f) = room((24, 16), 16);
    let adaptive = TraceSettings::new(s.resolution, 16).with_adaptive(0.05, 2);
    let one = render(&s, &f, &adaptive, 1);
    let two = render(&s, &f, &adaptive, 2);
    assert_eq!(one.images, two.images, "the same images on 1 and 2 threads");
    let [samples, error] = one.sampling.clone().expect("adaptive renders map their samples");
    assert_eq!(Some([samples.clone(), error.clone()]), two.sampling);
    let counts = &samples.planes[0];
    let stopped = counts.iter().filter(|&&n| n < 16.0).count();
    assert!(
        stopped > 0 && stopped < counts.len(),
        "{stopped} of {} pixels stopped early",
        counts.len()
    );
    for (i, (&n, &e)) in counts.iter().zip(&error.planes[0]).enumerate() {
        assert!(n >= 2.0 && (n == 16.0 || e < 0.05), "pixel {i}: {n} samples, error {e}");
    }
    let fixed = render(&s, &f, &TraceSettings::new(s.resolution, 16), 2);
    assert!(fixed.sampling.is_none(), "a fixed render maps no samples");
}

/// Mean squared display error of `layer` × coverage between two points' images, over the
/// pixels `reference` covers.
fn layer_error(image: &PointImages, reference: &PointImages, object: &str, kind: LayerKind) -> f64 {
    let cov =
        |i: &PointImages| i.object_layer(object, LayerKind::Coverage).map(|l| l.planes[0].clone());
    let (Some(ca), Some(cb)) = (cov(image), cov(reference)) else { return 0.0 };
    let (a, b) =
        (image.object_layer(object, kind).unwrap(), reference.object_layer(object, kind).unwrap());
    let (mut sum, mut n) = (0.0, 0usize);
    for i in (0..cb.len()).filter(|&i| cb[i] > 0.0) {
        for c in 0..3 {
            let d =
                (a.planes[c][i] * ca[i]).clamp(0.0, 1.0) - (b.planes[c][i] * cb[i]).clamp(0.0, 1.0);
            sum += (d * d) as f64;
        }
        n += 1;
    }
    sum / n.max(1) as f64
}

#[test]
fn denoised_layers_are_closer_to_the_converged_image_than_the_raw_ones() {
    let test = "denoised_layers_are_closer_to_the_converged_image_than_the_raw_ones";
    let Some(oidn) = pis_trace::oidn::shared_or_skip(test) else { return };
    let (s, f) = room((64, 48), 4);
    let mut noisy = TraceSettings::new(s.resolution, 4);
    noisy.denoise = true;
    let raw = render(&s, &f, &noisy, 2);
    let converged = TraceSettings::new(s.resolution, 256).with_shading_seed(ShadingSeed::Sample);
    let reference = render(&s, &f, &converged, 2).images;
    let objects: Vec<(String, ObjectRole)> =
        s.objects.iter().map(|o| (o.name.clone(), o.role)).collect();
    let input = raw.denoise_input.as_ref().expect("a denoising render keeps its halves");
    let out = denoise_point(oidn, &raw.images, input, &objects).expect("denoises");
    let mut denoised = raw.images.clone();
    denoised.layers.extend(out.images.clone());
    prefer_denoised(&mut denoised);
    let mut improved = 0;
    for (name, kind) in
        [("floor", LayerKind::Diffuse), ("wall", LayerKind::Diffuse), ("ball", LayerKind::Distant)]
    {
        let before = layer_error(&raw.images, &reference, name, kind);
        let after = layer_error(&denoised, &reference, name, kind);
        let db = 10.0 * (before / after).log10();
        eprintln!("{name} {}: {db:+.2} dB", kind.name());
        if out.summary.kept_raw.contains(&pis_trace::layers::object_layer_name(name, kind)) {
            assert_eq!(before, after, "{name} kept raw reads raw");
        } else {
            assert!(
                after < before,
                "{name} {}: denoised {after:e} against raw {before:e}",
                kind.name()
            );
            improved += 1;
        }
    }
    assert!(improved >= 2, "kept raw: {:?}", out.summary.kept_raw);
    assert!(out.summary.layers.contains(&"combined".to_string()));
}
