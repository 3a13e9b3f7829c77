//! The environment light in the tracer: a uniform sky (white furnace), an equirectangular
//! image lighting the side that faces its bright half, the sky in reflections (distant
//! layer) and probes, camera rays seeing it only as a `background`, and determinism.
//!
//! Tolerances come from the sample counts: one irradiance estimate at a diffuse point is a
//! next-event sample of the environment plus the diffuse lobe's ray, each contributing
//! L · p / (p_env + p) ∈ [0, L] with the balance heuristic, so the estimate lies in [0, 2L]
//! and its standard deviation is at most L. A pixel averages spp × diffuse_samples
//! independent estimates (coherence off); checks allow 4 standard deviations.

mod common;

use std::sync::Arc;

use common::*;
use glam::{Vec2, Vec3};
use pis_scene::{Environment, EnvironmentRadiance, LatLongImage, ObjectRole, Scene};
use pis_trace::camera::PerspectiveCamera;
use pis_trace::probe::{incident_radiance, Footprint};
use pis_trace::{render_point, LayerKind, PointRender, TraceSettings};

fn render(scene: &Scene, frame: &pis_scene::Frame, settings: &TraceSettings) -> PointRender {
    render_point(scene, frame, settings, &|| {}).expect("render")
}

fn uniform(l: f32, background: bool) -> Environment {
    Environment { radiance: EnvironmentRadiance::Uniform([l; 3]), rotation: 0.0, background }
}

/// A lat-long environment of `w × h` texels, `texel(column, row)` each, row 0 at the top.
fn lat_long(
    w: u32,
    h: u32,
    texel: impl Fn(u32, u32) -> [f32; 3],
    rotation_deg: f32,
    background: bool,
) -> Environment {
    let texels =
        (0..h).flat_map(|j| (0..w).map(move |i| (i, j))).map(|(i, j)| texel(i, j)).collect();
    let image = LatLongImage::new("sky.exr".into(), w, h, texels);
    Environment {
        radiance: EnvironmentRadiance::Image(Arc::new(image)),
        rotation: rotation_deg.to_radians(),
        background,
    }
}

/// Settings with independent estimates per camera sample (coherence off).
fn independent(s: &Scene, diffuse_samples: u32) -> TraceSettings {
    let mut settings = TraceSettings::new(s.resolution, s.spp);
    settings.diffuse_samples = diffuse_samples;
    settings.coherence_cell = Some(0.0);
    settings
}

/// The unit normal where the ray through the centre of pixel (x, y) meets the unit sphere
/// at the origin, if it does at a fairly frontal angle (|n·v| > 0.5: the pixel's footprint
/// stays on the ball and the normal varies nearly linearly over it).
fn ball_normal(cam: &PerspectiveCamera, x: u32, y: u32) -> Option<Vec3> {
    let d = cam.direction(Vec2::new(x as f32 + 0.5, y as f32 + 0.5));
    let o = cam.origin;
    let b = o.dot(d);
    let disc = b * b - (o.length_squared() - 1.0);
    if disc <= 0.0 {
        return None;
    }
    let n = (o + d * (-b - disc.sqrt())).normalize();
    (n.dot(-d) > 0.5).then_some(n)
}

