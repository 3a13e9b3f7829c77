//! Tests of [`crate::load`] and [`crate::Scene::frame`] on a small glTF written on the fly:
//! a triangle (node `Tri`), a camera (`Cam`), a light (`Lamp`, radius 0.25) and two
//! animations, `spin` (LINEAR rotation of `Tri`) and `hop` (STEP translation of `Lamp`).

use std::path::{Path, PathBuf};

use glam::{Quat, Vec3};
use serde_json::json;

use crate::{load, load_with, LoadOptions, ObjectRole, SceneError};

pub(crate) struct Fixture {
    pub(crate) dir: tempfile::TempDir,
}

pub(crate) const TOML: &str = r#"
gltf = "scene.gltf"
resolution = [32, 24]
spp = 2

[camera]
node = "Cam"

[[dimension]]
name = "spin"
driver = "animation"
animation = "spin"
kind = "object_motion"
samples = 3

[[dimension]]
name = "view"
driver = "orbit"
samples = 4
target = [0, 0.5, 0]
radius = 4
elevation_deg = 30
azimuth_deg = [0, 90]

[preset.paper]
resolution = [64, 48]
samples = { view = 8 }
"#;

pub(crate) fn f32s(v: &[f32]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}

impl Fixture {
    /// Writes the fixture; `edit` may change the glTF JSON and the buffer before writing.
    pub(crate) fn new(
        toml: &str,
        edit: impl FnOnce(&mut serde_json::Value, &mut Vec<u8>),
    ) -> Fixture {
        let positions = [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0];
        let times = [0.0f32, 1.0, 2.0];
        let half = std::f32::consts::FRAC_PI_4; // rotations 0°, 90°, 180° about +Y
        let rotations: Vec<f32> = [0.0, half, 2.0 * half]
            .iter()
            .flat_map(|h: &f32| [0.0, h.sin(), 0.0, h.cos()])
            .collect();
        let hops = [0.0f32, 2.0, 0.0, 0.0, 3.0, 0.0, 0.0, 4.0, 0.0];
        let mut bin = f32s(&positions); // 0..36
        bin.extend(f32s(&times)); // 36..48
        bin.extend(f32s(&rotations)); // 48..96
        bin.extend(f32s(&hops)); // 96..132
                                 // CUBICSPLINE translation keys (in-tangent, value, out-tangent) × 3.
        let bob = [
            0.0f32, 0.0, 0.0, /**/ 0.0, 0.0, 0.0, /**/ 1.0, 0.0,
            0.0, // key 0: value 0, out 1
            0.0, 0.0, 0.0, /**/ 1.0, 0.0, 0.0, /**/ 0.0, 0.0,
            0.0, // key 1: in 0, value 1
            0.0, 0.0, 0.0, /**/ 1.0, 0.0, 0.0, /**/ 0.0, 0.0, 0.0, // key 2: value 1
        ];
        bin.extend(f32s(&bob)); // 132..240
        let mut doc = json!({
            "asset": {"version": "2.0"},
            "extensionsUsed": ["KHR_lights_punctual"],
            "extensions": {"KHR_lights_punctual": {"lights": [
                {"name": "Lamp", "type": "point", "color": [1, 0.5, 0.25], "intensity": 4, "extras": {"radius": 0.25}}
            ]}},
            "scene": 0,
            "scenes": [{"nodes": [0, 1, 2]}],
            "nodes": [
                {"name": "Tri", "mesh": 0, "translation": [1, 0, 0]},
                {"name": "Cam", "camera": 0, "translation": [0, 1, 5]},
                {"name": "LampNode", "extensions": {"KHR_lights_punctual": {"light": 0}}, "translation": [0, 2, 0]}
            ],
            "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1}}],
            "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "material": 0}]}],
            "materials": [{"name": "chrome", "pbrMetallicRoughness": {"metallicFactor": 1.0, "roughnessFactor": 0.1}}],
            "buffers": [{"uri": "scene.bin", "byteLength": bin.len()}],
            "bufferViews": [
                {"buffer": 0, "byteOffset": 0, "byteLength": 36},
                {"buffer": 0, "byteOffset": 36, "byteLength": 12},
                {"buffer": 0, "byteOffset": 48, "byteLength": 48},
                {"buffer": 0, "byteOffset": 96, "byteLength": 36},
                {"buffer": 0, "byteOffset": 132, "byteLength": 108}
            ],
            "accessors": [
                {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
                {"bufferView": 1, "componentType": 5126, "count": 3, "type": "SCALAR", "min": [0], "max": [2]},
                {"bufferView": 2, "componentType": 5126, "count": 3, "type": "VEC4"},
                {"bufferView": 3, "componentType": 5126, "count": 3, "type": "VEC3"},
                {"bufferView": 4, "componentType": 5126, "count": 9, "type": "VEC3"}
            ],
            "animations": [
                {"name": "spin", "samplers": [{"input": 1, "output": 2, "interpolation": "LINEAR"}],
                 "channels": [{"sampler": 0, "target": {"node": 0, "path": "rotation"}}]},
                {"name": "hop", "samplers": [{"input": 1, "output": 3, "interpolation": "STEP"}],
                 "channels": [{"sampler": 0, "target": {"node": 2, "path": "translation"}}]},
                {"name": "bob", "samplers": [{"input": 1, "output": 4, "interpolation": "CUBICSPLINE"}],
                 "channels": [{"sampler": 0, "target": {"node": 0, "path": "translation"}}]}
            ]
        });
        edit(&mut doc, &mut bin);
        let dir = tempfile::tempdir().expect("temp dir");
        std::fs::write(
            dir.path().join("scene.gltf"),
            serde_json::to_vec_pretty(&doc).expect("json"),
        )
        .expect("write");
        std::fs::write(dir.path().join("scene.bin"), &bin).expect("write");
        std::fs::write(dir.path().join("scene.toml"), toml).expect("write");
        Fixture { dir }
    }

    pub(crate) fn toml(&self) -> PathBuf {
        self.dir.path().join("scene.toml")
    }
}

pub(crate) fn load_err(f: &Fixture) -> SceneError {
    match load(&f.toml(), None) {
        Ok(_) => panic!("expected an error"),
        Err(e) => e,
    }
}

#[test]
fn loads_objects_materials_lights_and_space() {
    let f = Fixture::new(TOML, |_, _| {});
    let s = load(&f.toml(), None).unwrap();
    assert_eq!(s.resolution, (32, 24));
    assert_eq!(s.spp, 2);
    assert_eq!(s.objects.len(), 1);
    assert_eq!(s.objects[0].name, "Tri");
    assert_eq!(s.objects[0].role, ObjectRole::Reflective);
    let prim = &s.objects[0].primitives[0];
    assert_eq!(prim.indices.len(), 3);
    assert_eq!(prim.normals[0], Vec3::Z); // generated flat
    assert_eq!(s.materials[0].metallic, 1.0);
    assert_eq!(s.space.dims.len(), 2);
    assert_eq!(s.space.dims[0].kind, crate::DimensionKind::ObjectMotion);
    assert_eq!(s.space.dims[0].values, vec![0.0, 1.0, 2.0]);
    assert_eq!(s.space.dims[1].kind, crate::DimensionKind::View);
    assert_eq!(s.space.dims[1].values, vec![0.0, 30.0, 60.0, 90.0]);
    assert_eq!(s.space.point_count(), 12);
    assert_eq!(s.rig.lights[0].radius, 0.25);
    assert_eq!(s.rig.lights[0].radiance, [4.0, 2.0, 1.0]);
    assert!((s.rig.camera.yfov - 0.8).abs() < 1e-6);
}

#[test]
fn preset_and_overrides() {
    let f = Fixture::new(TOML, |_, _| {});
    let s = load(&f.toml(), Some("paper")).unwrap();
    assert_eq!(s.resolution, (64, 48));
    assert_eq!(s.space.point_count(), 24);
    let opts =
        LoadOptions { preset: Some("paper".into()), resolution: Some((10, 5)), spp: Some(9) };
    let s = load_with(&f.toml(), &opts).unwrap();
    assert_eq!((s.resolution, s.spp), ((10, 5), 9));
}

#[test]
fn frame_poses_animation_and_orbit() {
    let f = Fixture::new(TOML, |_, _| {});
    let s = load(&f.toml(), None).unwrap();
    for index in 0..s.space.point_count() {
        let point = s.space.point(index);
        assert_eq!(s.space.index_of(&point), Some(index));
        let frame = s.frame(&point).unwrap();
        // The orbit camera looks at its target from 4 units away.
        let cam = frame.camera.world_from_camera;
        let local = cam.inverse().transform_point3(Vec3::new(0.0, 0.5, 0.0));
        assert!(local.x.abs() < 1e-4 && local.y.abs() < 1e-4 && (local.z + 4.0).abs() < 1e-4);
    }
    // spin sample 1 (t = 1): 90° about +Y; the node keeps its translation.
    let frame = s.frame(&[1, 0]).unwrap();
    let m = frame.instances[0].world_from_object;
    assert!(m.transform_point3(Vec3::X).distance(Vec3::new(1.0, 0.0, -1.0)) < 1e-5);
    let (_, r, _) = m.to_scale_rotation_translation();
    assert!(r.dot(Quat::from_rotation_y(std::f32::consts::FRAC_PI_2)).abs() > 1.0 - 1e-6);
    // The light stays at its node (hop is not a dimension).
    assert_eq!(frame.lights[0].position, Vec3::new(0.0, 2.0, 0.0));
    assert_eq!(frame.lights[0].name, "Lamp");
}

#[test]
fn a_scene_without_dimensions_is_one_still_point() {
    let toml = "gltf = \"scene.gltf\"\nresolution = [8, 8]\nspp = 1\n";
    let f = Fixture::new(toml, |_, _| {});
    let s = load(&f.toml(), None).unwrap();
    assert_eq!(s.space.dims.len(), 1);
    let d = &s.space.dims[0];
    assert_eq!(
        (d.name.as_str(), d.kind, &d.values[..]),
        ("point", crate::DimensionKind::Other, &[0.0][..])
    );
    assert_eq!(s.space.point_count(), 1);
    // The glTF camera, unmoved.
    let frame = s.frame(&[0]).unwrap();
    assert_eq!(
        frame.camera.world_from_camera.transform_point3(Vec3::ZERO),
        Vec3::new(0.0, 1.0, 5.0)
    );
}

#[test]
fn camera_node_and_animated_light() {
    let toml = r#"
gltf = "scene.gltf"
resolution = [8, 8]
spp = 1
[[dimension]]
name = "hop"
driver = "animation"
animation = "hop"
kind = "light"
samples = 5
time = [0, 2]
"#;
    let f = Fixture::new(toml, |_, _| {});
    let s = load(&f.toml(), None).unwrap();
    assert_eq!(s.space.dims[0].kind, crate::DimensionKind::Light);
    // No [camera]: the first glTF camera, at (0, 1, 5).
    let frame = s.frame(&[1]).unwrap();
    assert_eq!(
        frame.camera.world_from_camera.transform_point3(Vec3::ZERO),
        Vec3::new(0.0, 1.0, 5.0)
    );
    // STEP: t = 0.5 holds the first keyframe, t = 1.5 the second.
    assert_eq!(frame.lights[0].position, Vec3::new(0.0, 2.0, 0.0));
    assert_eq!(s.frame(&[3]).unwrap().lights[0].position, Vec3::new(0.0, 3.0, 0.0));
    assert_eq!(s.frame(&[4]).unwrap().lights[0].position, Vec3::new(0.0, 4.0, 0.0));
}

#[test]
fn cubic_spline_animation_through_gltf() {
    let toml = r#"
gltf = "scene.gltf"
resolution = [8, 8]
spp = 1
[[dimension]]
name = "bob"
driver = "animation"
animation = "bob"
samples = 3
time = [0, 1]
"#;
    let f = Fixture::new(toml, |_, _| {});
    let s = load(&f.toml(), None).unwrap();
    assert_eq!(s.space.dims[0].kind, crate::DimensionKind::Time);
    // Hermite at s = 0.5, dt = 1: 0.125·m0 + 0.5·p1 = 0.125·1 + 0.5·1 = 0.625.
    let x = |i: u32| s.frame(&[i]).unwrap().instances[0].world_from_object.w_axis.x;
    assert_eq!(x(0), 0.0);
    assert!((x(1) - 0.625).abs() < 1e-6, "{}", x(1));
    assert_eq!(x(2), 1.0);
}

#[test]
fn loads_binary_gltf() {
    let f = Fixture::new(&TOML.replace("scene.gltf", "scene.glb"), |_, _| {});
    // Repack scene.gltf + scene.bin as a GLB: header, JSON chunk, BIN chunk (4-byte aligned).
    let dir = f.dir.path();
    let mut doc: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("scene.gltf")).unwrap()).unwrap();
    let mut bin = std::fs::read(dir.join("scene.bin")).unwrap();
    doc["buffers"][0].as_object_mut().unwrap().remove("uri");
    let mut json = serde_json::to_vec(&doc).unwrap();
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let mut glb = Vec::new();
    glb.extend(b"glTF");
    glb.extend(2u32.to_le_bytes());
    glb.extend((total as u32).to_le_bytes());
    glb.extend((json.len() as u32).to_le_bytes());
    glb.extend(b"JSON");
    glb.extend(&json);
    glb.extend((bin.len() as u32).to_le_bytes());
    glb.extend(b"BIN\0");
    glb.extend(&bin);
    std::fs::write(dir.join("scene.glb"), glb).unwrap();
    let s = load(&f.toml(), None).unwrap();
    assert_eq!(s.objects[0].primitives[0].positions.len(), 3);
    assert_eq!(s.space.point_count(), 12);
}

