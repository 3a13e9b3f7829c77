//! The checked-in sample scenes load with pis-scene, evaluate at every parameter point, and
//! are exactly what the generator writes.

use std::path::{Path, PathBuf};

use glam::Vec3;
use pis_scene::material::{material_role, MIRROR_ROUGHNESS};
use pis_scene::{load, DimensionKind, Driver, ObjectRole, Scene};

fn samples_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The point each scene's camera must look at (the table, or the teapot's platform).
fn target(scene: &Scene) -> Vec3 {
    scene
        .space
        .dims
        .iter()
        .find_map(|d| match d.driver {
            Driver::Orbit { target, .. } => Some(target),
            _ => None,
        })
        .expect("every sample has an orbit dimension")
}

fn check(scene: &Scene) {
    for object in &scene.objects {
        let triangles: usize = object.primitives.iter().map(|p| p.indices.len() / 3).sum();
        assert!(triangles > 0, "{}: object {} has no triangles", scene.name, object.name);
        for p in &object.primitives {
            assert!(p.positions.iter().all(|v| v.is_finite()));
            assert!(p.normals.iter().all(|n| (n.length() - 1.0).abs() < 1e-3));
        }
    }
    let target = target(scene);
    for index in 0..scene.space.point_count() {
        let frame = scene.frame_at(index).expect("frame");
        let m = frame.camera.world_from_camera;
        assert!(m.is_finite(), "{} point {index}: camera not finite", scene.name);
        let eye = m.transform_point3(Vec3::ZERO);
        let forward = m.transform_vector3(Vec3::NEG_Z).normalize();
        // The view ray passes within 5 cm of the target, in front of the camera.
        let to_target = target - eye;
        let along = to_target.dot(forward);
        assert!(along > 0.5, "{} point {index}: target behind the camera", scene.name);
        assert!(
            (to_target - forward * along).length() < 0.05,
            "{} point {index}: camera misses the target",
            scene.name
        );
        assert_eq!(frame.instances.len(), scene.objects.len());
        assert!(frame.instances.iter().all(|i| i.world_from_object.is_finite()));
        assert!(!frame.lights.is_empty(), "{}: no light", scene.name);
        for l in &frame.lights {
            assert!(l.position.is_finite() && l.radius > 0.0);
        }
    }
}

#[test]
fn every_sample_loads_and_evaluates_at_every_point() {
    for name in pis_samples::SAMPLES {
        let toml = samples_dir().join(name).join("scene.toml");
        let ci = load(&toml, None).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(ci.name, name);
        assert_eq!(ci.resolution, (160, 120));
        assert!(ci.space.point_count() <= 16);
        check(&ci);
        let paper = load(&toml, Some("paper")).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(paper.resolution, (640, 480));
        let expected = if paper.space.dims.len() == 2 { 64 } else { 8 };
        assert_eq!(paper.space.point_count(), expected, "{name}");
        check(&paper);
    }
}

#[test]
fn demo_spaces_have_the_seed_kinds() {
    let kinds = |name: &str| -> Vec<DimensionKind> {
        let s = load(&samples_dir().join(name).join("scene.toml"), None).unwrap();
        s.space.dims.iter().map(|d| d.kind).collect()
    };
    assert_eq!(kinds("demo1"), [DimensionKind::Light, DimensionKind::View]);
    assert_eq!(kinds("demo2"), [DimensionKind::View, DimensionKind::ObjectMotion]);
    assert_eq!(kinds("teapot-pem"), [DimensionKind::View]);
    assert_eq!(kinds("teapot-glossy"), [DimensionKind::View]);
    assert_eq!(kinds("glass"), [DimensionKind::View]);
}

#[test]
fn demo1_light_swings_and_demo2_gewgaw_turns() {
    let s = load(&samples_dir().join("demo1/scene.toml"), Some("paper")).unwrap();
    let first = s.frame(&[0, 0]).unwrap().lights[0].position;
    let last = s.frame(&[7, 0]).unwrap().lights[0].position;
    // Pendulum pivot (0, 2.2, 0), arm 0.5: ±60° puts the light at x = ∓0.433, y = 1.95.
    assert!(
        first.distance(Vec3::new(0.5 * 60f32.to_radians().sin(), 2.2 - 0.25, 0.0)) < 1e-4,
        "{first}"
    );
    assert!(
        last.distance(Vec3::new(-0.5 * 60f32.to_radians().sin(), 2.2 - 0.25, 0.0)) < 1e-4,
        "{last}"
    );

    let s = load(&samples_dir().join("demo2/scene.toml"), Some("paper")).unwrap();
    let gewgaw = s.objects.iter().position(|o| o.name == "Gewgaw").unwrap();
    let a = s.frame(&[0, 0]).unwrap().instances[gewgaw].world_from_object;
    let b = s.frame(&[0, 1]).unwrap().instances[gewgaw].world_from_object;
    let (_, ra, _) = a.to_scale_rotation_translation();
    let (_, rb, _) = b.to_scale_rotation_translation();
    let turned = (ra.inverse() * rb).to_axis_angle().1.to_degrees();
    assert!((turned - 7.5).abs() < 1e-2, "{turned}");
}

