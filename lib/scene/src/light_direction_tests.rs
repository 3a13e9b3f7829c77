//! The `light_direction` driver loaded from scene.toml: the light it turns, where it places
//! it, and the errors that name their key (docs/SCENE.md).

use glam::Vec3;

use crate::load;
use crate::load_tests::{load_err, Fixture};

const SUN_HEAD: &str = "gltf = \"scene.gltf\"\nresolution = [8, 8]\nspp = 1\n[camera]\neye = [0, 0, 3]\ntarget = [0, 0, 0]\n[[light]]\nname = \"Sun\"\nkind = \"directional\"\ndirection = [0, -1, 0]\n";

#[test]
fn light_direction_turns_a_directional_light_and_places_a_point_light() {
    let head = SUN_HEAD;
    let sun = "[[dimension]]\nname = \"sun\"\ndriver = \"light_direction\"\nlight = \"Sun\"\nsamples = 16\n";
    let f = Fixture::new(&format!("{head}{sun}"), |_, _| {});
    let s = load(&f.toml(), None).unwrap();
    let d = &s.space.dims[0];
    assert_eq!((d.kind, d.values.len(), d.values[15]), (crate::DimensionKind::Light, 16, 15.0));
    let crate::Driver::LightDirection { directions, .. } = &d.driver else { panic!() };
    for i in [0u32, 7, 15] {
        let frame = s.frame(&[i]).unwrap();
        let light = frame.lights.iter().find(|l| l.name == "Sun").unwrap();
        assert!(light.direction.distance(-directions[i as usize]) < 1e-6);
        assert!(directions[i as usize].y > 0.0, "the upper hemisphere by default");
    }
    // A point light stands at the centre plus the distance along the direction.
    let lamp = "[[dimension]]\nname = \"lamp\"\ndriver = \"light_direction\"\nlight = \"Lamp\"\nsamples = 8\ndirections = \"sphere\"\ncenter = [0, 1, 0]\ndistance = 4\n";
    let f = Fixture::new(&format!("{head}{lamp}"), |_, _| {});
    let s = load(&f.toml(), None).unwrap();
    let crate::Driver::LightDirection { directions, .. } = &s.space.dims[0].driver else {
        panic!()
    };
    let frame = s.frame(&[7]).unwrap();
    let want = Vec3::new(0.0, 1.0, 0.0) + 4.0 * directions[7];
    assert!(frame.lights[0].position.distance(want) < 1e-5);
    assert!(directions[7].y < 0.0, "the sphere's last sample lies below");
}

#[test]
fn light_direction_errors_name_their_key() {
    let head = format!(
        "{SUN_HEAD}[[dimension]]\nname = \"l\"\ndriver = \"light_direction\"\nsamples = 4\n"
    );
    for (bad, field) in [
        ("light = \"Sun\"\ncenter = [0, 0, 0]\n", "dimension[0].center"),
        ("light = \"Lamp\"\ndistance = 2\n", "dimension[0].center"),
        ("light = \"Lamp\"\ncenter = [0, 0, 0]\ndistance = 0\n", "dimension[0].distance"),
        ("light = \"Sun\"\nup = [0, 0, 0]\n", "dimension[0].up"),
        ("light = \"Sun\"\nperiodic = true\n", "dimension[0].periodic"),
        ("light = \"Moon\"\n", "dimension[0].light"),
        ("light = \"Sun\"\npath = [[0, 0, 0]]\n", "dimension[0].path"),
        ("light = \"Sun\"\ndirections = \"cube\"\n", "directions"),
    ] {
        let f = Fixture::new(&format!("{head}{bad}"), |_, _| {});
        let err = load_err(&f).to_string();
        assert!(err.contains(field), "{bad}: {err}");
    }
}

#[test]
fn an_arc_moves_the_light_continuously_at_one_elevation() {
    let spec = "[[dimension]]\nname = \"sun\"\ndriver = \"light_direction\"\nlight = \"Sun\"\nsamples = 5\ndirections = \"arc\"\nelevation_deg = 30\nazimuth_deg = [0, 90]\n";
    let f = Fixture::new(&format!("{SUN_HEAD}{spec}"), |_, _| {});
    let s = load(&f.toml(), None).unwrap();
    let crate::Driver::LightDirection { directions, arc, .. } = &s.space.dims[0].driver else {
        panic!()
    };
    assert!(*arc);
    let (sin_e, cos_e) = 30f32.to_radians().sin_cos();
    assert!(directions[0].distance(Vec3::new(cos_e, sin_e, 0.0)) < 1e-6);
    assert!(directions[4].distance(Vec3::new(0.0, sin_e, cos_e)) < 1e-6);
    for w in directions.windows(2) {
        assert!((w[0].angle_between(w[1]) - (22.5f32.to_radians() * cos_e)).abs() < 0.01);
    }
    // The arc's keys belong to the arc only, and an arc needs its azimuths.
    let cover = spec.replace("\"arc\"", "\"hemisphere\"");
    let e = load_err(&Fixture::new(&format!("{SUN_HEAD}{cover}"), |_, _| {})).to_string();
    assert!(e.contains("elevation_deg") && e.contains("arc"), "{e}");
    let without = spec.replace("azimuth_deg = [0, 90]\n", "");
    let e = load_err(&Fixture::new(&format!("{SUN_HEAD}{without}"), |_, _| {})).to_string();
    assert!(e.contains("azimuth_deg"), "{e}");
}