#[test]
fn scene_toml_lights_join_the_gltfs() {
    let lights = r#"
[[light]]
name = "Key"
kind = "sphere"
position = [1, 2, 3]
radius = 0.5
intensity = 4
color = [1, 0.5, 0.25]
visible_camera = false

[[light]]
name = "Sun"
kind = "directional"
direction = [0, -2, 0]

[[light]]
name = "Spot"
kind = "spot"
position = [0, 3, 0]
direction = [1, 0, 0]
outer_cone_deg = 30
"#;
    let f = Fixture::new(&format!("{TOML}{lights}"), |_, _| {});
    let s = load(&f.toml(), None).unwrap();
    assert!(s.emits());
    let frame = s.frame(&[0, 0]).unwrap();
    let names: Vec<&str> = frame.lights.iter().map(|l| l.name.as_str()).collect();
    assert_eq!(names, ["Lamp", "Key", "Sun", "Spot"]);
    let (key, sun, spot) = (&frame.lights[1], &frame.lights[2], &frame.lights[3]);
    assert_eq!(
        (key.kind, key.position, key.radius, key.radiance),
        (crate::LightKind::Point, Vec3::new(1.0, 2.0, 3.0), 0.5, [4.0, 2.0, 1.0])
    );
    assert!(!key.visible_camera && frame.lights[0].visible_camera, "seen by the camera by default");
    assert_eq!(sun.kind, crate::LightKind::Directional);
    assert!(sun.direction.abs_diff_eq(Vec3::NEG_Y, 1e-6), "{}", sun.direction);
    assert!(
        spot.direction.abs_diff_eq(Vec3::X, 1e-6)
            && spot.position.abs_diff_eq(Vec3::new(0.0, 3.0, 0.0), 1e-6),
        "{spot:?}"
    );
    assert!(
        matches!(spot.kind, crate::LightKind::Spot { outer_cone, .. } if (outer_cone - 30f32.to_radians()).abs() < 1e-6)
    );
    for (bad, field) in [
        ("[[light]]\nname = \"A\"\nkind = \"sphere\"\nposition = [0, 1, 0]\n", "light[1].radius"),
        (
            "[[light]]\nname = \"A\"\nkind = \"point\"\nposition = [0, 1, 0]\nvisible_camera = false\n",
            "light[1].visible_camera",
        ),
        ("[[light]]\nname = \"A\"\nkind = \"spot\"\nposition = [0, 1, 0]\n", "light[1].direction"),
        (
            "[[light]]\nname = \"A\"\nkind = \"directional\"\ndirection = [0, 0, 0]\n",
            "light[1].direction",
        ),
        ("[[light]]\nname = \"Lamp\"\nkind = \"point\"\nposition = [0, 1, 0]\n", "light[1].name"),
        (
            "[[light]]\nname = \"A\"\nkind = \"point\"\nposition = [0, 1, 0]\nintensity = -1\n",
            "light[1].intensity",
        ),
    ] {
        let f = Fixture::new(&format!("{TOML}\n{bad}"), |_, _| {});
        let err = load_err(&f).to_string();
        assert!(err.contains(field), "{bad}: {err}");
    }
}