#[test]
fn teapot_glossy_is_teapot_pem_with_a_glossy_reflective_teapot() {
    for preset in [None, Some("paper")] {
        let pem = load(&samples_dir().join("teapot-pem/scene.toml"), preset).unwrap();
        let glossy = load(&samples_dir().join("teapot-glossy/scene.toml"), preset).unwrap();
        assert_eq!(glossy.resolution, pem.resolution);
        assert_eq!(glossy.spp, pem.spp);
        assert_eq!(glossy.space.point_count(), pem.space.point_count());
        let names = |s: &Scene| s.objects.iter().map(|o| o.name.clone()).collect::<Vec<_>>();
        assert_eq!(names(&glossy), names(&pem));
        for (g, p) in glossy.objects.iter().zip(&pem.objects) {
            assert_eq!(g.role, p.role, "{}", g.name);
            assert_eq!(g.primitives.len(), p.primitives.len());
            for (gp, pp) in g.primitives.iter().zip(&p.primitives) {
                assert_eq!(gp.positions, pp.positions, "{}", g.name);
                assert_eq!(gp.indices, pp.indices, "{}", g.name);
                let (gm, pm) = (&glossy.materials[gp.material], &pem.materials[pp.material]);
                if g.name.starts_with("Teapot") {
                    assert_eq!(g.role, ObjectRole::Reflective);
                    assert_eq!(gm.base_color, pm.base_color);
                    assert_eq!(gm.metallic, 1.0);
                    assert!(pm.roughness < MIRROR_ROUGHNESS, "teapot-pem's teapot is a mirror");
                    // Glossy, not a mirror, yet still inferred reflective.
                    assert!(gm.roughness > MIRROR_ROUGHNESS, "{}", gm.roughness);
                    assert_eq!(material_role(gm), ObjectRole::Reflective);
                } else {
                    assert_eq!(gm.name, pm.name);
                    assert_eq!(gm.roughness, pm.roughness);
                }
            }
        }
        for index in 0..pem.space.point_count() {
            let (g, p) = (glossy.frame_at(index).unwrap(), pem.frame_at(index).unwrap());
            assert_eq!(g.camera.world_from_camera, p.camera.world_from_camera);
            assert_eq!(g.lights.len(), p.lights.len());
        }
    }
}

/// Numbers equal up to float rounding (sin/cos come from the platform's libm, so another
/// platform may differ in the last bit; on one platform the output is byte-identical).
fn close(a: f64, b: f64) -> bool {
    a == b || (a - b).abs() <= 1e-5 * a.abs().max(b.abs()).max(1.0)
}

fn same_json(a: &serde_json::Value, b: &serde_json::Value) -> bool {
    use serde_json::Value::*;
    match (a, b) {
        (Number(x), Number(y)) => {
            close(x.as_f64().unwrap_or(f64::NAN), y.as_f64().unwrap_or(f64::NAN))
        }
        (Array(x), Array(y)) => x.len() == y.len() && x.iter().zip(y).all(|(x, y)| same_json(x, y)),
        (Object(x), Object(y)) => {
            x.len() == y.len() && x.iter().all(|(k, v)| y.get(k).is_some_and(|w| same_json(v, w)))
        }
        _ => a == b,
    }
}

/// Binary buffers hold little-endian f32 and u16/u32 indices, all 4-byte aligned; compare
/// word by word, as floats where the words differ.
fn same_bin(a: &[u8], b: &[u8]) -> bool {
    a.len() == b.len()
        && a.chunks(4).zip(b.chunks(4)).all(|(x, y)| {
            x == y || {
                let f = |w: &[u8]| f32::from_le_bytes([w[0], w[1], w[2], w[3]]) as f64;
                x.len() == 4 && close(f(x), f(y))
            }
        })
}

#[test]
fn generator_reproduces_the_checked_in_files() {
    let dir = tempfile::tempdir().unwrap();
    pis_samples::generate_all(dir.path()).unwrap();
    let wild = pis_samples::WILD.iter().map(|n| format!("wild/{n}"));
    for name in pis_samples::SAMPLES.iter().map(|n| n.to_string()).chain(wild) {
        let name = name.as_str();
        let mut files: Vec<_> = std::fs::read_dir(dir.path().join(name))
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        files.sort();
        for f in files {
            let shown = format!("samples/{name}/{}", f.to_string_lossy());
            let fresh = std::fs::read(dir.path().join(name).join(&f)).unwrap();
            let checked_in = std::fs::read(samples_dir().join(name).join(&f))
                .unwrap_or_else(|_| panic!("{shown} is not checked in; run the generator"));
            let same = fresh == checked_in
                || match Path::new(&f).extension().and_then(|e| e.to_str()) {
                    Some("gltf") => same_json(
                        &serde_json::from_slice(&fresh).unwrap(),
                        &serde_json::from_slice(&checked_in).unwrap(),
                    ),
                    Some("bin") => same_bin(&fresh, &checked_in),
                    _ => false,
                };
            assert!(same, "{shown} differs from the generator's output; regenerate with `cargo run -p pis-samples --release -- samples/`");
        }
    }
}