/// A closed convex diffuse ball of albedo a under a uniform sky L sees only the sky: its
/// radiance is a·L, with one bounce (white furnace). Background pixels are black unless the
/// environment is the background, then they are L.
#[test]
fn a_ball_under_a_uniform_sky_has_its_albedo_times_the_sky() {
    let l = 0.7;
    for albedo in [1.0f32, 0.5] {
        let mut s = scene(
            vec![object(
                "ball",
                ObjectRole::Diffuse,
                vec![sphere(Vec3::ZERO, 1.0, 24, 48, 0, false)],
            )],
            vec![matte([albedo; 3])],
            (24, 24),
            8,
        );
        s.environment = Some(uniform(l, false));
        let f = frame(&s, camera(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, 45.0), vec![]);
        let settings = independent(&s, 16);
        let r = render(&s, &f, &settings);
        let cov = r.images.object_layer("ball", LayerKind::Coverage).unwrap();
        let diffuse = r.images.object_layer("ball", LayerKind::Diffuse).unwrap();
        let combined = r.images.layer("combined").unwrap();
        let expect = albedo * l;
        let per_pixel = (settings.spp * settings.diffuse_samples) as f32;
        let pixel_tolerance = 4.0 * expect / per_pixel.sqrt();
        let (mut n, mut sum) = (0u32, 0.0f64);
        for y in 0..24 {
            for x in 0..24 {
                let c = cov.value("A", x, y);
                if c == 0.0 {
                    assert_eq!(combined.rgb(x, y), Vec3::ZERO, "background ({x},{y}) is black");
                }
                if c < 1.0 {
                    continue;
                }
                let (v, d) = (combined.rgb(x, y), diffuse.rgb(x, y));
                assert!(
                    (v - d).abs().max_element() < 1e-5,
                    "({x},{y}): combined {v} is the diffuse layer {d}"
                );
                assert!(
                    (v - Vec3::splat(expect)).abs().max_element() <= pixel_tolerance,
                    "pixel ({x},{y}): {v} vs {expect} ± {pixel_tolerance}"
                );
                n += 1;
                sum += v.x as f64;
            }
        }
        assert!(n > 150, "only {n} fully covered pixels");
        let mean = sum / n as f64;
        let tolerance = 4.0 * expect as f64 / (per_pixel as f64 * n as f64).sqrt();
        assert!(
            (mean - expect as f64).abs() <= tolerance,
            "albedo {albedo}: mean {mean} vs {expect} ± {tolerance}"
        );

        s.environment = Some(uniform(l, true));
        let r = render(&s, &f, &settings);
        let corner = r.images.layer("combined").unwrap().rgb(0, 0);
        assert!(
            (corner - Vec3::splat(l)).abs().max_element() < 1e-6,
            "the sky as background: {corner}"
        );
        assert_eq!(
            r.images.object_layer("ball", LayerKind::Coverage).unwrap().value("A", 0, 0),
            0.0
        );
    }
}

/// An image bright (L) where x > 0 (u ∈ [¼, ¾)) and black elsewhere lights a diffuse ball
/// of albedo a with a·L·(1 + n·x̂)/2 (irradiance of a hemisphere light, E = πL(1 + cos α)/2):
/// the side facing +X lit, the side facing −X dark.
#[test]
fn an_image_bright_towards_plus_x_lights_the_side_of_the_ball_facing_it() {
    let (l, albedo) = (2.0f32, 0.8f32);
    let mut s = scene(
        vec![object("ball", ObjectRole::Diffuse, vec![sphere(Vec3::ZERO, 1.0, 48, 96, 0, false)])],
        vec![matte([albedo; 3])],
        (32, 32),
        8,
    );
    s.environment = Some(lat_long(
        64,
        32,
        |i, _| if (16..48).contains(&i) { [l; 3] } else { [0.0; 3] },
        0.0,
        false,
    ));
    let f = frame(&s, camera(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, 45.0), vec![]);
    let settings = independent(&s, 16);
    let r = render(&s, &f, &settings);
    let cam = PerspectiveCamera::new(&f.camera, s.resolution);
    let cov = r.images.object_layer("ball", LayerKind::Coverage).unwrap();
    let combined = r.images.layer("combined").unwrap();
    let per_pixel = (settings.spp * settings.diffuse_samples) as f32;
    // Statistics (4σ) plus 1 % of a·L for the geometry: flat facets, the shading normals
    // differing from them, and the pixel-centre normal standing for the filtered footprint.
    let geometry = 0.01 * albedo * l;
    let pixel_tolerance = 4.0 * albedo * l / per_pixel.sqrt() + geometry;
    let mut halves = [(0u32, 0.0f64, 0.0f64); 2];
    for y in 0..32 {
        for x in 0..32 {
            let Some(n) = ball_normal(&cam, x, y).filter(|_| cov.value("A", x, y) >= 1.0) else {
                continue;
            };
            let expect = albedo * l * (1.0 + n.x) / 2.0;
            let v = combined.rgb(x, y).x;
            assert!(
                (v - expect).abs() <= pixel_tolerance,
                "pixel ({x},{y}), normal {n}: {v} vs {expect} ± {pixel_tolerance}"
            );
            let h = &mut halves[usize::from(n.x > 0.0)];
            *h = (h.0 + 1, h.1 + v as f64, h.2 + expect as f64);
        }
    }
    for (side, (n, measured, expected)) in ["−X", "+X"].iter().zip(halves) {
        assert!(n > 100, "{side}: only {n} pixels");
        let tolerance =
            4.0 * (albedo * l) as f64 / (per_pixel as f64 * n as f64).sqrt() + geometry as f64;
        let (m, e) = (measured / n as f64, expected / n as f64);
        assert!((m - e).abs() <= tolerance, "{side} half: mean {m} vs {e} ± {tolerance}");
    }
    let mean = |(n, m, e): (u32, f64, f64)| (m / n as f64, e / n as f64);
    let ((lit, lit_expected), (dark, dark_expected)) = (mean(halves[1]), mean(halves[0]));
    assert!(
        lit - dark > 0.5 * (lit_expected - dark_expected),
        "the +X side is the lit one: {halves:?}"
    );
}