#[test]
fn light_path_moves_the_light() {
    let toml = r#"
gltf = "scene.gltf"
resolution = [8, 8]
spp = 1
[camera]
eye = [0, 0, 3]
target = [0, 0, 0]
[[dimension]]
name = "light"
driver = "light_path"
light = "Lamp"
samples = 3
path = [[-1, 3, 0], [1, 3, 0]]
"#;
    let f = Fixture::new(toml, |_, _| {});
    let s = load(&f.toml(), None).unwrap();
    assert_eq!(s.space.dims[0].kind, crate::DimensionKind::Light);
    assert_eq!(s.frame(&[1]).unwrap().lights[0].position, Vec3::new(0.0, 3.0, 0.0));
    assert_eq!(s.frame(&[2]).unwrap().lights[0].position, Vec3::new(1.0, 3.0, 0.0));
}

#[test]
fn role_override() {
    let toml = format!("{TOML}\n[object.Tri]\nrole = \"diffuse\"\n");
    let f = Fixture::new(&toml, |_, _| {});
    assert_eq!(load(&f.toml(), None).unwrap().objects[0].role, ObjectRole::Diffuse);
}

#[test]
fn reflector_names_the_object_a_part_of() {
    let toml = format!("{TOML}\n[object.Tri]\nreflector = \"Teapot\"\n");
    let f = Fixture::new(&toml, |_, _| {});
    let s = load(&f.toml(), None).unwrap();
    assert_eq!(s.objects[0].reflector.as_deref(), Some("Teapot"));
    let f = Fixture::new(&format!("{TOML}\n[object.Tri]\nreflector = \" \"\n"), |_, _| {});
    let err = load_err(&f);
    assert!(err.to_string().contains("object.Tri.reflector"), "{err}");
}

