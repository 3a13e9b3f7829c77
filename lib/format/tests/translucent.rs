//! Translucent objects (SPEC.md 7.1, since 1.3): a surface layer of 4 channels, order 0,
//! combining by `add`, makes its object translucent. Such a file is valid, round-trips, and
//! is written as minor version 3; every other file stays minor version 2. A 4-channel surface
//! layer that multiplies or comes later, and a translucent object with shells or a
//! multiplying layer, break rule 6003.

use pis_format::samples::{encode_block, tiny};
use pis_format::*;

/// `tiny`'s ball without its shell: a diffuse object whose checker layer holds an opacity
/// (from 0 at the left to 1 at the right) and colour premultiplied by it.
fn translucent() -> Container {
    let mut c = tiny().unwrap();
    let o = &mut c.objects[0];
    o.role = ObjectRole::Diffuse;
    o.layers.truncate(1);
    let l = &mut o.layers[0];
    l.channels = 4;
    let (w, h) = (8usize, 8usize);
    let texture = |light: u32| -> Vec<f32> {
        (0..w * h)
            .flat_map(|t| {
                let (x, y) = (t % w, t / w);
                let a = x as f32 / (w - 1) as f32;
                let check = if (x / 2 + y / 2) % 2 == 0 { 0.8 } else { 0.2 };
                let s = (0.5 + 0.5 * light as f32) * check * a;
                [s, s * 0.9, s * 0.7, a]
            })
            .collect()
    };
    let block = Block { levels: vec![], ..l.blocks[0].clone() };
    let layer = Layer { blocks: vec![], ..l.clone() };
    let samples = [texture(0), texture(1)];
    l.blocks =
        vec![encode_block(&layer, block, &[2], &[vec![1], vec![2]], &samples, CodecId::Lossless)
            .unwrap()];
    c
}

fn rules(c: &Container) -> Vec<u16> {
    validate_bytes(to_bytes_unchecked(c)).issues.iter().map(|i| i.id).collect()
}

#[test]
fn a_translucent_object_is_valid_and_written_as_minor_version_3() {
    let c = translucent();
    assert_eq!(rules(&c), Vec::<u16>::new());
    let bytes = to_bytes(&c).unwrap();
    assert_eq!(u16::from_le_bytes([bytes[10], bytes[11]]), 3, "minor version");
    let r = PisReader::from_bytes(bytes.clone()).unwrap();
    assert_eq!(r.load_all().unwrap(), c);
    let t = r.texture(0, 0, &[0, 1]).unwrap();
    assert_eq!(t.data.len(), 8 * 8 * 4, "four channels a texel");
    let opaque = to_bytes(&tiny().unwrap()).unwrap();
    assert_eq!(u16::from_le_bytes([opaque[10], opaque[11]]), 2, "a file without one");
}

/// A change made to a translucent file.
type Edit = fn(&mut Container);

#[test]
fn a_translucent_layer_adds_and_comes_first_and_its_object_has_no_shells() {
    let cases: [(&str, Edit); 4] = [
        ("multiplying", |c| c.objects[0].layers[0].combine = Combine::Multiply),
        ("order 1", |c| c.objects[0].layers[0].order = 1),
        ("with a shell", |c| {
            let shell = tiny().unwrap().objects[0].layers[1].clone();
            c.objects[0].role = ObjectRole::Reflective;
            c.objects[0].layers.push(shell);
        }),
        ("with a multiplying layer", |c| {
            let mut lighting = c.objects[0].layers[0].clone();
            lighting.channels = 3;
            lighting.order = 1;
            lighting.kind = LayerKind::Lighting;
            lighting.combine = Combine::Multiply;
            c.objects[0].layers.push(lighting);
        }),
    ];
    for (what, edit) in cases {
        let mut c = translucent();
        edit(&mut c);
        assert!(rules(&c).contains(&6003), "{what}: {:?}", rules(&c));
    }
}
