//! Relightable layers (SPEC.md 7.1 and 6.6, since 1.6): a surface layer's spherical-harmonic
//! coefficients over the light directions the file records. Such a file is valid,
//! round-trips and is written as minor version 6; a coefficient layer that depends on the
//! light dimension, or is not a 3-channel added surface layer, is invalid.

use pis_format::relight::{light_directions, light_settings, LightDirections};
use pis_format::samples::{encode_block, tiny};
use pis_format::*;

/// `tiny` with its diffuse layer replaced by `n` coefficient layers that depend on no
/// dimension, and its light dimension's two directions recorded.
fn relightable(n: u8) -> Container {
    let mut c = tiny().unwrap();
    let diffuse = c.objects[0].layers.remove(0);
    let block = Block { levels: vec![], ..diffuse.blocks[0].clone() };
    let texels = (block.width * block.height * 3) as usize;
    for k in 0..n {
        let layer =
            Layer { basis: k + 1, depends_on: DepMask(0), blocks: vec![], ..diffuse.clone() };
        let values: Vec<f32> =
            (0..texels).map(|i| (i as f32 * 0.01 - 0.2) / (k + 1) as f32).collect();
        let b = encode_block(&layer, block.clone(), &[], &[vec![]], &[values], CodecId::Lossless)
            .unwrap();
        c.objects[0].layers.insert(k as usize, Layer { blocks: vec![b], ..layer });
    }
    let lights = LightDirections {
        dim: 1,
        radiance: [3.0, 3.0, 2.5],
        directions: vec![[0.0, 1.0, 0.0], [0.6, 0.8, 0.0]],
    };
    c.provenance.as_mut().unwrap().settings.extend(light_settings("light", &lights));
    c
}

fn rules(c: &Container) -> Vec<u16> {
    validate_bytes(to_bytes_unchecked(c)).issues.iter().map(|i| i.id).collect()
}

#[test]
fn a_relightable_file_is_valid_round_trips_and_is_minor_version_6() {
    let c = relightable(4);
    assert_eq!(rules(&c), Vec::<u16>::new());
    let bytes = to_bytes(&c).unwrap();
    assert_eq!(u16::from_le_bytes([bytes[10], bytes[11]]), 6);
    let r = PisReader::from_bytes(bytes).unwrap();
    assert_eq!(r.load_all().unwrap(), c);
    let lights = light_directions(c.provenance.as_ref(), &c.space).unwrap().unwrap();
    assert_eq!((lights.dim, lights.radiance), (1, [3.0, 3.0, 2.5]));
    // Negative coefficients come back exactly.
    let t = r.texture(0, 0, &[0, 0]).unwrap();
    assert!(t.data.iter().any(|v| *v < 0.0));
}

#[test]
fn a_coefficient_layer_must_not_vary_with_its_light_and_must_be_an_added_surface() {
    let mut c = relightable(2);
    c.objects[0].layers[1].basis = 1;
    assert_eq!(rules(&c), vec![6008], "two layers of coefficient 0");
    let mut c = relightable(1);
    c.objects[0].layers[1].basis = 2; // the shell
    assert_eq!(rules(&c), vec![6003]);
    let mut c = relightable(1);
    c.objects[0].layers[0].basis = 82;
    assert_eq!(rules(&c), vec![6003]);
    // A coefficient over the light dimension: what the shell (mask: view) may not be.
    let mut c = tiny().unwrap();
    c.objects[0].layers[0].basis = 1;
    c.provenance.as_mut().unwrap().settings.extend(light_settings(
        "light",
        &LightDirections { dim: 1, radiance: [1.0; 3], directions: vec![[0.0, 1.0, 0.0]; 2] },
    ));
    assert_eq!(rules(&c), vec![6011]);
}