#[test]
fn parts_naming_one_reflector_share_its_first_part() {
    let mut s = crate::Scene::default();
    for (name, reflector) in [
        ("Body", None),
        ("Box", None),
        ("Lid", Some("Body")),
        ("Knob", Some("Pot")),
        ("Spout", Some("Pot")),
    ] {
        s.objects.push(crate::SceneObject {
            name: name.into(),
            role: ObjectRole::Reflective,
            reflector: reflector.map(String::from),
            primitives: vec![],
        });
    }
    let of: Vec<u32> = (0..5).map(|o| s.reflector_of(o)).collect();
    assert_eq!(s.reflectors(), of);
    assert_eq!(of, [0, 1, 0, 3, 3]);
}

#[test]
fn error_missing_scene_toml() {
    let err = load(Path::new("/nonexistent/scene.toml"), None).unwrap_err();
    assert!(matches!(err, SceneError::Io { .. }));
    assert!(err.to_string().contains("/nonexistent/scene.toml"), "{err}");
}

#[test]
fn error_missing_gltf() {
    let f = Fixture::new(&TOML.replace("scene.gltf", "other.gltf"), |_, _| {});
    let err = load_err(&f);
    assert!(
        matches!(err, SceneError::Io { .. }) && err.to_string().contains("other.gltf"),
        "{err}"
    );
}

