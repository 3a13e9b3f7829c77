//! Cases of rules.rs kept apart: the many large level images of rule 6010, and the light
//! basis of relightable layers (rules 6011 and 9006).

use pis_format::samples::tiny;
use pis_format::*;

use super::{unchecked, File};

/// Rule 6010: the light dimension of `tiny` made 32 samples long, in one block, so that the
/// diffuse layer's block holds 63 level images (1 + 2 + … + 32) of a few bytes each; its
/// texture then declared 1024² texels. One level image (12 MiB) stays under 8192 × the
/// file's codestream bytes (2.4 KB), all 63 together exceed 131072 × them.
pub(crate) fn many_large_level_images() -> Vec<u8> {
    let mut c = tiny().unwrap();
    let light = &mut c.space.dims[1];
    light.values = (0..32).map(|i| i as f32 / 31.0).collect();
    light.block_size = 32;
    let layer = c.objects[0].layers[0].clone();
    let block = Block { levels: vec![], ..layer.blocks[0].clone() };
    let (w, h) = (block.width, block.height);
    let counts: Vec<Vec<u32>> = (0..6).map(|k| vec![1 << k]).collect();
    let textures: Vec<Vec<f32>> =
        (0..32).map(|i| vec![0.1 + 0.02 * i as f32; (w * h * 3) as usize]).collect();
    let block = pis_format::samples::encode_block(
        &layer,
        block,
        &[32],
        &counts,
        &textures,
        CodecId::Lossless,
    )
    .unwrap();
    c.objects[0].layers[0].blocks = vec![block];
    let mut f = File::of(&c);
    f.set_u32("layer 0 block 0 width", 1024).set_u32("layer 0 block 0 height", 1024).reseal()
}

/// Rules 6011 and 9006: a coefficient layer in a file without light directions, and light
/// directions naming no dimension.
pub(crate) fn light_basis_cases() -> Vec<(u16, Vec<u8>)> {
    vec![
        (6011, unchecked(|c| c.objects[0].layers[0].basis = 1)),
        (
            9006,
            unchecked(|c| {
                let p = c.provenance.as_mut().unwrap();
                p.settings.push(("light_directions.nobody".into(), "0,1,0".into()));
            }),
        ),
    ]
}
