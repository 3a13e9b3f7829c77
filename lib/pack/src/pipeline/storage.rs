//! Level images and the storage they get: the adaptive Laplacian pyramid of one parameter
//! block (thesis 4.3), equal-slope storage allocation over every level image of every block,
//! layer and object with screen-area weights (4.5), and the encoding at the allocated rates.
//! `pis-pack` and `pis-reencode` code their textures through here.

use std::borrow::Cow;
use std::sync::Arc;

use anyhow::{anyhow, bail, Result};
use pis_codec::allocate::{allocate, Item, Target};
use pis_codec::pyramid::{
    adaptive, build, l1_cost, level_image_index, unflatten, Pyramid, PyramidFilter, PyramidLevel,
};
use pis_codec::{CodecId, LevelCodec, PlaneShape, Rate};
use rayon::prelude::*;

use super::scratch::{Reader, Scratch, Span, Writer};
use super::settings::MaxMse;

/// One pyramid level as coded: counts, the images as encoded, their codestreams.
pub type CodedLevel = (Vec<u32>, Vec<Vec<f32>>, Vec<Vec<u8>>);

/// The full pyramid's level counts, top first: every dimension halved (rounding up) per
/// level until one sample is left.
pub fn full_levels(extent: &[u32]) -> Vec<Vec<u32>> {
    let mut levels = vec![extent.to_vec()];
    while levels.last().is_some_and(|c| c.iter().any(|&v| v > 1)) {
        let next: Vec<u32> = levels[levels.len() - 1].iter().map(|v| v.div_ceil(2)).collect();
        levels.push(next);
    }
    levels.reverse();
    levels
}

/// One parameter block's pyramid, ready to be allocated and encoded.
#[derive(Clone)]
pub struct BlockPyramid {
    /// The object the block belongs to: an index into the allocation's screen areas.
    pub object: usize,
    pub planes: Vec<PlaneShape>,
    pub extent: Vec<u32>,
    /// Finest samples of the block's layer over all its blocks: a level image's weight in
    /// its object's error is the share of these samples it reaches.
    pub layer_samples: f64,
    /// Per level, top first: counts, images as encoded, codestreams (empty until encoded).
    pub levels: Vec<CodedLevel>,
    /// Screen weight of every texel of every finest sample (row-major over `extent`; one
    /// value per texel, mean 1 where the sample shows): how much of the screen each texel's
    /// error reaches. With them the allocation weighs texture error as screen error; None:
    /// every texel weighs the same. A block that is spilled drops them once its curves are
    /// measured.
    pub texel_weights: Option<Vec<Vec<f32>>>,
    /// Where a pack that streams keeps the level images ([`BlockPyramid::spill`]), one span
    /// per image in level and image order: each is then an empty vector in `levels` (the
    /// counts stay), and `rd` holds their rate–distortion items, measured before.
    pub spilled: Option<(Arc<Scratch>, Vec<Span>)>,
    pub rd: Option<Vec<Item>>,
}