#[test]
fn error_missing_buffer() {
    let f = Fixture::new(TOML, |doc, _| doc["buffers"][0]["uri"] = json!("gone.bin"));
    let err = load_err(&f);
    assert!(
        matches!(err, SceneError::Gltf { .. }) && err.to_string().contains("scene.gltf"),
        "{err}"
    );
}

#[test]
fn error_unknown_camera() {
    let f = Fixture::new(&TOML.replace("node = \"Cam\"", "node = \"Kam\""), |_, _| {});
    let err = load_err(&f);
    assert!(matches!(err, SceneError::UnknownName { what: "camera", .. }), "{err}");
    assert!(err.to_string().contains("camera.node") && err.to_string().contains("Cam"), "{err}");
}

#[test]
fn error_unknown_animation() {
    let f = Fixture::new(&TOML.replace("animation = \"spin\"", "animation = \"spun\""), |_, _| {});
    let err = load_err(&f);
    assert!(matches!(err, SceneError::UnknownName { what: "animation", .. }), "{err}");
    assert!(err.to_string().contains("dimension[0].animation"), "{err}");
}

#[test]
fn error_unknown_light() {
    let toml = "gltf = \"scene.gltf\"\nresolution = [8, 8]\nspp = 1\n[[dimension]]\nname = \"l\"\ndriver = \"light_path\"\nlight = \"Sun\"\nsamples = 2\npath = [[0, 0, 0]]\n";
    let f = Fixture::new(toml, |_, _| {});
    let err = load_err(&f);
    assert!(matches!(err, SceneError::UnknownName { what: "light", .. }), "{err}");
}

