//! The decoder's work, done on worker threads (never on the render thread): decoding level
//! images from their codestreams, and rebuilding a parameter sample's texture from the level
//! images on its pyramid path (sum, inverse gamma, stored MIP residuals: SPEC.md 8.4), at
//! full or reduced resolution: a surface texture as the finest GPU level padded for upload,
//! a shell's cube map as every face and MIP level in the cube layout's order.

use std::sync::Arc;

use pis_codec::{CodecError, PlaneShape};
use pis_compile::TextureLayout;
use pis_format::issue::id;
use pis_format::mip::{decimate, mip_size};
use pis_format::reconstruct::face_len;
use pis_format::texture::LevelLayout;
use pis_format::MipMode;
use pis_format::{Error, Issue, Layer, PisReader, StreamRef};
use rayon::prelude::*;

use crate::cube_atlas::CubeAtlas;
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

/// A rebuilt cube map ready to upload: its layout (six square faces and their MIP chains,
/// from the finest drawn level down) and its atlas images, RGBA f32 face after face, each
/// face's levels with their borders ([`CubeAtlas::border`]).
#[derive(Clone, Debug, PartialEq)]
pub struct CubeImage {
    pub layout: TextureLayout,
    pub atlas: CubeAtlas,
    pub texels: Vec<f32>,
}

impl CubeImage {
    /// The texels as RGBA f32 in the layout's order, face after face, each face's levels in
    /// order (SPEC.md 8.1).
    pub fn rgba(&self) -> Vec<f32> {
        self.atlas.interior(&self.layout, &self.texels)
    }
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
        CodecError::NotSupported(c) => {
            Error::NotSupported(format!("codec '{c}' (object {o}, layer {l})"))
        }
        e => Error::Invalid(
            Issue::new(
                id::codestream::PLANES_MISMATCH,
                format!("object {o} layer {l} block {b} level {lv}: {e}"),
            )
            .in_chunk("CSTR", job.stream.chunk as usize),
        ),
    })?;
    let want =
        pis_codec::value_count(&job.planes).map_err(|e| PlayError::Request(e.to_string()))?;
    if values.len() != want {
        return Err(Error::Invalid(Issue::new(id::codestream::PLANES_MISMATCH, format!("object {o} layer {l} block {b} level {lv}: {} values decoded, the planes hold {want}", values.len()))).into());
    }
    // A fold without an early exit, which the compiler vectorizes; the position only on failure.
    let finite = values.iter().fold(true, |all, v| all & v.is_finite());
    if let Some(bad) = (!finite).then(|| values.iter().position(|v| !v.is_finite())).flatten() {
        return Err(Error::Invalid(Issue::new(
            id::codestream::VALUE_NOT_FINITE,
            format!("object {o} layer {l} block {b} level {lv}: value {bad} is {}", values[bad]),
        ))
        .into());
    }
    Ok(values)
}

/// Values `at..at + out.len()` of a job's planes, linear (SPEC.md 8.4 steps 2–3): the level
/// images summed top first (the sum starts as the top level's copy, as the reader's does)
/// and inverse gamma. Element by element, so any split of a texture into spans gives the
/// values the whole gives.
fn linear_span(job: &AssembleJob, at: usize, out: &mut [f32]) {
    let len = out.len();
    match job.levels.first() {
        Some(top) => out.copy_from_slice(&top[at..at + len]),
        None => out.fill(0.0),
    }
    for img in job.levels.iter().skip(1) {
        out.iter_mut().zip(&img[at..at + len]).for_each(|(a, v)| *a += v);
    }
    pis_codec::gamma::uncompensate(out, job.layer.gamma);
}

/// Values per parallel piece of a texture's sum and inverse gamma.
const CHUNK: usize = 1 << 14;

/// One texel of `c` channels as RGBA: grey for 1 channel, grey and alpha for 2, opaque RGB
/// for 3.
fn rgba_texel(px: &[f32]) -> [f32; 4] {
    match px.len() {
        1 => [px[0], px[0], px[0], 1.0],
        2 => [px[0], px[0], px[0], px[1]],
        3 => [px[0], px[1], px[2], 1.0],
        _ => [px[0], px[1], px[2], px[3]],
    }
}

