//! Clean sets: adaptive sampling and denoised layers, measured against a converged render.

mod common;

use common::*;
use pis_scene::{Frame, ObjectRole, Scene};
use pis_trace::denoise::{denoise_point, prefer_denoised};
use pis_trace::layers::LayerKind;
use pis_trace::{render_point, PointRender, ShadingSeed, TraceSettings};

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