#[test]
fn error_unknown_object() {
    let f = Fixture::new(&format!("{TOML}\n[object.Vase]\nrole = \"reflective\"\n"), |_, _| {});
    assert!(matches!(load_err(&f), SceneError::UnknownName { what: "object", .. }));
}

#[test]
fn error_zero_samples() {
    let f = Fixture::new(&TOML.replace("samples = 4", "samples = 0"), |_, _| {});
    let err = load_err(&f);
    assert!(matches!(err, SceneError::ZeroSamples { .. }), "{err}");
    assert!(
        err.to_string().contains("dimension[1].samples") && err.to_string().contains("view"),
        "{err}"
    );
}

#[test]
fn error_unknown_toml_key() {
    let f = Fixture::new(&TOML.replace("spp = 2", "spp = 2\nspf = 3"), |_, _| {});
    let err = load_err(&f);
    assert!(matches!(err, SceneError::Toml { .. }) && err.to_string().contains("spf"), "{err}");
}

#[test]
fn error_key_of_another_driver() {
    let f =
        Fixture::new(&TOML.replace("radius = 4", "radius = 4\nanimation = \"spin\""), |_, _| {});
    let err = load_err(&f);
    assert!(err.to_string().contains("dimension[1].animation"), "{err}");
}

#[test]
fn error_nan_in_buffer() {
    let f = Fixture::new(TOML, |_, bin| bin[12..16].copy_from_slice(&f32::NAN.to_le_bytes()));
    let err = load_err(&f);
    assert!(matches!(err, SceneError::NonFinite { element: 1, .. }), "{err}");
    assert!(err.to_string().contains("meshes[0].primitives[0].attributes.POSITION"), "{err}");
}

/// A position of 3 · 10³⁸ once traced and failed only at pack: refused at load, naming
/// the accessor and the element.
#[test]
fn error_position_out_of_range() {
    let f = Fixture::new(TOML, |_, bin| bin[12..16].copy_from_slice(&3e38f32.to_le_bytes()));
    let err = load_err(&f);
    let text = err.to_string();
    assert!(matches!(err, SceneError::Invalid { .. }), "{err}");
    assert!(text.contains("meshes[0].primitives[0].attributes.POSITION"), "{err}");
    assert!(text.contains("element 1"), "{err}");
}

#[test]
fn error_inf_in_animation() {
    let f = Fixture::new(TOML, |_, bin| bin[52..56].copy_from_slice(&f32::INFINITY.to_le_bytes()));
    let err = load_err(&f);
    assert!(err.to_string().contains("animations[0].samplers[0].output"), "{err}");
}

#[test]
fn error_required_extension() {
    let f = Fixture::new(TOML, |doc, _| {
        doc["extensionsRequired"] = json!(["KHR_draco_mesh_compression"])
    });
    let err = load_err(&f);
    assert!(matches!(err, SceneError::Unsupported { .. }), "{err}");
    assert!(err.to_string().contains("extensionsRequired"), "{err}");
}

#[test]
fn error_non_triangle_primitive() {
    let f = Fixture::new(TOML, |doc, _| doc["meshes"][0]["primitives"][0]["mode"] = json!(1));
    let err = load_err(&f);
    assert!(matches!(err, SceneError::Unsupported { .. }), "{err}");
    assert!(err.to_string().contains("meshes[0].primitives[0].mode"), "{err}");
}

#[test]
fn error_point_out_of_range() {
    let f = Fixture::new(TOML, |_, _| {});
    let s = load(&f.toml(), None).unwrap();
    assert!(matches!(s.frame(&[3, 0]), Err(SceneError::PointOutOfRange { .. })));
    assert!(matches!(s.frame(&[0]), Err(SceneError::PointOutOfRange { .. })));
}

#[test]
fn error_unknown_preset() {
    let f = Fixture::new(TOML, |_, _| {});
    let err = load(&f.toml(), Some("huge")).unwrap_err();
    assert!(
        matches!(err, SceneError::UnknownName { what: "preset", .. })
            && err.to_string().contains("paper"),
        "{err}"
    );
}

