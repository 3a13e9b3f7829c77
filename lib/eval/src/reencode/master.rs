//! Where `pis-reencode` takes its textures from: the file's lossless master (SPEC.md 6.7) or
//! its decoded level images, one parameter block at a time; and how far a file's decoded
//! textures are from the master.

use crate::diff::decode::decode_block;
use crate::metrics::SquaredError;
use pis_format::blocks::BlockGrid;
use pis_format::master::sample_point;
use pis_format::{Container, Error, LevelLayout, Master, ParameterSpace, PisReader, StreamRef};
use rayon::prelude::*;

/// The linear textures of one parameter block.
pub struct BlockSource {
    pub layout: LevelLayout,
    pub extent: Vec<u32>,
    /// Per block-local sample (row-major over the extent): its linear values.
    pub textures: Vec<Vec<f32>>,
    /// Per block-local sample: its index in a table over the layer's dimensions.
    pub tables: Vec<usize>,
    /// Per block-local sample: the master's screen weights (one per finest texel), where the
    /// master carries them.
    pub weights: Option<Vec<Vec<f32>>>,
}

/// The index of a layer sample (sample indices over the masked dimensions) in a table over
/// them (SPEC.md 6.2).
fn table_index<S>(c: &Container<S>, object: usize, layer: usize, key: &[u32]) -> usize {
    let mask = c.objects[object].layers[layer].depends_on;
    mask.dims().zip(key).fold(0usize, |a, (k, &s)| a * c.space.dims[k].values.len() + s as usize)
}

/// Every block of layer `layer` of object `object` from the master `m`: the textures exactly
/// as the writer solved them.
pub fn from_master(
    c: &Container<StreamRef>,
    m: &Master,
    object: usize,
    layer: usize,
) -> Result<Vec<BlockSource>, Error> {
    let o = &c.objects[object];
    let l = &o.layers[layer];
    let n = c.space.table_len(l.depends_on) as usize;
    let all = (0..n)
        .into_par_iter()
        .map(|s| m.texture(c, layer, s))
        .collect::<Result<Vec<Vec<f32>>, Error>>()?;
    let weights = (0..n)
        .into_par_iter()
        .map(|s| m.weights(c, layer, s))
        .collect::<Result<Vec<Option<Vec<f32>>>, Error>>()?;
    let layouts: Vec<LevelLayout> = l.blocks.iter().map(|b| LevelLayout::of(l, b)).collect();
    group(c, &c.space, &o.stagger, object, layer, &layouts, all, weights)
}

/// Table samples (`textures` and their screen `weights`, in table order) grouped into the
/// blocks of the grid of `space` and `stagger`, block i with `layouts[i]`. Weights are kept
/// where every sample has them.
#[allow(clippy::too_many_arguments)]
fn group<S>(
    c: &Container<S>,
    space: &ParameterSpace,
    stagger: &[u32],
    object: usize,
    layer: usize,
    layouts: &[LevelLayout],
    textures: Vec<Vec<f32>>,
    weights: Vec<Option<Vec<f32>>>,
) -> Result<Vec<BlockSource>, Error> {
    let l = &c.objects[object].layers[layer];
    let grid = BlockGrid::new(space, l.depends_on, stagger);
    let has_weights = !weights.is_empty() && weights.iter().all(Option::is_some);
    if layouts.len() != grid.block_count() as usize {
        return Err(Error::Request(format!(
            "object {object} layer {layer}: {} block layouts for {} blocks",
            layouts.len(),
            grid.block_count()
        )));
    }
    let mut blocks: Vec<BlockSource> = layouts
        .iter()
        .enumerate()
        .map(|(bi, layout)| {
            let extent = grid.extent(bi);
            let count = extent.iter().map(|&e| e as usize).product();
            BlockSource {
                layout: layout.clone(),
                extent,
                textures: vec![Vec::new(); count],
                tables: vec![0; count],
                weights: has_weights.then(|| vec![Vec::new(); count]),
            }
        })
        .collect();
    for (s, (x, w)) in textures.into_iter().zip(weights).enumerate() {
        let pos = grid.locate(&sample_point(c, l, s as u64));
        let idx = pos
            .local
            .iter()
            .zip(&pos.extent)
            .fold(0usize, |a, (&i, &e)| a * e as usize + i as usize);
        let b = blocks.get_mut(pos.block).ok_or_else(|| {
            Error::Request(format!("object {object} layer {layer}: sample {s} lies in no block"))
        })?;
        b.textures[idx] = x;
        b.tables[idx] = s;
        if let (Some(ws), Some(w)) = (b.weights.as_mut(), w) {
            ws[idx] = w;
        }
    }
    Ok(blocks)
}