impl BlockPyramid {
    /// The level images per level (read back from the scratch file where spilled).
    pub fn level_images(&self) -> Result<Vec<Cow<'_, [Vec<f32>]>>> {
        let Some((scratch, spans)) = &self.spilled else {
            return Ok(self.levels.iter().map(|l| Cow::Borrowed(l.1.as_slice())).collect());
        };
        let mut spans = spans.iter();
        let mut read = || -> Result<Vec<f32>> {
            let span = spans.next().ok_or_else(|| {
                anyhow!("a spilled block has fewer level images than its levels count")
            })?;
            let bytes = scratch.get(*span)?;
            let mut r = Reader::new(&bytes);
            let img = r.f32s()?;
            r.done()?;
            Ok(img)
        };
        self.levels
            .iter()
            .map(|l| (0..l.1.len()).map(|_| read()).collect::<Result<Vec<_>>>().map(Cow::Owned))
            .collect()
    }

    /// The allocation's item of every level image, in level and image order (with `c`, a
    /// lossy codec): its rate–distortion curve, weighed by the screen weights where the
    /// block has them, and the share of its layer's samples it reaches.
    fn items(&self, c: &dyn LevelCodec) -> Result<Vec<Item>> {
        if let Some(rd) = &self.rd {
            return Ok(rd.clone());
        }
        let count: usize = self.extent.iter().map(|&e| e as usize).product();
        let members: Vec<Vec<usize>> = self
            .levels
            .iter()
            .map(|(counts, images, _)| {
                let mut m = vec![0usize; images.len()];
                for s in 0..count {
                    m[level_image_index(counts, &unflatten(s, &self.extent), &self.extent)] += 1;
                }
                m
            })
            .collect();
        let refs: Vec<(usize, usize)> = self
            .levels
            .iter()
            .enumerate()
            .flat_map(|(lv, l)| (0..l.1.len()).map(move |ii| (lv, ii)))
            .collect();
        Ok(refs
            .par_iter()
            .map(|&(lv, ii)| {
                let values = &self.levels[lv].1[ii];
                let weights = level_image_weights(self, lv, ii, values.len());
                let curve = c.rd_curve_weighted(&self.planes, values, weights.as_deref())?;
                Ok(Item {
                    curve,
                    object: self.object,
                    weight: members[lv][ii] as f64 / self.layer_samples,
                })
            })
            .collect::<Result<Vec<Item>, pis_codec::CodecError>>()?)
    }

    /// Moves the level images to `scratch`, having measured their rate–distortion items
    /// for `codec` where it is lossy (a pack that streams).
    pub fn spill(&mut self, scratch: &Arc<Scratch>, codec: CodecId) -> Result<()> {
        if self.spilled.is_some() {
            return Ok(());
        }
        if codec.is_lossy() {
            let c = pis_codec::codec(codec)
                .ok_or_else(|| anyhow!("codec {codec} is not in this build"))?;
            self.rd = Some(self.items(c)?);
        }
        // The screen weights served the curves only.
        self.texel_weights = None;
        // One image at a time: the block's images are never held twice.
        let mut spans = Vec::new();
        for l in &mut self.levels {
            for img in &mut l.1 {
                let mut w = Writer::default();
                w.f32s(img);
                *img = Vec::new();
                spans.push(scratch.put(&w.0)?);
            }
        }
        self.spilled = Some((scratch.clone(), spans));
        Ok(())
    }
}

/// Builds the adaptive pyramid of a block's finest samples (gamma-compensated, row-major over
/// `extent`). With `exact` (lossless and raw codecs) the finest level is adjusted so that the
/// decoder's sum gives every sample back bit for bit.
///
/// `full`: every level of the pyramid over the block, without adaptive subdivision (the
/// baseline `pis-pack --pyramid full` compares against).
pub fn build_pyramid(
    object: usize,
    planes: Vec<PlaneShape>,
    extent: &[u32],
    samples: &[Vec<f32>],
    layer_samples: f64,
    exact: bool,
    full: bool,
) -> Result<BlockPyramid> {
    let mut pyr = if full {
        build(extent, samples, &full_levels(extent), PyramidFilter::Gaussian)?
    } else {
        adaptive(extent, samples, PyramidFilter::Gaussian, l1_cost)?.0
    };
    if exact {
        exact_finest(&mut pyr, samples, extent);
    }
    let levels = pyr
        .levels
        .into_iter()
        .map(|l| {
            let n = l.images.len();
            (l.counts, l.images, vec![Vec::new(); n])
        })
        .collect();
    Ok(BlockPyramid {
        object,
        planes,
        extent: extent.to_vec(),
        layer_samples,
        levels,
        texel_weights: None,
        spilled: None,
        rd: None,
    })
}