/// A level of `C`-channel texels written as RGBA texels into `out` ([`rgba_texel`]).
fn put_rgba<const C: usize>(level: &[f32], out: &mut [f32]) {
    level
        .chunks_exact(C)
        .zip(out.chunks_exact_mut(4))
        .for_each(|(px, o)| o.copy_from_slice(&rgba_texel(px)));
}

/// [`put_rgba`] for a level of `c` channels.
fn level_rgba(level: &[f32], c: u32, out: &mut [f32]) {
    match c {
        1 => put_rgba::<1>(level, out),
        2 => put_rgba::<2>(level, out),
        3 => put_rgba::<3>(level, out),
        _ => put_rgba::<4>(level, out),
    }
}

/// Rebuilds a texture: its finest level, linear, decimated `drop_levels` times, padded to
/// powers of two with its last column and row. At full resolution in one pass, bands of
/// rows on the workers: each band's values summed, inverse gamma and written as RGBA.
pub fn assemble(job: &AssembleJob) -> TextureImage {
    if job.drop_levels > 0 {
        return assemble_reduced(job);
    }
    let (w, h, c) = (job.layout.width, job.layout.height, job.layout.channels);
    let (pw, ph) = (w.next_power_of_two(), h.next_power_of_two());
    let (row_in, row_out) = ((w * c) as usize, pw as usize * 4);
    let mut rgba = vec![0.0f32; row_out * ph as usize];
    let band = (CHUNK / row_in).max(1);
    let (used, pad) = rgba.split_at_mut(row_out * h as usize);
    used.par_chunks_mut(row_out * band).enumerate().for_each(|(k, out)| {
        let mut linear = vec![0.0f32; out.len() / row_out * row_in];
        linear_span(job, k * band * row_in, &mut linear);
        for (row, o) in linear.chunks_exact(row_in).zip(out.chunks_exact_mut(row_out)) {
            padded_row(row, c, o);
        }
    });
    let last = &used[used.len() - row_out..];
    pad.chunks_exact_mut(row_out).for_each(|o| o.copy_from_slice(last));
    TextureImage { width: w, height: h, padded_width: pw, padded_height: ph, rgba }
}

/// A row of `c`-channel texels as RGBA at the start of `out`, its last texel repeated to
/// the end.
fn padded_row(row: &[f32], c: u32, out: &mut [f32]) {
    let (used, pad) = out.split_at_mut(row.len() / c as usize * 4);
    level_rgba(row, c, used);
    let last = &used[used.len() - 4..];
    pad.chunks_exact_mut(4).for_each(|t| t.copy_from_slice(last));
}

/// [`assemble`] at a resolution reduction: the finest level, linear, decimated `drop_levels`
/// times.
fn assemble_reduced(job: &AssembleJob) -> TextureImage {
    let (w0, h0, c) = (job.layout.width, job.layout.height, job.layout.channels);
    let mut finest = vec![0.0f32; (w0 * h0 * c) as usize];
    finest.par_chunks_mut(CHUNK).enumerate().for_each(|(k, out)| linear_span(job, k * CHUNK, out));
    let (mut w, mut h) = (w0, h0);
    for m in 0..job.drop_levels {
        finest = decimate(&finest, w, h, c);
        (w, h) = mip_size(w0, h0, m + 1);
    }
    let (pw, ph) = (w.next_power_of_two(), h.next_power_of_two());
    let mut rgba = vec![0.0f32; pw as usize * ph as usize * 4];
    let (row_in, row_out) = ((w * c) as usize, pw as usize * 4);
    for (j, out) in rgba.chunks_exact_mut(row_out).enumerate() {
        let src = (j as u32).min(h - 1) as usize * row_in;
        padded_row(&finest[src..src + row_in], c, out);
    }
    TextureImage { width: w, height: h, padded_width: pw, padded_height: ph, rgba }
}