#[test]
fn hand_built_scene_has_identity_instances() {
    let mut s = crate::Scene::default();
    s.objects.push(crate::SceneObject {
        name: "o".into(),
        role: ObjectRole::Diffuse,
        reflector: None,
        primitives: vec![],
    });
    let frame = s.frame(&[]).unwrap();
    assert_eq!(frame.instances[0].world_from_object, glam::Mat4::IDENTITY);
}

/// Damaged inputs must give an error (or load), never a panic: every numeric field of the
/// glTF JSON set to a few hostile values, and the buffer truncated at every length.
#[test]
fn damaged_gltf_errors_without_panicking() {
    fn numeric_paths(v: &serde_json::Value, path: Vec<String>, out: &mut Vec<Vec<String>>) {
        match v {
            serde_json::Value::Number(_) => out.push(path),
            serde_json::Value::Array(a) => {
                for (i, x) in a.iter().enumerate() {
                    let mut p = path.clone();
                    p.push(i.to_string());
                    numeric_paths(x, p, out);
                }
            }
            serde_json::Value::Object(o) => {
                for (k, x) in o {
                    let mut p = path.clone();
                    p.push(k.clone());
                    numeric_paths(x, p, out);
                }
            }
            _ => {}
        }
    }
    let base = Fixture::new(TOML, |_, _| {});
    let doc: serde_json::Value =
        serde_json::from_slice(&std::fs::read(base.dir.path().join("scene.gltf")).unwrap())
            .unwrap();
    let mut paths = Vec::new();
    numeric_paths(&doc, vec![], &mut paths);
    for path in &paths {
        for value in [json!(0), json!(1), json!(7), json!(1_000_000), json!(-1), json!(0.5)] {
            let f = Fixture::new(TOML, |d, _| {
                let mut slot = &mut *d;
                for key in path {
                    slot = match slot {
                        serde_json::Value::Array(a) => &mut a[key.parse::<usize>().unwrap()],
                        other => &mut other[key.as_str()],
                    };
                }
                *slot = value.clone();
            });
            let result = std::panic::catch_unwind(|| {
                load(&f.toml(), None).map(|s| s.frame_at(0).map(|_| ()))
            });
            assert!(result.is_ok(), "panic with {} = {value}", path.join("."));
        }
    }
    let bin_len = std::fs::read(base.dir.path().join("scene.bin")).unwrap().len();
    for len in 0..bin_len {
        let f = Fixture::new(TOML, |_, bin| bin.truncate(len));
        let result = std::panic::catch_unwind(|| load(&f.toml(), None).map(|_| ()));
        assert!(result.is_ok(), "panic with the buffer cut to {len} bytes");
    }
}

#[test]
fn error_accessor_past_its_buffer_view() {
    let f = Fixture::new(TOML, |doc, _| doc["accessors"][0]["count"] = json!(1000));
    let err = load_err(&f);
    let msg = err.to_string();
    assert!(msg.contains("meshes[0].primitives[0].attributes.POSITION (accessors[0])"), "{msg}");
    assert!(msg.contains("exceed buffer view 0"), "{msg}");
}

#[test]
fn error_animation_target_node_missing() {
    let f = Fixture::new(TOML, |doc, _| {
        doc["animations"][0]["channels"][0]["target"]["node"] = json!(9)
    });
    let err = load_err(&f);
    assert!(err.to_string().contains("animations[0].channels[0].target.node"), "{err}");
}

#[test]
fn error_normal_accessor_of_wrong_type() {
    let f = Fixture::new(TOML, |doc, _| {
        doc["meshes"][0]["primitives"][0]["attributes"]["NORMAL"] = json!(1)
    });
    let err = load_err(&f);
    assert!(err.to_string().contains("expected [Vec3] of [F32]"), "{err}");
}