/// What the allocation gave: bytes per level image (in block, level, image order), or the
/// codec's default rate for exact codecs.
pub struct Storage {
    pub rates: Vec<Rate>,
    /// Bytes the allocation spends (lossy codecs).
    pub allocated: Option<usize>,
    pub level_images: usize,
    /// With [`MaxMse::Best`], the free allocation (rates and bytes) where the constraint
    /// changed it: the alternative to encode and compare.
    pub free: Option<(Vec<Rate>, usize)>,
}

/// The codec of a lossy `codec` id, or an error where this build lacks it.
fn lossy_codec(codec: CodecId) -> Result<&'static dyn LevelCodec> {
    pis_codec::codec(codec).ok_or_else(|| anyhow!("codec {codec} is not in this build"))
}

/// The allocation's items of every level image of `blocks` (with `c`, a lossy codec), in
/// block, level and image order; blocks in parallel, their level images in parallel within
/// each.
fn level_items(blocks: &[BlockPyramid], c: &dyn LevelCodec) -> Result<Vec<Item>> {
    Ok(blocks
        .par_iter()
        .map(|pb| pb.items(c))
        .collect::<Result<Vec<_>>>()?
        .into_iter()
        .flatten()
        .collect())
}

/// Measures every level image's rate–distortion item for a lossy `codec` once, so that
/// allocations that follow (a played-quality search) reuse them.
pub fn measure_items(blocks: &mut [BlockPyramid], codec: CodecId) -> Result<()> {
    if !codec.is_lossy() {
        return Ok(());
    }
    let c = lossy_codec(codec)?;
    blocks.par_iter_mut().try_for_each(|pb| -> Result<()> {
        pb.rd = Some(pb.items(c)?);
        Ok(())
    })
}

/// The highest PSNR (dB, peak 1) of the coded textures an allocation over `blocks` reaches:
/// every level image at its richest point, weighed as the allocation weighs it (at most
/// [`BEYOND_DB`], for a codec that reaches the textures exactly).
pub fn reachable_coding_db(blocks: &[BlockPyramid], codec: CodecId, areas: &[f64]) -> Result<f64> {
    let items = level_items(blocks, lossy_codec(codec)?)?;
    Ok(pis_codec::allocate::reachable_psnr(&items, areas, 1.0)?.min(BEYOND_DB))
}

/// Far above any lossy codec's reach (dB).
const BEYOND_DB: f64 = 1000.0;

/// Equal-slope allocation (thesis 4.5) over every level image of `blocks` for a lossy
/// `codec`: each level image's rate–distortion curve, weighted by the share of its layer's
/// samples it reaches and by its object's screen area `areas[object]`, with the max-MSE
/// constraint as `max_mse` asks (thesis 4.8). Exact codecs need no allocation.
pub fn allocate_storage(
    blocks: &[BlockPyramid],
    codec: CodecId,
    target: Target,
    areas: &[f64],
    max_mse: MaxMse,
) -> Result<Storage> {
    let refs: Vec<(usize, usize, usize)> = blocks
        .iter()
        .enumerate()
        .flat_map(|(b, pb)| {
            pb.levels
                .iter()
                .enumerate()
                .flat_map(move |(lv, l)| (0..l.1.len()).map(move |ii| (b, lv, ii)))
        })
        .collect();
    if !codec.is_lossy() {
        return Ok(Storage {
            rates: vec![Rate::Default; refs.len()],
            allocated: None,
            level_images: refs.len(),
            free: None,
        });
    }
    let items = level_items(blocks, lossy_codec(codec)?)?;
    let a = allocate(&items, areas, target, max_mse.alpha())?;
    // Two allocations of one byte budget compare by their predictions; a PSNR target asks
    // for the fewest bytes instead, and keeps the constraint.
    let free = match max_mse {
        MaxMse::Best(_) if matches!(target, Target::Bytes(_)) => {
            Some(allocate(&items, areas, target, None)?)
                .filter(|f| f.bytes != a.bytes)
                .map(|f| (f.bytes.into_iter().map(Rate::Bytes).collect(), f.total_bytes))
        }
        _ => None,
    };
    Ok(Storage {
        rates: a.bytes.into_iter().map(Rate::Bytes).collect(),
        allocated: Some(a.total_bytes),
        level_images: refs.len(),
        free,
    })
}

