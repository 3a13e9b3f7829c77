//! Every texture of one parameter block, decoded once: each level image is decoded a single
//! time and the block's samples are rebuilt by adding the images on their pyramid paths, top
//! first, then undoing gamma and MIP residuals (SPEC.md 8.4) — the same values, bit for bit,
//! as [`PisReader::texture`] gives one sample at a time.

use pis_codec::CodecError;
use pis_format::blocks::{level_image_index, BlockGrid};
use pis_format::issue::id;
use pis_format::reconstruct::finish;
use pis_format::{Error, Issue, LevelLayout, PisReader};
use rayon::prelude::*;

/// The decoded textures of one block of one layer.
pub struct BlockTextures {
    pub layout: LevelLayout,
    /// Samples per masked dimension.
    pub extent: Vec<u32>,
    /// Per block-local sample (row-major over the extent, the last dimension fastest): its
    /// sample index along each of the layer's dimensions.
    pub keys: Vec<Vec<u32>>,
    /// Per block-local sample: linear values of every plane, in [`LevelLayout::planes`] order.
    pub textures: Vec<Vec<f32>>,
}

fn unflatten(mut i: usize, extent: &[u32]) -> Vec<u32> {
    let mut out = vec![0; extent.len()];
    for k in (0..extent.len()).rev() {
        out[k] = (i % extent[k] as usize) as u32;
        i /= extent[k] as usize;
    }
    out
}

/// The first sample of block `block` along each masked dimension of the layer.
fn block_start(r: &PisReader, object: usize, layer: usize, block: usize) -> Vec<u32> {
    let c = r.container();
    let o = &c.objects[object];
    let l = &o.layers[layer];
    let grid = BlockGrid::new(&c.space, l.depends_on, &o.stagger);
    let per_axis = grid.blocks_per_axis();
    let mut coords = vec![0u64; per_axis.len()];
    let mut rest = block as u64;
    for k in (0..per_axis.len()).rev() {
        coords[k] = rest % per_axis[k];
        rest /= per_axis[k];
    }
    l.depends_on
        .dims()
        .zip(coords)
        .map(|(d, j)| {
            let size = c.space.dims[d].block_size as u64;
            (j * size).saturating_sub(o.stagger[d] as u64) as u32
        })
        .collect()
}

/// Decodes every sample of block `block` of layer `layer` of object `object`.
pub fn decode_block(
    r: &PisReader,
    object: usize,
    layer: usize,
    block: usize,
) -> Result<BlockTextures, Error> {
    let c = r.container();
    let l =
        c.objects.get(object).and_then(|o| o.layers.get(layer)).ok_or_else(|| {
            Error::Request(format!("object {object} layer {layer} does not exist"))
        })?;
    let b = l.blocks.get(block).ok_or_else(|| {
        Error::Request(format!("object {object} layer {layer} has no block {block}"))
    })?;
    let layout = LevelLayout::of(l, b);
    let planes = layout.planes();
    let start = block_start(r, object, layer, block);
    let extent = b.levels.last().map(|lv| lv.counts.clone()).unwrap_or_default();
    // Every level image, decoded once (the reader has checked each level's sizes).
    let jobs: Vec<(usize, usize)> = b
        .levels
        .iter()
        .enumerate()
        .flat_map(|(lv, level)| (0..level.images.len()).map(move |i| (lv, i)))
        .collect();
    let decoded = jobs
        .par_iter()
        .map(|&(lv, i)| {
            let s = &b.levels[lv].images[i];
            let bytes = r.codestream(s)?;
            let values = pis_codec::decode(s.codec, &planes, &bytes).map_err(|e| match e {
                CodecError::NotSupported(codec) => {
                    Error::NotSupported(format!("codec '{codec}' (object {object}, layer {layer})"))
                }
                e => Error::Invalid(
                    Issue::new(id::codestream::PLANES_MISMATCH, format!("object {object} layer {layer} block {block} level {lv}: {e}"))
                        .in_chunk("CSTR", s.chunk as usize),
                ),
            })?;
            if let Some(bad) = values.iter().position(|v| !v.is_finite()) {
                return Err(Error::Invalid(
                    Issue::new(
                        id::codestream::VALUE_NOT_FINITE,
                        format!("object {object} layer {layer} block {block} level {lv}: value {bad} is {}", values[bad]),
                    )
                    .in_chunk("CSTR", s.chunk as usize),
                ));
            }
            Ok(values)
        })
        .collect::<Result<Vec<Vec<f32>>, Error>>()?;
    let mut images: Vec<Vec<&[f32]>> = b.levels.iter().map(|_| Vec::new()).collect();
    for ((lv, _), v) in jobs.iter().zip(&decoded) {
        images[*lv].push(v);
    }
    let count: usize = extent.iter().map(|&e| e as usize).product();
    let samples: Vec<(Vec<u32>, Vec<f32>)> = (0..count)
        .into_par_iter()
        .map(|s| {
            let local = unflatten(s, &extent);
            let mut sum: Option<Vec<f32>> = None;
            for (level, imgs) in b.levels.iter().zip(&images) {
                let img = imgs[level_image_index(&level.counts, &local, &extent)];
                match &mut sum {
                    None => sum = Some(img.to_vec()),
                    Some(acc) => acc.iter_mut().zip(img).for_each(|(a, v)| *a += v),
                }
            }
            let key = local.iter().zip(&start).map(|(a, b)| a + b).collect();
            (key, finish(l, &layout, sum.unwrap_or_default()))
        })
        .collect();
    let (keys, textures) = samples.into_iter().unzip();
    Ok(BlockTextures { layout, extent, keys, textures })
}

/// The parameter point (one sample index per dimension; 0 along dimensions the layer ignores)
/// of a layer sample `key` over the dimensions in `mask`.
pub fn point_of(dims: usize, mask: pis_format::DepMask, key: &[u32]) -> Vec<u32> {
    let mut p = vec![0u32; dims];
    for (d, &v) in mask.dims().zip(key) {
        p[d] = v;
    }
    p
}
