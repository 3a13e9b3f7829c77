//! Depth shells (SPEC.md 7.3, since 1.5): shell shape 6, `depth`, whose parameters are the
//! face size n of its depth cube (an integer in 1..256), the march steps s (an integer in
//! 1..64) and the far distance F (> 0), the other three 0. Such a file is valid, round-trips,
//! and is written as minor version 5; every other file keeps the minor version it had. Other
//! parameters break rule 6007.

use pis_format::samples::tiny;
use pis_format::*;

/// `tiny` with its shell's blocks made depth shells of parameters `params`.
fn depth(params: [f32; 6]) -> Container {
    let mut c = tiny().unwrap();
    for b in &mut c.objects[0].layers[1].blocks {
        let Placement::Shell { origin, lookups, .. } = b.placement else {
            panic!("tiny's layer 1 is a shell layer")
        };
        b.placement = Placement::Shell { shape: ShellShape::Depth, origin, params, lookups };
    }
    c
}

fn rules(c: &Container) -> Vec<u16> {
    validate_bytes(to_bytes_unchecked(c)).issues.iter().map(|i| i.id).collect()
}

fn minor(bytes: &[u8]) -> u16 {
    u16::from_le_bytes([bytes[10], bytes[11]])
}

#[test]
fn depth_is_shell_shape_6_with_six_faces() {
    assert_eq!(ShellShape::from_code(6), Some(ShellShape::Depth));
    assert_eq!(ShellShape::Depth.name(), "depth");
    assert_eq!(ShellShape::Depth.faces(), 6);
    assert_eq!(ShellShape::from_code(7), None);
}

#[test]
fn a_depth_shell_is_valid_and_written_as_minor_version_5() {
    let c = depth([16.0, 8.0, 10.0, 0.0, 0.0, 0.0]);
    assert_eq!(rules(&c), Vec::<u16>::new());
    let bytes = to_bytes(&c).unwrap();
    assert_eq!(minor(&bytes), 5, "minor version");
    let r = PisReader::from_bytes(bytes).unwrap();
    assert_eq!(r.load_all().unwrap(), c);
    let plain = to_bytes(&tiny().unwrap()).unwrap();
    assert_eq!(minor(&plain), 2, "a file without one");
}

#[test]
fn a_depth_shell_outranks_an_object_filter() {
    let mut c = depth([16.0, 8.0, 10.0, 0.0, 0.0, 0.0]);
    let (k, v) = FileFilter::Bilinear.object_setting(&c.objects[0].name);
    let provenance = Provenance {
        tool: "t".into(),
        source: "s".into(),
        raw_image_bytes: 0,
        settings: vec![(k, v)],
    };
    c.provenance = Some(provenance.clone());
    assert_eq!(minor(&to_bytes(&c).unwrap()), 5, "with a depth shell");
    let mut plain = tiny().unwrap();
    plain.provenance = Some(provenance);
    assert_eq!(minor(&to_bytes(&plain).unwrap()), 4, "without one");
}

#[test]
fn depth_parameters_at_their_limits_are_valid() {
    for params in [
        [1.0, 1.0, 1e-6, 0.0, 0.0, 0.0],
        [256.0, 64.0, 1e30, 0.0, 0.0, 0.0],
        [64.0, 32.0, 5.0, -0.0, -0.0, -0.0],
    ] {
        assert_eq!(rules(&depth(params)), Vec::<u16>::new(), "{params:?}");
    }
}

#[test]
fn invalid_depth_parameters_break_rule_6007() {
    let cases: [(&str, [f32; 6]); 10] = [
        ("n = 0", [0.0, 8.0, 10.0, 0.0, 0.0, 0.0]),
        ("n = 1.5", [1.5, 8.0, 10.0, 0.0, 0.0, 0.0]),
        ("n = 257", [257.0, 8.0, 10.0, 0.0, 0.0, 0.0]),
        ("n = -16", [-16.0, 8.0, 10.0, 0.0, 0.0, 0.0]),
        ("steps 0", [16.0, 0.0, 10.0, 0.0, 0.0, 0.0]),
        ("steps 65", [16.0, 65.0, 10.0, 0.0, 0.0, 0.0]),
        ("steps 2.5", [16.0, 2.5, 10.0, 0.0, 0.0, 0.0]),
        ("far 0", [16.0, 8.0, 0.0, 0.0, 0.0, 0.0]),
        ("far -1", [16.0, 8.0, -1.0, 0.0, 0.0, 0.0]),
        ("p[3] = 1", [16.0, 8.0, 10.0, 1.0, 0.0, 0.0]),
    ];
    for (what, params) in cases {
        let c = depth(params);
        assert_eq!(rules(&c), vec![6007, 6007], "{what}: one issue per shell block");
        assert!(to_bytes(&c).is_err(), "{what}: the writer refuses it");
    }
    for (what, params) in [
        ("p[4] = 1", [16.0, 8.0, 10.0, 0.0, 1.0, 0.0]),
        ("p[5] = -1", [16.0, 8.0, 10.0, 0.0, 0.0, -1.0]),
        ("far infinite", [16.0, 8.0, f32::INFINITY, 0.0, 0.0, 0.0]),
        ("far NaN", [16.0, 8.0, f32::NAN, 0.0, 0.0, 0.0]),
    ] {
        assert_eq!(rules(&depth(params)), vec![6007, 6007], "{what}");
    }
}