/// The screen weight of every value of level image `ii` of level `lv`: the mean of the
/// texel weights of the finest samples it reaches (its error adds to each of them), one
/// value per channel; `None` (texture error) when the weights do not cover its planes.
fn level_image_weights(pb: &BlockPyramid, lv: usize, ii: usize, values: usize) -> Option<Vec<f32>> {
    let maps = pb.texel_weights.as_ref()?;
    // Planes of interleaved channels (a surface texture's level 0, or a shell's faces and
    // MIP levels): one weight per texel of all planes.
    let channels = pb.planes.first()?.channels as usize;
    if pb.planes.iter().any(|p| p.channels as usize != channels) {
        return None;
    }
    let texels: usize = pb.planes.iter().map(|p| p.width as usize * p.height as usize).sum();
    if texels * channels != values || maps.iter().any(|m| m.len() != texels) {
        return None;
    }
    let counts = &pb.levels[lv].0;
    let mut sum = vec![0.0f64; texels];
    let mut n = 0usize;
    for (s, map) in maps.iter().enumerate() {
        if level_image_index(counts, &unflatten(s, &pb.extent), &pb.extent) == ii {
            sum.iter_mut().zip(map).for_each(|(a, w)| *a += *w as f64);
            n += 1;
        }
    }
    let n = n.max(1) as f64;
    Some(sum.iter().flat_map(|w| std::iter::repeat_n((w / n) as f32, channels)).collect())
}

/// Encodes every level image of `blocks` at its allocated rate into the blocks' codestream
/// slots; returns the bytes written.
pub fn encode_levels(blocks: &mut [BlockPyramid], codec: CodecId, rates: &[Rate]) -> Result<usize> {
    let streams = level_streams(blocks, codec, rates)?;
    let mut total = 0;
    for (pb, block) in blocks.iter_mut().zip(streams) {
        for (l, level) in pb.levels.iter_mut().zip(block) {
            total += level.iter().map(Vec::len).sum::<usize>();
            l.2 = level;
        }
    }
    Ok(total)
}

/// The codestreams of every level image of `blocks` at `rates` (in block, level, image
/// order), per block, level and image; the pyramids are left as they are.
pub fn level_streams(
    blocks: &[BlockPyramid],
    codec: CodecId,
    rates: &[Rate],
) -> Result<Vec<Vec<Vec<Vec<u8>>>>> {
    let c = pis_codec::codec(codec).ok_or_else(|| anyhow!("codec {codec} is not in this build"))?;
    // Each block's first rate.
    let mut first = Vec::with_capacity(blocks.len());
    let mut n = 0usize;
    for pb in blocks {
        first.push(n);
        n += pb.levels.iter().map(|l| l.1.len()).sum::<usize>();
    }
    if rates.len() < n {
        bail!("fewer rates ({}) than level images ({n})", rates.len());
    }
    blocks
        .par_iter()
        .zip(first)
        .map(|(pb, first)| {
            let images = pb.level_images()?;
            let jobs: Vec<(usize, usize, Rate)> = images
                .iter()
                .enumerate()
                .flat_map(|(lv, l)| (0..l.len()).map(move |ii| (lv, ii)))
                .enumerate()
                .map(|(k, (lv, ii))| (lv, ii, rates[first + k]))
                .collect();
            let streams = jobs
                .par_iter()
                .map(|&(lv, ii, rate)| c.encode(&pb.planes, &images[lv][ii], rate))
                .collect::<Result<Vec<Vec<u8>>, pis_codec::CodecError>>()?;
            let mut out: Vec<Vec<Vec<u8>>> =
                images.iter().map(|l| vec![Vec::new(); l.len()]).collect();
            for ((lv, ii, _), bytes) in jobs.into_iter().zip(streams) {
                out[lv][ii] = bytes;
            }
            Ok(out)
        })
        .collect()
}