/// One face's MIP chain of a shell texture (face `f` of the job's planes), rebuilt level by
/// level: each stored level's values linear ([`linear_span`]), a stored MIP level with the
/// finest level decimated to its size added (mip mode `stored`, as
/// `pis_format::reconstruct::add_stored_mips`), the levels below the stored ones each the
/// previous decimated (SPEC.md 8.3); from level `drop` down, as RGBA texels written inside
/// their levels of the face's atlas image `image` (of `atlas`, whose level 0 is level `drop`).
fn face_chain(job: &AssembleJob, f: usize, drop: u32, (atlas, image): (&CubeAtlas, &mut [f32])) {
    let layout = &job.layout;
    let (n, c) = (layout.width, layout.channels);
    let residuals = job.layer.mip_mode == MipMode::Stored && layout.mips > 1;
    let mut at = f * face_len(layout);
    let mut level: Vec<f32> = Vec::new();
    // The finest level decimated to the current level's size, for stored residuals.
    let mut finest: Vec<f32> = Vec::new();
    for m in 0..pis_format::mip::mip_count(n, n) {
        let (w, h) = mip_size(n, n, m);
        let len = (w * h * c) as usize;
        if m < layout.mips {
            level.resize(len, 0.0);
            linear_span(job, at, &mut level);
            at += len;
            if residuals && m == 0 {
                finest.clone_from(&level);
            } else if residuals {
                let (pw, ph) = mip_size(n, n, m - 1);
                finest = decimate(&finest, pw, ph, c);
                level.iter_mut().zip(&finest).for_each(|(v, d)| *v += d);
            }
        } else {
            let (pw, ph) = mip_size(n, n, m - 1);
            level = decimate(&level, pw, ph, c);
        }
        if m >= drop {
            for (j, row) in level.chunks_exact((w * c) as usize).enumerate() {
                let start = atlas.texel(m - drop, 0, j as i64) * 4;
                level_rgba(row, c, &mut image[start..start + w as usize * 4]);
            }
        }
    }
}

