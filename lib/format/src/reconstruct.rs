//! The steps after the pyramid sum (SPEC.md, "Reconstructing a texture"): inverse gamma,
//! then MIP residuals.

use crate::mip::{decimate, mip_size};
use crate::model::{Layer, MipMode};
use crate::texture::LevelLayout;

/// Turns the sum of a block's level images into linear texture values.
pub fn finish<S>(layer: &Layer<S>, layout: &LevelLayout, mut data: Vec<f32>) -> Vec<f32> {
    pis_codec::gamma::uncompensate(&mut data, layer.gamma);
    if layer.mip_mode == MipMode::Stored && layout.mips > 1 {
        data.chunks_exact_mut(face_len(layout)).for_each(|face| add_stored_mips(layout, face));
    }
    data
}

/// Values of one face of `layout`: its finest level and the MIP levels stored below it
/// (faces follow each other in a level layout's planes).
pub fn face_len(layout: &LevelLayout) -> usize {
    (0..layout.mips.max(1))
        .map(|m| {
            let (w, h) = mip_size(layout.width, layout.height, m);
            (w * h * layout.channels) as usize
        })
        .sum()
}

/// One face's stored MIP levels (linear residuals after inverse gamma) made levels: each has
/// the finest level decimated to its size added ([`finish`]'s last step, face by face, so
/// that a caller may run the faces in parallel).
pub fn add_stored_mips(layout: &LevelLayout, face: &mut [f32]) {
    let c = layout.channels;
    let (w0, h0) = (layout.width, layout.height);
    let len0 = (w0 * h0 * c) as usize;
    let mut decimated = face[..len0].to_vec();
    let mut offset = len0;
    for m in 1..layout.mips {
        let (w, h) = mip_size(w0, h0, m - 1);
        decimated = decimate(&decimated, w, h, c);
        let plane = &mut face[offset..offset + decimated.len()];
        plane.iter_mut().zip(&decimated).for_each(|(v, d)| *v += d);
        offset += decimated.len();
    }
}

/// The inverse of [`finish`] for writers: linear texture values to the values a pyramid
/// encodes (gamma applied, MIP levels below the finest as residuals).
pub fn prepare<S>(layer: &Layer<S>, layout: &LevelLayout, linear: &[f32]) -> Vec<f32> {
    let mut data = linear.to_vec();
    if layer.mip_mode == MipMode::Stored && layout.mips > 1 {
        let c = layout.channels;
        let mut start = 0;
        for _ in 0..layout.faces {
            let (w0, h0) = (layout.width, layout.height);
            let len0 = (w0 * h0 * c) as usize;
            let mut decimated = linear[start..start + len0].to_vec();
            let mut offset = start + len0;
            for m in 1..layout.mips {
                let (w, h) = mip_size(w0, h0, m - 1);
                decimated = decimate(&decimated, w, h, c);
                let plane = &mut data[offset..offset + decimated.len()];
                plane.iter_mut().zip(&decimated).for_each(|(v, d)| *v -= d);
                offset += decimated.len();
            }
            start = offset;
        }
    }
    pis_codec::gamma::compensate(&mut data, layer.gamma);
    data
}