/// A mirror ball under a sky that is A above the horizon and B below: its distant layer
/// holds A where the reflected ray goes up and B where it goes down; camera rays that miss
/// the ball are black, or the sky with `background`.
#[test]
fn reflections_and_the_background_see_the_sky() {
    let (a, b) = (Vec3::new(0.2, 0.4, 0.9), Vec3::new(0.5, 0.3, 0.1));
    let sky = |background| {
        lat_long(8, 4, move |_, j| if j < 2 { a.to_array() } else { b.to_array() }, 0.0, background)
    };
    let mut s = scene(
        vec![object(
            "ball",
            ObjectRole::Reflective,
            vec![sphere(Vec3::ZERO, 1.0, 48, 96, 0, false)],
        )],
        vec![metal([1.0; 3], 0.0)],
        (32, 32),
        4,
    );
    s.environment = Some(sky(false));
    let f = frame(&s, camera(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, 45.0), vec![]);
    let settings = TraceSettings::new(s.resolution, s.spp);
    let r = render(&s, &f, &settings);
    let cam = PerspectiveCamera::new(&f.camera, s.resolution);
    let cov = r.images.object_layer("ball", LayerKind::Coverage).unwrap();
    let distant = r.images.object_layer("ball", LayerKind::Distant).unwrap();
    let combined = r.images.layer("combined").unwrap();
    // The reflected direction's height at the pixel centre and ± the filter radius: all of a
    // pixel's samples reflect to the same side of the horizon when all five agree.
    let reflected_y = |x: f32, y: f32| {
        let d = cam.direction(Vec2::new(x, y));
        let (o, bb) = (cam.origin, cam.origin.dot(d));
        let disc = bb * bb - (o.length_squared() - 1.0);
        (disc > 0.0).then(|| {
            let n = (o + d * (-bb - disc.sqrt())).normalize();
            (d - n * (2.0 * d.dot(n))).y
        })
    };
    let (mut up, mut down) = (0, 0);
    for y in 0..32 {
        for x in 0..32 {
            if cov.value("A", x, y) < 1.0 {
                if cov.value("A", x, y) == 0.0 {
                    assert_eq!(combined.rgb(x, y), Vec3::ZERO, "background ({x},{y})");
                }
                continue;
            }
            let (cx, cy) = (x as f32 + 0.5, y as f32 + 0.5);
            let ys: Option<Vec<f32>> =
                [(0.0, 0.0), (1.5, 0.0), (-1.5, 0.0), (0.0, 1.5), (0.0, -1.5)]
                    .iter()
                    .map(|(dx, dy)| reflected_y(cx + dx, cy + dy))
                    .collect();
            let Some(ys) = ys else { continue };
            let expect = if ys.iter().all(|&y| y > 0.05) {
                up += 1;
                a
            } else if ys.iter().all(|&y| y < -0.05) {
                down += 1;
                b
            } else {
                continue;
            };
            let d = distant.rgb(x, y);
            assert!((d - expect).abs().max_element() < 1e-4, "distant ({x},{y}): {d} vs {expect}");
        }
    }
    assert!(up > 50 && down > 50, "{up} pixels reflect the sky above, {down} below");

    s.environment = Some(sky(true));
    let r = render(&s, &f, &settings);
    let combined = r.images.layer("combined").unwrap();
    // The top and bottom rows look above and below the horizon, past the ball.
    assert!((combined.rgb(0, 0) - a).abs().max_element() < 1e-6, "{}", combined.rgb(0, 0));
    assert!((combined.rgb(31, 31) - b).abs().max_element() < 1e-6, "{}", combined.rgb(31, 31));
}