/// Rebuilds a shell's cube map: each face's MIP chain from its finest drawn level (level
/// `drop_levels` of the stored chain, for a resolution reduction) down to 1×1 ([`face_chain`]),
/// as RGBA (a 3-channel shell opaque: alpha 1), bordered into its atlas; the faces on the
/// workers.
pub fn assemble_cube(job: &AssembleJob) -> CubeImage {
    let full = TextureLayout::cube(job.layout.width);
    let drop = job.drop_levels.min(full.levels - 1);
    let (size, _) = full.level_size(drop);
    let layout = TextureLayout { width: size, height: size, levels: full.levels - drop, faces: 6 };
    let atlas = CubeAtlas::of(&layout);
    let per_face = atlas.face_texels() * 4;
    let mut texels = vec![0.0f32; per_face * 6];
    texels
        .par_chunks_exact_mut(per_face)
        .enumerate()
        .for_each(|(f, image)| face_chain(job, f, drop, (&atlas, image)));
    atlas.fill_borders(&mut texels);
    CubeImage { layout, atlas, texels }
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

    /// Queues `work` on the workers; the caller does not wait.
    pub fn spawn(&self, work: impl FnOnce() + Send + 'static) {
        self.pool.spawn(work);
    }

    /// Decodes `jobs` on the workers; the caller waits.
    pub fn decode_levels(
        &self,
        reader: &PisReader,
        jobs: &[LevelJob],
    ) -> Vec<Result<Vec<f32>, PlayError>> {
        self.pool.install(|| jobs.par_iter().map(|j| decode_level(reader, j)).collect())
    }

    /// Rebuilds textures on the workers; the caller waits.
    pub fn assemble(&self, jobs: &[AssembleJob]) -> Vec<TextureImage> {
        self.pool.install(|| jobs.par_iter().map(assemble).collect())
    }

    /// Rebuilds cube maps on the workers; the caller waits.
    pub fn assemble_cubes(&self, jobs: &[AssembleJob]) -> Vec<CubeImage> {
        self.pool.install(|| jobs.par_iter().map(assemble_cube).collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use pis_format::mip::mip_count;
    use pis_format::reconstruct::prepare;
    use pis_format::{Combine, DepMask, LayerKind, Mapping, MipMode, Term};

    fn shell_layer(channels: u8, mip_mode: MipMode) -> Layer<StreamRef> {
        Layer {
            kind: LayerKind::EnvLocal,
            mapping: Mapping::Shell,
            channels,
            mip_mode,
            term: Term::Reflection,
            order: 0,
            combine: Combine::Over,
            basis: 0,
            gamma: 2.2,
            depends_on: DepMask::NONE,
            blocks: vec![],
        }
    }

    /// The level images a writer stores for `linear` (gamma, MIP residuals), split into two
    /// pyramid levels that sum to them.
    fn job<'a>(
        layer: &'a Layer<StreamRef>,
        layout: &LevelLayout,
        linear: &[f32],
        drop_levels: u32,
    ) -> AssembleJob<'a> {
        let stored = prepare(layer, layout, linear);
        let top: Vec<f32> = stored.iter().map(|v| v * 0.25).collect();
        let rest: Vec<f32> = stored.iter().zip(&top).map(|(v, t)| v - t).collect();
        AssembleJob {
            layer,
            layout: layout.clone(),
            levels: vec![Arc::new(top), Arc::new(rest)],
            drop_levels,
        }
    }

    fn values(n: usize) -> Vec<f32> {
        (0..n).map(|k| ((k as u64 * 2654435761 % 1000) as f32) / 1000.0).collect()
    }

    /// The reader's texture (`pis_format::reconstruct::finish` on the level images summed
    /// top first) as RGBA texels, `c` channels a texel.
    fn readers_rgba(job: &AssembleJob) -> Vec<f32> {
        let mut sum = job.levels[0].to_vec();
        for img in &job.levels[1..] {
            sum.iter_mut().zip(img.iter()).for_each(|(a, v)| *a += v);
        }
        let linear = pis_format::reconstruct::finish(job.layer, &job.layout, sum);
        let mut rgba = vec![0.0; linear.len() / job.layout.channels as usize * 4];
        level_rgba(&linear, job.layout.channels, &mut rgba);
        rgba
    }

    #[test]
    fn the_one_pass_rebuild_gives_the_readers_values_bit_for_bit() {
        // A surface of several bands of rows, not a power of two wide or high.
        let layer = Layer { mapping: Mapping::Surface, ..shell_layer(3, MipMode::Decimated) };
        let layout = LevelLayout { width: 300, height: 50, channels: 3, faces: 1, mips: 1 };
        let linear: Vec<f32> = values(300 * 50 * 3).iter().map(|v| 4.0 * v - 1.0).collect();
        let surface = job(&layer, &layout, &linear, 0);
        const { assert!(CHUNK / 900 < 50, "one band would hold every row") };
        let img = assemble(&surface);
        let want = readers_rgba(&surface);
        for j in 0..img.padded_height as usize {
            for i in 0..img.padded_width as usize {
                let src = (j.min(49) * 300 + i.min(299)) * 4;
                let got = &img.rgba[(j * 512 + i) * 4..(j * 512 + i) * 4 + 4];
                assert_eq!(got, &want[src..src + 4], "texel ({i}, {j})");
            }
        }
        // A cube map with stored MIP residuals, 4 channels.
        let layer = shell_layer(4, MipMode::Stored);
        let layout =
            LevelLayout { width: 9, height: 9, channels: 4, faces: 6, mips: mip_count(9, 9) };
        let n: usize = layout.planes().iter().map(|p| (p.width * p.height * 4) as usize).sum();
        let linear: Vec<f32> = values(n).iter().map(|v| 3.0 * v - 0.5).collect();
        let cube = job(&layer, &layout, &linear, 0);
        let got = assemble_cube(&cube).rgba();
        assert_eq!(got.len(), n / 4 * 4);
        assert!(got.iter().zip(readers_rgba(&cube)).all(|(a, b)| a == &b));
    }

    #[test]
    fn a_surface_texture_is_padded_with_its_last_column_and_row() {
        let layer = Layer {
            mapping: Mapping::Surface,
            mip_mode: MipMode::Decimated,
            ..shell_layer(3, MipMode::Decimated)
        };
        let layout = LevelLayout { width: 3, height: 3, channels: 3, faces: 1, mips: 1 };
        let linear = values(27);
        let img = assemble(&job(&layer, &layout, &linear, 0));
        assert_eq!((img.width, img.height, img.padded_width, img.padded_height), (3, 3, 4, 4));
        for j in 0..4usize {
            for i in 0..4usize {
                let src = (j.min(2) * 3 + i.min(2)) * 3;
                let want = [linear[src], linear[src + 1], linear[src + 2], 1.0];
                let got = &img.rgba[(j * 4 + i) * 4..(j * 4 + i) * 4 + 4];
                for (g, w) in got.iter().zip(want) {
                    assert!((g - w).abs() < 1e-5, "texel ({i}, {j}): {got:?} against {want:?}");
                }
            }
        }
    }

    #[test]
    fn a_stored_cube_map_is_rebuilt_face_after_face_level_after_level() {
        let layer = shell_layer(4, MipMode::Stored);
        let layout =
            LevelLayout { width: 5, height: 5, channels: 4, faces: 6, mips: mip_count(5, 5) };
        let n: usize =
            layout.planes().iter().map(|p| (p.width * p.height * p.channels) as usize).sum();
        let linear = values(n);
        let cube = assemble_cube(&job(&layer, &layout, &linear, 0));
        assert_eq!(cube.layout, TextureLayout::cube(5));
        let rgba = cube.rgba();
        assert_eq!(rgba.len(), cube.layout.texel_count() * 4);
        let worst = rgba.iter().zip(&linear).map(|(a, b)| (a - b).abs()).fold(0.0, f32::max);
        assert!(worst < 1e-5, "{worst}");
    }

    #[test]
    fn a_reduced_rgb_cube_map_starts_at_a_coarser_level_and_is_opaque() {
        let layer = shell_layer(3, MipMode::Stored);
        let layout =
            LevelLayout { width: 6, height: 6, channels: 3, faces: 6, mips: mip_count(6, 6) };
        let planes = layout.planes();
        let n: usize = planes.iter().map(|p| (p.width * p.height * 3) as usize).sum();
        let linear = values(n);
        let cube = assemble_cube(&job(&layer, &layout, &linear, 1));
        assert_eq!(cube.layout, TextureLayout::cube(3));
        // Per face, the stored levels 1.. as RGBA with alpha 1.
        let mut want = Vec::new();
        let mut at = 0;
        for (k, p) in planes.iter().enumerate() {
            let len = (p.width * p.height * 3) as usize;
            if !(k as u32).is_multiple_of(layout.mips) {
                linear[at..at + len]
                    .chunks_exact(3)
                    .for_each(|t| want.extend([t[0], t[1], t[2], 1.0]));
            }
            at += len;
        }
        let rgba = cube.rgba();
        assert_eq!(rgba.len(), want.len());
        let worst = rgba.iter().zip(&want).map(|(a, b)| (a - b).abs()).fold(0.0, f32::max);
        assert!(worst < 1e-5, "{worst}");
    }

    #[test]
    fn a_decimated_cube_map_gets_its_chain_by_decimation() {
        let layer = shell_layer(4, MipMode::Decimated);
        let layout = LevelLayout { width: 3, height: 3, channels: 4, faces: 6, mips: 1 };
        let linear = values(6 * 9 * 4);
        let cube = assemble_cube(&job(&layer, &layout, &linear, 0));
        assert_eq!(cube.layout, TextureLayout::cube(3));
        let rgba = cube.rgba();
        for face in 0..6u32 {
            let finest = &linear[face as usize * 36..face as usize * 36 + 36];
            let mut level = finest.to_vec();
            for m in 0..cube.layout.levels {
                if m > 0 {
                    let (w, h) = mip_size(3, 3, m - 1);
                    level = decimate(&level, w, h, 4);
                }
                let start = cube.layout.face_texel(face, m, 0, 0) * 4;
                let got = &rgba[start..start + level.len()];
                let worst = got.iter().zip(&level).map(|(a, b)| (a - b).abs()).fold(0.0, f32::max);
                assert!(worst < 1e-5, "face {face} level {m}: {worst}");
            }
        }
    }
}
