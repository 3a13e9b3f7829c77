//! The decoder's work, done on worker threads (never on the render thread): decoding level
//! images from their codestreams, and rebuilding a parameter sample's texture from the level
//! images on its pyramid path (sum, inverse gamma, SPEC.md "Reconstructing a texture"), at
//! full or reduced resolution, as the finest GPU level padded for upload.

use std::sync::Arc;

use pis_codec::{CodecError, PlaneShape};
use pis_format::mip::{decimate, mip_size};
use pis_format::texture::LevelLayout;
use pis_format::{Error, Issue, Layer, PisReader, StreamRef};
use rayon::prelude::*;

use crate::error::PlayError;

/// A level image to decode.
#[derive(Clone, Debug)]
pub struct LevelJob {
    pub stream: StreamRef,
    pub planes: Vec<PlaneShape>,
    /// For messages: object, layer, block, level.
    pub at: (usize, usize, usize, usize),
}

/// A texture to rebuild: its layer, its level images (top first), the resolution reduction
/// (MIP levels dropped, 0 for full resolution).
pub struct AssembleJob<'a> {
    pub layer: &'a Layer<StreamRef>,
    pub layout: LevelLayout,
    pub levels: Vec<Arc<Vec<f32>>>,
    pub drop_levels: u32,
}

/// A rebuilt texture ready to upload: the used size of its finest drawn level, and that level
/// as RGBA f32 in a `next_pow2(width) × next_pow2(height)` image, the last used column and
/// row repeated into the padding.
#[derive(Clone, Debug, PartialEq)]
pub struct TextureImage {
    pub width: u32,
    pub height: u32,
    pub padded_width: u32,
    pub padded_height: u32,
    pub rgba: Vec<f32>,
}

/// The pool of decoding threads.
pub struct Decoder {
    pool: rayon::ThreadPool,
}

/// Decodes one level image (its codestream read and checksum-verified by the reader).
pub fn decode_level(reader: &PisReader, job: &LevelJob) -> Result<Vec<f32>, PlayError> {
    let (o, l, b, lv) = job.at;
    let bytes = reader.codestream(&job.stream)?;
    let values = pis_codec::decode(job.stream.codec, &job.planes, &bytes).map_err(|e| match e {
        CodecError::NotSupported(c) => Error::NotSupported(format!("codec '{c}' (object {o}, layer {l})")),
        e => Error::Invalid(Issue::new(8005, format!("object {o} layer {l} block {b} level {lv}: {e}")).in_chunk("CSTR", job.stream.chunk as usize)),
    })?;
    let want = pis_codec::value_count(&job.planes).map_err(|e| PlayError::Request(e.to_string()))?;
    if values.len() != want {
        return Err(Error::Invalid(Issue::new(8005, format!("object {o} layer {l} block {b} level {lv}: {} values decoded, the planes hold {want}", values.len()))).into());
    }
    if let Some(bad) = values.iter().position(|v| !v.is_finite()) {
        return Err(Error::Invalid(Issue::new(8006, format!("object {o} layer {l} block {b} level {lv}: value {bad} is {}", values[bad]))).into());
    }
    Ok(values)
}

/// Rebuilds a texture: the level images summed (top first, as the encoder's prediction),
/// inverse gamma, the finest level decimated `drop_levels` times, padded to powers of two.
pub fn assemble(job: &AssembleJob) -> TextureImage {
    let n: usize = job.layout.planes().iter().map(|p| (p.width * p.height * p.channels) as usize).sum();
    let mut sum = vec![0.0f32; n];
    for img in &job.levels {
        sum.iter_mut().zip(img.iter()).for_each(|(a, v)| *a += v);
    }
    let linear = pis_format::reconstruct::finish(job.layer, &job.layout, sum);
    let (w0, h0, c) = (job.layout.width, job.layout.height, job.layout.channels);
    let mut finest = linear[..(w0 * h0 * c) as usize].to_vec();
    let (mut w, mut h) = (w0, h0);
    for m in 0..job.drop_levels {
        finest = decimate(&finest, w, h, c);
        (w, h) = mip_size(w0, h0, m + 1);
    }
    let (pw, ph) = (w.next_power_of_two(), h.next_power_of_two());
    let mut rgba = vec![0.0f32; pw as usize * ph as usize * 4];
    let c = c as usize;
    for j in 0..ph {
        for i in 0..pw {
            let src = (j.min(h - 1) * w + i.min(w - 1)) as usize * c;
            let dst = (j * pw + i) as usize * 4;
            let px = &finest[src..src + c];
            rgba[dst..dst + 4].copy_from_slice(&match c {
                1 => [px[0], px[0], px[0], 1.0],
                2 => [px[0], px[0], px[0], px[1]],
                3 => [px[0], px[1], px[2], 1.0],
                _ => [px[0], px[1], px[2], px[3]],
            });
        }
    }
    TextureImage { width: w, height: h, padded_width: pw, padded_height: ph, rgba }
}

impl Decoder {
    pub fn new(workers: usize) -> Result<Decoder, PlayError> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(workers.max(1))
            .thread_name(|i| format!("pis-decode-{i}"))
            .build()
            .map_err(|e| PlayError::Worker(e.to_string()))?;
        Ok(Decoder { pool })
    }

    /// Decodes `jobs` on the workers; the caller waits.
    pub fn decode_levels(&self, reader: &PisReader, jobs: &[LevelJob]) -> Vec<Result<Vec<f32>, PlayError>> {
        self.pool.install(|| jobs.par_iter().map(|j| decode_level(reader, j)).collect())
    }

    /// Rebuilds textures on the workers; the caller waits.
    pub fn assemble(&self, jobs: &[AssembleJob]) -> Vec<TextureImage> {
        self.pool.install(|| jobs.par_iter().map(assemble).collect())
    }
}
