//! The largest valid file the spec's limits allow for its size (SPEC.md section 12), built
//! at run time: `HUGE_LAYERS` diffuse layers whose one level image is a 16384 × 16384
//! texture with its MIP chain stored (4 GiB decoded each, from an empty `wavelet`
//! codestream: all zeros, section 11.2), and one small `raw` specular layer whose codestream
//! raises C, the bytes the level images read, to what those textures need:
//! 8192 × C ≥ 4 GiB per image and 131072 × C ≥ every image together. About 530 KB on disk.

use std::path::Path;

use pis_format::{
    Block, CodecId, Codestream, Container, Layer, LayerKind, Level, MipMode, Placement,
};

/// The texture side of the huge layers: the spec's largest (section 12).
pub const SIDE: u32 = 16384;
/// The raw layer's size: its 256 × 171 × 3 values × 4 bytes (525,312) are C.
pub const RAW: (u32, u32) = (256, 171);
/// As many 4 GiB level images as 131072 × C allows beside the raw one.
pub const HUGE_LAYERS: usize = 16;

/// Bytes one huge level image decodes to: every MIP level of a 16384² RGB texture, `f32`.
pub fn huge_image_bytes() -> u64 {
    image_bytes(SIDE)
}

/// Bytes a `side`² RGB texture with its MIP chain takes as `f32`.
pub fn image_bytes(side: u32) -> u64 {
    let mut texels = 0u64;
    let mut side = side as u64;
    loop {
        texels += side * side;
        if side == 1 {
            break;
        }
        side = side.div_ceil(2);
    }
    texels * 3 * 4
}

/// The container: the spec's worked example's quad and cameras, with the layers above.
pub fn largest_container() -> Container {
    container(SIDE, HUGE_LAYERS)
}

/// The worked example's quad and cameras with `layers` diffuse layers of one `side`²
/// texture each (its MIP chain stored, all zeros) and the raw specular layer.
pub fn container(side: u32, huge_layers: usize) -> Container {
    let mut c = pis_format::samples::minimal().expect("the spec's worked example");
    let object = &mut c.objects[0];
    let base = object.layers[0].clone();
    let huge_block = Block {
        width: side,
        height: side,
        placement: Placement::surface([1.0, 0.0, 0.0, 1.0, 0.0, 0.0]),
        levels: vec![Level {
            counts: vec![],
            images: vec![Codestream { codec: CodecId::Wavelet, bytes: vec![] }],
        }],
    };
    let mut layers: Vec<Layer> = (0..huge_layers)
        .map(|i| Layer {
            kind: LayerKind::Diffuse,
            order: i as u8,
            mip_mode: MipMode::Stored,
            gamma: 1.0,
            blocks: vec![huge_block.clone()],
            ..base.clone()
        })
        .collect();
    let (w, h) = RAW;
    let values: Vec<f32> = (0..w * h * 3).map(|i| (i % 7) as f32 / 64.0).collect();
    let shape = [pis_format::PlaneShape::new(w, h, 3)];
    let bytes = pis_codec::encode(CodecId::Raw, &shape, &values).expect("raw codestream");
    layers.push(Layer {
        kind: LayerKind::Specular,
        order: huge_layers as u8,
        gamma: 1.0,
        blocks: vec![Block {
            width: w,
            height: h,
            placement: Placement::surface([1.0, 0.0, 0.0, 1.0, 0.0, 0.0]),
            levels: vec![Level {
                counts: vec![],
                images: vec![Codestream { codec: CodecId::Raw, bytes }],
            }],
        }],
        ..base
    });
    object.layers = layers;
    c
}

/// Writes the largest valid file to `path`; returns its size in bytes.
pub fn write_largest(path: &Path) -> u64 {
    pis_format::write(path, &largest_container()).expect("the largest file is valid")
}

/// Writes [`container`]`(side, huge_layers)` to `path`; returns its size in bytes.
pub fn write_with(path: &Path, side: u32, huge_layers: usize) -> u64 {
    pis_format::write(path, &container(side, huge_layers)).expect("a valid file")
}