/// A glTF from elsewhere once read `../../etc/passwd`: references that leave the glTF's
/// folder are refused, naming the field, unless scene.toml allows them.
#[test]
fn buffer_uri_leaving_the_scene_folder_is_refused() {
    let with_uri = |uri: String| {
        move |doc: &mut serde_json::Value, _: &mut Vec<u8>| {
            doc["buffers"][0]["uri"] = json!(uri);
        }
    };
    for uri in ["../../etc/passwd", "/etc/passwd", "file:///etc/passwd", "../missing.bin"] {
        let e = load_err(&Fixture::new(TOML, with_uri(uri.to_string()))).to_string();
        assert!(e.contains("buffers[0].uri") && e.contains("refused"), "{uri}: {e}");
    }
    // a path that climbs out and back in stays inside
    let f = Fixture::new(TOML, |_, _| {});
    let back = format!("../{}/scene.bin", f.dir.path().file_name().unwrap().to_string_lossy());
    let gltf = f.dir.path().join("scene.gltf");
    let mut doc: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&gltf).unwrap()).unwrap();
    doc["buffers"][0]["uri"] = json!(back);
    std::fs::write(&gltf, serde_json::to_vec(&doc).unwrap()).unwrap();
    assert!(load(&f.toml(), None).is_ok(), "{back}: inside the folder");
    // a buffer truly outside: refused, and read when scene.toml allows it
    let elsewhere = tempfile::tempdir().expect("temp dir");
    let outside = elsewhere.path().join("outside.bin");
    std::fs::copy(Fixture::new(TOML, |_, _| {}).dir.path().join("scene.bin"), &outside).unwrap();
    let uri = outside.to_string_lossy().to_string();
    let e = load_err(&Fixture::new(TOML, with_uri(uri.clone()))).to_string();
    assert!(e.contains("absolute path") && e.contains("allow_outside_files"), "{e}");
    let f = Fixture::new(&format!("allow_outside_files = true\n{TOML}"), with_uri(uri));
    assert!(load(&f.toml(), None).is_ok(), "allow_outside_files = true reads it");
}

#[test]
fn image_uri_leaving_the_scene_folder_is_refused() {
    let f = Fixture::new(TOML, |doc, _| {
        doc["images"] = json!([{"uri": "../secret.png"}]);
    });
    let e = load_err(&f).to_string();
    assert!(e.contains("images[0].uri") && e.contains("leaves the glTF's folder"), "{e}");
}

/// The glTF reader pads a buffer up to 3 bytes short with zeros: refused instead.
#[test]
fn buffer_shorter_than_its_byte_length_is_refused() {
    for short in 1..=3 {
        let f = Fixture::new(TOML, |doc, bin| {
            doc["buffers"][0]["byteLength"] = json!(bin.len());
            bin.truncate(bin.len() - short);
        });
        let e = load_err(&f).to_string();
        assert!(
            e.contains("buffers[0].byteLength") && e.contains("the data holds"),
            "{short} bytes short: {e}"
        );
    }
}

/// A 9-dimension space once traced fully and then failed at write: refused at load.
#[test]
fn more_dimensions_than_a_file_holds_are_refused_at_load() {
    let dims: String = (0..9).map(|k| format!("\n[[dimension]]\nname = \"d{k}\"\ndriver = \"animation\"\nanimation = \"spin\"\nkind = \"other\"\nsamples = 1\n")).collect();
    let toml = format!(
        "gltf = \"scene.gltf\"\nresolution = [32, 24]\nspp = 1\n[camera]\nnode = \"Cam\"\n{dims}"
    );
    let e = load_err(&Fixture::new(&toml, |_, _| {})).to_string();
    assert!(e.contains("9 dimensions: a .pis file holds at most 8"), "{e}");
}

/// 10^9 samples once allocated 4 GB at load: refused before any sample value is made.
#[test]
fn more_points_than_a_file_holds_are_refused_at_load() {
    let toml = TOML.replace("samples = 3", "samples = 1000000000");
    let e = load_err(&Fixture::new(&toml, |_, _| {})).to_string();
    assert!(e.contains("1000000000 spin × 4 view: more than 16777216 parameter points"), "{e}");
}

/// Huge resolutions once aborted on allocation.
#[test]
fn a_resolution_over_the_file_limit_is_refused_at_load() {
    let f = Fixture::new(TOML, |_, _| {});
    let options = LoadOptions { resolution: Some((70000, 10)), ..LoadOptions::default() };
    let e = load_with(&f.toml(), &options).expect_err("refused").to_string();
    assert!(e.contains("70000x10: a .pis file holds images of at most 65536 pixels a side"), "{e}");
}