/// Makes the finest level's residuals such that the decoder's f32 sum of the levels, top
/// first, gives back every sample bit for bit: the residual `x − s` is nudged by a few ulps
/// where rounding loses it; where no nudge works, the block falls back to a zero top level
/// and the samples themselves.
pub fn exact_finest(pyr: &mut Pyramid, samples: &[Vec<f32>], extent: &[u32]) {
    let n_levels = pyr.levels.len();
    let ok = (|| {
        let (coarse, finest) = pyr.levels.split_at_mut(n_levels.checked_sub(1)?);
        let finest = finest.first_mut()?;
        for (si, x) in samples.iter().enumerate() {
            let local = unflatten(si, extent);
            let mut sum = vec![0.0f32; x.len()];
            for l in coarse.iter() {
                let img = &l.images[level_image_index(&l.counts, &local, extent)];
                sum.iter_mut().zip(img).for_each(|(a, v)| *a += v);
            }
            let fi = level_image_index(&finest.counts, &local, extent);
            let r = &mut finest.images[fi];
            for ((rv, &sv), &xv) in r.iter_mut().zip(&sum).zip(x) {
                let mut c = xv - sv;
                let mut k: i32 = 0;
                while (sv + c).to_bits() != xv.to_bits() {
                    k += 1;
                    if k > 16 {
                        return None;
                    }
                    let step: i32 = (k + 1) / 2;
                    let base = xv - sv;
                    c = if k % 2 == 1 { nudge(base, step) } else { nudge(base, -step) };
                }
                *rv = c;
            }
        }
        Some(())
    })();
    if ok.is_none() && extent.iter().any(|&e| e > 1) {
        let ones = vec![1u32; extent.len()];
        let n = samples.first().map_or(0, Vec::len);
        pyr.levels = vec![
            PyramidLevel { counts: ones, images: vec![vec![0.0; n]] },
            PyramidLevel { counts: extent.to_vec(), images: samples.to_vec() },
        ];
    }
}

/// `v` moved by `ulps` representable steps (up when positive).
pub fn nudge(v: f32, ulps: i32) -> f32 {
    let mut x = v;
    for _ in 0..ulps.unsigned_abs() {
        x = if ulps > 0 { x.next_up() } else { x.next_down() };
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_level_image_weighs_the_mean_of_the_samples_it_reaches_per_channel() {
        // A 1-D block of 4 samples, 2 texels each, RGB; pyramid levels: 1 image, then 4.
        let extent = [4u32];
        let samples: Vec<Vec<f32>> = (0..4).map(|s| vec![s as f32; 6]).collect();
        let mut pb =
            build_pyramid(0, vec![PlaneShape::new(2, 1, 3)], &extent, &samples, 4.0, false, true)
                .unwrap();
        let maps = vec![vec![1.0, 0.0], vec![3.0, 0.0], vec![0.0, 2.0], vec![0.0, 2.0]];
        assert!(level_image_weights(&pb, 0, 0, 6).is_none(), "no weights: uniform");
        pb.texel_weights = Some(maps.clone());
        let top = 0;
        let finest = pb.levels.len() - 1;
        assert_eq!(pb.levels[top].1.len(), 1);
        // the top image reaches all four samples: the mean of the maps, per channel
        assert_eq!(
            level_image_weights(&pb, top, 0, 6).unwrap(),
            vec![1.0, 1.0, 1.0, 1.0, 1.0, 1.0]
        );
        // a finest image reaches its own sample only
        let idx = level_image_index(&pb.levels[finest].0, &[1], &extent);
        assert_eq!(
            level_image_weights(&pb, finest, idx, 6).unwrap(),
            vec![3.0, 3.0, 3.0, 0.0, 0.0, 0.0]
        );
        // maps of the wrong size are ignored rather than misread
        pb.texel_weights = Some(vec![vec![1.0; 3]; 4]);
        assert!(level_image_weights(&pb, top, 0, 6).is_none());
    }
}