/// Every block of layer `layer` of object `object` decoded from the file's level images.
pub fn from_decoded(r: &PisReader, object: usize, layer: usize) -> Result<Vec<BlockSource>, Error> {
    let c = r.container();
    (0..c.objects[object].layers[layer].blocks.len())
        .into_par_iter()
        .map(|bi| {
            let b = decode_block(r, object, layer, bi)?;
            let tables = b.keys.iter().map(|k| table_index(c, object, layer, k)).collect();
            Ok(BlockSource {
                layout: b.layout,
                extent: b.extent,
                textures: b.textures,
                tables,
                weights: None,
            })
        })
        .collect()
}

/// Display error of `r`'s decoded textures against the master `masters` (one per object, of
/// a file with the same objects and layers): per object and overall, each layer sample
/// weighted by the parameter points that read it.
pub fn error_against(
    r: &PisReader,
    masters: &[Master],
) -> Result<(SquaredError, Vec<SquaredError>), Error> {
    let c = r.container();
    let points = c.space.point_count();
    let mut total = SquaredError::default();
    let mut objects = Vec::with_capacity(c.objects.len());
    for (oi, o) in c.objects.iter().enumerate() {
        let m = masters
            .iter()
            .find(|m| m.object as usize == oi)
            .ok_or_else(|| Error::Request(format!("object {oi} has no master")))?;
        let mut obj = SquaredError::default();
        for li in 0..o.layers.len() {
            let multiplicity = points / c.space.table_len(o.layers[li].depends_on).max(1);
            for b in from_decoded(r, oi, li)? {
                let errors = b
                    .textures
                    .par_iter()
                    .zip(&b.tables)
                    .map(|(x, &t)| {
                        let want = m.texture(c, li, t)?;
                        let mut e = SquaredError::default();
                        e.add_slices(x, &want);
                        Ok(e)
                    })
                    .collect::<Result<Vec<SquaredError>, Error>>()?;
                for e in errors {
                    obj.sum += e.sum * multiplicity as f64;
                    obj.count += e.count * multiplicity;
                    obj.max = obj.max.max(e.max);
                }
            }
        }
        total.merge(&obj);
        objects.push(obj);
    }
    Ok((total, objects))
}

/// The same samples grouped into the blocks of another grid (`pis-reencode --block`): `space`
/// holds the new block sizes, `stagger` the object's new block origins. Every block of the
/// layer must share one texture placement and size (`pis-pack --placement object`), since a
/// new block may gather samples of several old ones: textures placed per block (pis-pack's
/// default) are solved again for new blocks by packing with the new `--block`.
pub fn regroup<S>(
    c: &Container<S>,
    space: &ParameterSpace,
    stagger: &[u32],
    object: usize,
    layer: usize,
    old: Vec<BlockSource>,
) -> Result<Vec<BlockSource>, Error> {
    let l = &c.objects[object].layers[layer];
    let first = l
        .blocks
        .first()
        .ok_or_else(|| Error::Request(format!("object {object} layer {layer} has no blocks")))?;
    if l.blocks.iter().any(|b| !b.same_placement(first)) {
        return Err(Error::Request(format!(
            "object '{}' layer {layer}: its blocks place the texture differently (texture coordinates optimized per block); re-blocking needs one placement per layer: pack with --placement object, or pack again with the new --block",
            c.objects[object].name)));
    }
    let layout = old.first().map(|b| b.layout.clone()).ok_or_else(|| {
        Error::Request(format!("object {object} layer {layer}: no block sources"))
    })?;
    let n = c.space.table_len(l.depends_on) as usize;
    let mut textures: Vec<Option<Vec<f32>>> = vec![None; n];
    let mut weights: Vec<Option<Vec<f32>>> = vec![None; n];
    for b in old {
        let ws = b
            .weights
            .map(|w| w.into_iter().map(Some).collect::<Vec<_>>())
            .unwrap_or_else(|| vec![None; b.tables.len()]);
        for ((x, t), w) in b.textures.into_iter().zip(b.tables).zip(ws) {
            let slot = textures.get_mut(t).ok_or_else(|| {
                Error::Request(format!(
                    "object {object} layer {layer}: table sample {t} out of range"
                ))
            })?;
            *slot = Some(x);
            weights[t] = w;
        }
    }
    let textures = textures
        .into_iter()
        .enumerate()
        .map(|(s, x)| {
            x.ok_or_else(|| {
                Error::Request(format!(
                    "object {object} layer {layer}: table sample {s} is in no block"
                ))
            })
        })
        .collect::<Result<Vec<_>, Error>>()?;
    let blocks = BlockGrid::new(space, l.depends_on, stagger).block_count() as usize;
    group(c, space, stagger, object, layer, &vec![layout; blocks], textures, weights)
}
