//! Write → read → compare, for the built-in samples.

use pis_format::samples::{minimal, tiny};
use pis_format::*;

#[test]
fn tiny_round_trips_through_bytes() {
    let c = tiny().unwrap();
    let bytes = to_bytes(&c).unwrap();
    let r = PisReader::from_bytes(bytes.clone()).unwrap();
    assert_eq!(r.len(), bytes.len() as u64);
    assert_eq!(r.load_all().unwrap(), c);
    // Writing what was read gives the same bytes.
    assert_eq!(to_bytes(&r.load_all().unwrap()).unwrap(), bytes);
}

#[test]
fn serialization_is_deterministic() {
    assert_eq!(to_bytes(&tiny().unwrap()).unwrap(), to_bytes(&tiny().unwrap()).unwrap());
}

#[test]
fn tiny_textures_decode_to_what_was_encoded() {
    let r = PisReader::from_bytes(to_bytes(&tiny().unwrap()).unwrap()).unwrap();
    // Diffuse (layer 0) varies with the light only: a brighter light gives brighter texels.
    let dark = r.texture(0, 0, &[0, 0]).unwrap();
    let bright = r.texture(0, 0, &[1, 1]).unwrap();
    assert_eq!(dark, r.texture(0, 0, &[1, 0]).unwrap(), "diffuse must not depend on the view");
    assert_eq!(dark.layout.width, 8);
    // Texel (0,0) is a light checker square: 0.8 × (0.5 + 0.5·light) in red.
    assert!((dark.data[0] - 0.4).abs() < 1e-5, "{}", dark.data[0]);
    assert!((bright.data[0] - 0.8).abs() < 1e-5, "{}", bright.data[0]);
    // The shell (layer 1) has 6 faces with 3 MIP levels each; green encodes the view.
    let shell = r.texture(0, 1, &[1, 0]).unwrap();
    assert_eq!((shell.layout.faces, shell.layout.mips), (6, 3));
    assert!((shell.plane(2, 0)[1] - 0.4).abs() < 1e-6);
    assert!((shell.plane(5, 2)[0] - 0.5).abs() < 1e-6, "{}", shell.plane(5, 2)[0]);
    assert!((r.texture(0, 1, &[0, 1]).unwrap().plane(0, 0)[1] - 0.3).abs() < 1e-6);
}

#[test]
fn a_texture_reads_only_its_pyramid_path() {
    let r = PisReader::from_bytes(to_bytes(&tiny().unwrap()).unwrap()).unwrap();
    r.texture(0, 0, &[0, 1]).unwrap();
    assert_eq!(r.stats().codestreams, 2, "two pyramid levels");
    r.texture(0, 1, &[1, 1]).unwrap();
    assert_eq!(r.stats().codestreams, 3, "one level for a one-sample block");
}

#[test]
fn bad_requests_are_errors() {
    let r = PisReader::from_bytes(to_bytes(&tiny().unwrap()).unwrap()).unwrap();
    assert!(matches!(r.texture(1, 0, &[0, 0]), Err(Error::Request(_))));
    assert!(matches!(r.texture(0, 2, &[0, 0]), Err(Error::Request(_))));
    assert!(matches!(r.texture(0, 0, &[0, 2]), Err(Error::Request(_))));
    assert!(matches!(r.texture(0, 0, &[0]), Err(Error::Request(_))));
}

#[test]
fn minimal_example_round_trips() {
    let c = minimal().unwrap();
    let r = PisReader::from_bytes(to_bytes(&c).unwrap()).unwrap();
    let t = r.texture(0, 0, &[1]).unwrap();
    assert_eq!(t.data, vec![1.0, 0.5, 0.25, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.5, 0.5, 0.5]);
}

#[test]
fn atomic_write_leaves_no_partial_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("out.pis");
    let n = write(&path, &tiny().unwrap()).unwrap();
    assert_eq!(std::fs::metadata(&path).unwrap().len(), n);
    // An invalid model is refused and the existing file is untouched.
    let mut bad = tiny().unwrap();
    bad.space.dims[0].block_size = 0;
    assert!(matches!(write(&path, &bad), Err(Error::InvalidModel(_))));
    assert_eq!(std::fs::metadata(&path).unwrap().len(), n);
    // A missing folder is an I/O error, and nothing is created.
    let missing = dir.path().join("no/such/dir/out.pis");
    assert!(matches!(write(&missing, &tiny().unwrap()), Err(Error::Io { .. })));
    let names: Vec<_> =
        std::fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(names, vec![std::ffi::OsString::from("out.pis")], "no temporary file left behind");
}

#[test]
fn branch_cuts_and_repeat_flags_round_trip() {
    let mut c = tiny().unwrap();
    c.objects[0].layers[0].blocks[0].placement = Placement::Surface {
        affine: [2.0, 0.0, 0.0, 1.0, -0.5, 0.0],
        repeat: [false, true],
        cut: [Some(0.25), None],
    };
    let r = PisReader::from_bytes(to_bytes(&c).unwrap()).unwrap();
    assert_eq!(r.load_all().unwrap(), c);
}

#[test]
fn hull_triangles_round_trip_and_too_many_are_refused() {
    let mut c = tiny().unwrap();
    let triangles = c.objects[0].mesh.indices.len() / 3;
    c.objects[0].mesh.hull_triangles = triangles as u32;
    let r = PisReader::from_bytes(to_bytes(&c).unwrap()).unwrap();
    assert_eq!(r.load_all().unwrap().objects[0].mesh.hull_triangles, triangles as u32);
    c.objects[0].mesh.hull_triangles = triangles as u32 + 1;
    match to_bytes(&c) {
        Err(Error::InvalidModel(issue)) => assert_eq!(issue.id, 5206, "{issue:?}"),
        other => panic!(
            "a mesh with more hull triangles than triangles was written: {:?}",
            other.map(|b| b.len())
        ),
    }
}

/// A shell block's lookups per pixel side (SPEC.md 7.3 flags, 8.2) survive writing and
/// reading, and a file written with 1 has the flags of a file from before the field.
#[test]
fn shell_lookups_round_trip() {
    fn lookups<S>(c: &Container<S>) -> Vec<u32> {
        c.objects
            .iter()
            .flat_map(|o| &o.layers)
            .flat_map(|l| &l.blocks)
            .filter_map(|b| match b.placement {
                Placement::Shell { lookups, .. } => Some(lookups),
                Placement::Surface { .. } => None,
            })
            .collect()
    }
    let mut c = tiny().unwrap();
    let plain = to_bytes(&c).unwrap();
    assert!(
        !lookups(&c).is_empty() && lookups(&c).iter().all(|&k| k == 1),
        "the sample has shell blocks, each looked up once"
    );
    for (k, b) in c
        .objects
        .iter_mut()
        .flat_map(|o| o.layers.iter_mut())
        .flat_map(|l| l.blocks.iter_mut())
        .enumerate()
    {
        if let Placement::Shell { lookups, .. } = &mut b.placement {
            *lookups = 1 + (k as u32 % 3);
        }
    }
    let want = lookups(&c);
    assert!(want.iter().any(|&k| k > 1));
    let read = PisReader::from_bytes(to_bytes(&c).unwrap()).unwrap();
    assert_eq!(lookups(read.container()), want);
    assert_ne!(plain, to_bytes(&c).unwrap());
}