/// Probes (the static environment map's texels) see the image where their rays leave the
/// scene, texel by texel in the documented directions, turned by `rotation_deg`.
#[test]
fn probes_see_the_image_in_the_documented_directions() {
    // 4 × 2 texels, each its own colour.
    let colour = |i: u32, j: u32| [1.0 + i as f32, 10.0 * (j + 1) as f32, 0.5];
    // A speck far below, so that the scene has geometry; no probe looks at it.
    let mut s = scene(
        vec![object(
            "speck",
            ObjectRole::Diffuse,
            vec![quad(Vec3::new(0.0, -100.0, 0.0), Vec3::X * 0.01, Vec3::Z * 0.01, 0)],
        )],
        vec![matte([0.5; 3])],
        (1, 1),
        4,
    );
    let f = frame(&s, camera(Vec3::ZERO, Vec3::NEG_Z, 45.0), vec![]);
    let settings = TraceSettings::new((1, 1), 4);
    // Texel (i, j)'s centre: u = (i + ½)/4, v = (j + ½)/2, i.e. azimuth from +X towards +Z
    // of 2π(u − ½) and 45° above (j = 0) or below (j = 1) the horizon.
    let centre = |i: u32, j: u32| {
        let phi = 2.0 * std::f32::consts::PI * ((i as f32 + 0.5) / 4.0 - 0.5);
        let y = if j == 0 { 1.0 } else { -1.0 };
        Vec3::new(phi.cos(), y, phi.sin()).normalize()
    };
    for rotation in [0.0f32, 90.0] {
        s.environment = Some(lat_long(4, 2, colour, rotation, false));
        let turn = glam::Quat::from_rotation_y(rotation.to_radians());
        let texels: Vec<(u32, u32)> = (0..2).flat_map(|j| (0..4).map(move |i| (i, j))).collect();
        let footprints: Vec<Footprint> = texels
            .iter()
            .map(|&(i, j)| {
                let c = turn * centre(i, j);
                let u = c.any_orthonormal_vector();
                Footprint { centre: c, half_u: u * 0.05, half_v: c.cross(u) * 0.05 }
            })
            .collect();
        let seen = incident_radiance(&s, &f, &settings, Vec3::ZERO, &footprints, None).unwrap();
        for (&(i, j), l) in texels.iter().zip(&seen) {
            assert_eq!(*l, Vec3::from(colour(i, j)), "texel ({i},{j}) at rotation {rotation}°");
        }
    }
    // The documented landmarks: the image centre is +X, a quarter right of it +Z.
    s.environment = Some(lat_long(4, 2, colour, 0.0, false));
    let at = |d: Vec3| {
        let u = d.any_orthonormal_vector();
        incident_radiance(
            &s,
            &f,
            &settings,
            Vec3::ZERO,
            &[Footprint { centre: d, half_u: u * 0.01, half_v: d.cross(u) * 0.01 }],
            None,
        )
        .unwrap()[0]
    };
    assert_eq!(
        at(Vec3::new(1.0, 0.2, 0.1).normalize()),
        Vec3::from(colour(2, 0)),
        "+X, just above the horizon: u just past ½"
    );
    assert_eq!(
        at(Vec3::new(0.1, 0.2, 1.0).normalize()),
        Vec3::from(colour(2, 0)),
        "+Z: u just below ¾"
    );
    assert_eq!(
        at(Vec3::new(-0.1, 0.2, 1.0).normalize()),
        Vec3::from(colour(3, 0)),
        "+Z turned towards −X: u past ¾"
    );
}

/// An image environment renders byte-identically on one thread and on two.
#[test]
fn environment_renders_are_deterministic_across_thread_counts() {
    let mut s = scene(
        vec![
            object(
                "floor",
                ObjectRole::Diffuse,
                vec![quad(Vec3::ZERO, Vec3::Z * 3.0, Vec3::X * 3.0, 0)],
            ),
            object(
                "ball",
                ObjectRole::Reflective,
                vec![sphere(Vec3::new(-0.4, 0.5, 0.0), 0.5, 10, 20, 1, false)],
            ),
        ],
        vec![matte([0.7, 0.6, 0.5]), metal([0.9, 0.8, 0.6], 0.3)],
        (16, 12),
        4,
    );
    s.environment = Some(lat_long(
        32,
        16,
        |i, j| [0.1 + i as f32 * 0.05, 0.2 + j as f32 * 0.1, 0.3],
        20.0,
        true,
    ));
    let f = frame(&s, camera(Vec3::new(0.0, 1.2, 3.0), Vec3::new(0.0, 0.4, 0.0), 50.0), vec![]);
    let settings = TraceSettings::new(s.resolution, s.spp);
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| render(&s, &f, &settings))
    };
    let bytes = |r: &PointRender| {
        pis_trace::set::encode_exr(&r.images, std::path::Path::new("x.exr")).unwrap()
    };
    assert_eq!(bytes(&run(1)), bytes(&run(2)));
}
