//! Writing a ray-traced set and reading it back.

mod common;

use common::*;
use glam::Vec3;
use pis_scene::{Dimension, DimensionKind, Driver, ObjectRole, ParameterSpace};
use pis_trace::set::{RaySet, SetWriter};
use pis_trace::{render_point, LayerKind, TraceSettings};

#[test]
fn set_round_trips_images_records_and_metadata() {
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
                vec![sphere(Vec3::new(-0.4, 0.5, 0.0), 0.5, 8, 16, 1, false)],
            ),
            object(
                "lens.1",
                ObjectRole::Refractive,
                vec![sphere(Vec3::new(0.6, 0.4, 0.4), 0.4, 8, 16, 2, false)],
            ),
        ],
        vec![matte([0.7, 0.6, 0.5]), metal([0.9, 0.8, 0.6], 0.0), glass(1.5, [0.8, 0.9, 0.8], 1.0)],
        (10, 8),
        2,
    );
    s.space = ParameterSpace {
        dims: vec![Dimension {
            name: "view".into(),
            kind: DimensionKind::View,
            periodic: false,
            unit: "deg".into(),
            values: vec![0.0, 10.0],
            driver: Driver::Orbit { target: Vec3::ZERO, radius: 3.0, elevation_deg: 20.0 },
        }],
    };
    let settings = TraceSettings::new(s.resolution, s.spp);
    let dir = tempfile::tempdir().unwrap();
    let mut writer = SetWriter::create(dir.path(), &s, &settings).unwrap();
    let mut renders = Vec::new();
    for i in 0..2 {
        let eye = Vec3::new(i as f32, 1.2, 3.0);
        let f = frame(
            &s,
            camera(eye, Vec3::new(0.0, 0.4, 0.0), 50.0),
            vec![sphere_light("key", Vec3::new(1.0, 3.0, 2.0), [20.0; 3], 0.25)],
        );
        let r = render_point(&s, &f, &settings, &|| {}).unwrap();
        writer.write_point(&s, i, &f, &r).unwrap();
        renders.push(r);
    }
    writer.finish().unwrap();
    // No temporary files are left behind.
    for e in std::fs::read_dir(dir.path()).unwrap() {
        let name = e.unwrap().file_name().to_string_lossy().into_owned();
        assert!(!name.starts_with('.'), "left over {name}");
    }

    let set = RaySet::open(dir.path()).unwrap();
    assert_eq!(set.len(), 2);
    assert_eq!(set.meta.resolution, [10, 8]);
    assert_eq!(set.meta.objects[2].channel_name, "lens_1");
    assert_eq!(set.meta.points[1].values, vec![10.0]);
    assert!(set.meta.objects[2].layers.contains(&"refraction_confidence".to_string()));
    for (i, r) in renders.iter().enumerate() {
        let back = set.read_point(i).unwrap();
        for layer in &r.images.layers {
            let b = back.layer(&layer.name).unwrap_or_else(|| panic!("missing {}", layer.name));
            assert_eq!(b.channels, layer.channels, "{}", layer.name);
            for (p, q) in layer.planes.iter().zip(&b.planes) {
                assert!(
                    p.iter().zip(q).all(|(x, y)| x.to_bits() == y.to_bits()),
                    "{} differs",
                    layer.name
                );
            }
        }
        assert!(back.object_layer("ball", LayerKind::Local).is_some());
        assert_eq!(set.read_records(i).unwrap(), r.records);
    }
    // A damaged EXR is an error, not a panic.
    let exr = dir.path().join(&set.meta.points[0].image);
    let bytes = std::fs::read(&exr).unwrap();
    std::fs::write(&exr, &bytes[..bytes.len() / 2]).unwrap();
    assert!(set.read_point(0).is_err());
}
