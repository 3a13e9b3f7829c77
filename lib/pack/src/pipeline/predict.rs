//! The pack's predicted quality: textures, as solved or as decoded, rebuilt into the MIP
//! chains the player draws, drawn through each point's render matrices and compared with the
//! traced images (the display error of thesis 4.8).
//!
//! A pack in memory holds one object's chains at a time. One that streams
//! ([`super::memory`]) builds a solved chain when a point reads it and spills the decoded
//! ones to its scratch file block by block, so that neither the prediction nor the solved
//! error holds more than one block's level images and one chain per layer.

use std::borrow::Cow;
use std::collections::BTreeMap;

use anyhow::Result;
use pis_codec::pyramid::{level_image_index, unflatten};
use pis_codec::CodecId;
use pis_format::precision::Level16;
use pis_format::reconstruct::finish;
use pis_format::{Block, LevelLayout};

use super::input::LoadedSet;
use super::model::{key, InferredLayer, ObjectModel};
use super::packed::{LayerTextures, Packed, Quality};
use super::textures::Textures;

/// Where [`display_error`] reads an object's texture chains, one sample at a time.
pub trait Chains {
    /// The MIP chain of layer `li`'s sample `k`; `None` where the layer has no such sample.
    fn chain(&self, li: usize, k: &[u32]) -> Result<Option<Cow<'_, [f32]>>>;
}

impl Chains for [LayerTextures] {
    fn chain(&self, li: usize, k: &[u32]) -> Result<Option<Cow<'_, [f32]>>> {
        Ok(self[li].get(k).map(|x| Cow::Borrowed(x.as_slice())))
    }
}

impl Chains for [Textures] {
    fn chain(&self, li: usize, k: &[u32]) -> Result<Option<Cow<'_, [f32]>>> {
        let t = &self[li];
        if t.contains_key(k) {
            t.get(k).map(Some)
        } else {
            Ok(None)
        }
    }
}

/// An object's solved textures, each chain rebuilt from its finest level when read.
pub struct SolvedChains<'a>(pub &'a ObjectModel);

impl Chains for SolvedChains<'_> {
    fn chain(&self, li: usize, k: &[u32]) -> Result<Option<Cow<'_, [f32]>>> {
        let l = &self.0.layers[li];
        if !l.textures.contains_key(k) {
            return Ok(None);
        }
        Ok(Some(Cow::Owned(solved_chain(l, k, &l.textures.get(k)?))))
    }
}

/// The MIP chain the player rebuilds from the finest level of `l`'s solved texture `x` of
/// sample `k`.
fn solved_chain(l: &InferredLayer, k: &[u32], x: &[f32]) -> Vec<f32> {
    l.form.drawn(k, l.form.stored(k, x))
}

/// The solved textures of `m` per layer, each as the MIP chain the player rebuilds from its
/// finest level.
pub fn solved_chains(m: &ObjectModel) -> Result<Vec<LayerTextures>> {
    m.layers
        .iter()
        .map(|l| {
            l.textures.iter().map(|r| r.map(|(k, x)| (k.clone(), solved_chain(l, k, &x)))).collect()
        })
        .collect()
}

/// The squared display error of object `m` drawn with `chains` through A at every point,
/// against the gold-standard layers, and the number of values it sums.
pub fn display_error(
    set: &LoadedSet,
    m: &ObjectModel,
    chains: &(impl Chains + ?Sized),
) -> Result<(f64, usize)> {
    let (mut sse, mut n) = (0.0f64, 0usize);
    let mut cursor = Cursor::new(m);
    for (p, s) in set.samples.iter().enumerate() {
        let v = m.views.get(p)?;
        let keys = cursor.advance(chains, s)?;
        let img = m.render_view(&v, p, &keys, &cursor.at());
        for (k, g) in img.iter().enumerate() {
            sse += (display(*g) - display(v.diffuse[k] + v.specular[k])).powi(2);
        }
        n += img.len();
    }
    Ok((sse, n))
}

/// A linear value as the display shows it (clamped, sRGB-encoded).
fn display(v: f32) -> f64 {
    crate::images::srgb_encode(v.clamp(0.0, 1.0)) as f64
}

/// The squared display difference between object `m` drawn with `chains` and drawn with
/// them rounded to half floats (as a player holding 16-bit textures draws it), at every
/// point, and the number of values it sums; `None` where a texel lies beyond the half-float
/// range.
pub fn half_float_error(
    set: &LoadedSet,
    m: &ObjectModel,
    chains: &(impl Chains + ?Sized),
) -> Result<Option<(f64, usize)>> {
    let (mut sse, mut n) = (0.0f64, 0usize);
    let mut cursor = Cursor::new(m);
    let mut halves: Vec<Option<Vec<f32>>> = m.layers.iter().map(|_| None).collect();
    for (p, s) in set.samples.iter().enumerate() {
        let v = m.views.get(p)?;
        let keys = cursor.advance(chains, s)?;
        let at = cursor.at();
        for (li, &changed) in cursor.changed.iter().enumerate() {
            if let (true, Some(x)) = (changed, at[li]) {
                let Some(h) = round_to_half(x) else { return Ok(None) };
                halves[li] = Some(h);
            } else if changed {
                halves[li] = None;
            }
        }
        let half_at: Vec<Option<&[f32]>> = halves.iter().map(|h| h.as_deref()).collect();
        let full = m.render_view(&v, p, &keys, &at);
        let half = m.render_view(&v, p, &keys, &half_at);
        sse +=
            full.iter().zip(&half).map(|(a, b)| (display(*a) - display(*b)).powi(2)).sum::<f64>();
        n += full.len();
    }
    Ok(Some((sse, n)))
}

/// `x` rounded to the nearest half floats; `None` where a value lies beyond their range
/// (±65504, a NaN).
fn round_to_half(x: &[f32]) -> Option<Vec<f32>> {
    x.iter().map(|&v| Some(half::f16::from_f32(v).to_f32()).filter(|h| h.is_finite())).collect()
}

/// The chain each layer of an object read last, kept while consecutive points share the
/// samples of a layer that does not depend on the fastest dimension.
struct Cursor<'m, 'c> {
    m: &'m ObjectModel,
    last: Vec<Option<LastChain<'c>>>,
    /// Per layer, whether the last [`Cursor::advance`] read its chain.
    changed: Vec<bool>,
}

impl<'m, 'c> Cursor<'m, 'c> {
    fn new(m: &'m ObjectModel) -> Self {
        Cursor {
            m,
            last: m.layers.iter().map(|_| None).collect(),
            changed: vec![false; m.layers.len()],
        }
    }

    /// Moves to the parameter sample `s`: reads the chains of the layers whose key changed
    /// and returns every layer's key.
    fn advance<C: Chains + ?Sized>(&mut self, chains: &'c C, s: &[u32]) -> Result<Vec<Vec<u32>>> {
        let keys: Vec<Vec<u32>> = self.m.layers.iter().map(|il| key(s, il.depends_on)).collect();
        for (li, k) in keys.iter().enumerate() {
            self.changed[li] = self.last[li].as_ref().is_none_or(|(held, _)| held != k);
            if self.changed[li] {
                self.last[li] = Some((k.clone(), chains.chain(li, k)?));
            }
        }
        Ok(keys)
    }

    /// Every layer's chain at the current sample (none where the layer has no sample).
    fn at(&self) -> Vec<Option<&[f32]>> {
        self.last.iter().map(|l| l.as_ref().and_then(|(_, c)| c.as_deref())).collect()
    }
}

/// The solved error of `m` ([`Packed::solved_error`]): from chains held for the object, or,
/// for a pack that streams, built as the points read them.
pub fn solved_error(set: &LoadedSet, m: &ObjectModel) -> Result<(f64, usize)> {
    match set.scratch {
        Some(_) => display_error(set, m, &SolvedChains(m)),
        None => display_error(set, m, solved_chains(m)?.as_slice()),
    }
}

/// Decoded linear textures (whole MIP chain, rebuilt by decimation as the player does), per
/// object model and layer, keyed like [`super::model::InferredLayer::textures`].
pub fn decoded_textures(
    models: &[ObjectModel],
    packed: &Packed,
) -> Result<Vec<Vec<LayerTextures>>> {
    models
        .iter()
        .enumerate()
        .map(|(mi, m)| {
            let mut per_layer = vec![BTreeMap::new(); m.layers.len()];
            for_each_decoded(mi, m, packed, |li, k, x| {
                per_layer[li].insert(k, x);
                Ok(())
            })?;
            Ok(per_layer)
        })
        .collect()
}

/// Calls `f(layer, key, chain)` with every decoded chain of object model `mi`, `m`, one
/// block's level images decoded at a time.
fn for_each_decoded(
    mi: usize,
    m: &ObjectModel,
    packed: &Packed,
    f: impl FnMut(usize, Vec<u32>, Vec<f32>) -> Result<()>,
) -> Result<()> {
    for_each_rebuilt(mi, m, packed, false, f).map(|_| ())
}

/// [`for_each_decoded`] with, where `level16`, every decoded level image held in 16 bits a
/// value before the sum (`pis_format::precision::Level16`, as a player holding 16-bit level
/// images rebuilds them). Returns false, having stopped, where a value is not finite.
fn for_each_rebuilt(
    mi: usize,
    m: &ObjectModel,
    packed: &Packed,
    level16: bool,
    mut f: impl FnMut(usize, Vec<u32>, Vec<f32>) -> Result<()>,
) -> Result<bool> {
    for li in 0..m.layers.len() {
        let layer = &packed.container.objects[mi].layers[li];
        for (b, pb) in packed.blocks[mi][li].iter().enumerate() {
            let block = &layer.blocks[b];
            let layout = LevelLayout::of(layer, block);
            let planes = layout.planes();
            let mut decoded: Vec<Vec<Vec<f32>>> = pb
                .levels
                .iter()
                .map(|(_, _, streams)| {
                    streams
                        .iter()
                        .map(|s| pis_codec::decode(layer_codec(block), &planes, s))
                        .collect::<Result<Vec<_>, _>>()
                })
                .collect::<Result<_, _>>()?;
            if level16 {
                for img in decoded.iter_mut().flatten() {
                    match Level16::of(img) {
                        Some(l) => *img = l.values(),
                        None => return Ok(false),
                    }
                }
            }
            for (s, k) in pb.keys.iter().enumerate() {
                let local = unflatten(s, &pb.extent);
                let mut sum = vec![0.0f32; pis_codec::value_count(&planes)?];
                for ((counts, _, _), imgs) in pb.levels.iter().zip(&decoded) {
                    let img = &imgs[level_image_index(counts, &local, &pb.extent)];
                    sum.iter_mut().zip(img).for_each(|(a, v)| *a += v);
                }
                let lin = finish(layer, &layout, sum);
                f(li, k.clone(), m.layers[li].form.drawn(k, lin))?;
            }
        }
    }
    Ok(true)
}

fn layer_codec(block: &Block) -> CodecId {
    block.levels.first().and_then(|l| l.images.first()).map_or(CodecId::Raw, |c| c.codec)
}

/// PSNR in dB (peak 1) of squared error sums over their numbers of values, summed.
pub fn total_psnr(e: &[(f64, usize)]) -> f64 {
    let (s, n) = e.iter().fold((0.0, 0), |a, x| (a.0 + x.0, a.1 + x.1));
    psnr(s, n)
}

/// PSNR in dB (peak 1) of a squared error sum over `n` values.
pub fn psnr(sse: f64, n: usize) -> f64 {
    10.0 * (1.0 / (sse / n.max(1) as f64).max(1e-20)).log10()
}

/// The chain a layer read last: its key, and the chain (none where the layer has no sample
/// there).
type LastChain<'a> = (Vec<u32>, Option<Cow<'a, [f32]>>);

/// Renders the decoded and the solved textures through the render matrices (the hardware
/// model's or probe mode's). Object by object, each decoded chain is compared with the
/// solved one, kept (held, or spilled when the pack streams), and drawn at every point.
pub fn predicted_psnr(set: &LoadedSet, models: &[ObjectModel], packed: &Packed) -> Result<Quality> {
    if let Some(q) = &packed.quality {
        return Ok(q.clone());
    }
    let mut max_err = 0.0f32;
    let mut e_dec = Vec::with_capacity(models.len());
    for (mi, m) in models.iter().enumerate() {
        let solved = SolvedChains(m);
        let mut decoded: Vec<Textures> =
            m.layers.iter().map(|_| Textures::new(set.scratch.as_ref())).collect();
        for_each_decoded(mi, m, packed, |li, k, y| {
            if let Some(x) = solved.chain(li, &k)? {
                let n = m.layers[li].form.stored_texels(&k) * m.layers[li].form.channels();
                for (a, b) in x[..n].iter().zip(&y[..n]) {
                    max_err = max_err.max((a - b).abs());
                }
            }
            decoded[li].insert(k, y)
        })?;
        e_dec.push(display_error(set, m, decoded.as_slice())?);
    }
    let e_sol = &packed.solved_error;
    Ok(Quality {
        objects: e_dec.iter().zip(e_sol).map(|(a, b)| (psnr(a.0, a.1), psnr(b.0, b.1))).collect(),
        overall: total_psnr(&e_dec),
        overall_solved: total_psnr(e_sol),
        max_texel_error: max_err,
    })
}

/// The PSNR of frames drawn from the decoded textures rounded to half floats against frames
/// drawn from them in full, over every object and point (SPEC.md 6.6 `half_float_psnr_db`);
/// `None` where a texel lies beyond the half-float range.
pub fn half_float_psnr(
    set: &LoadedSet,
    models: &[ObjectModel],
    packed: &Packed,
) -> Result<Option<f64>> {
    psnr_over_objects(models, |mi, m| {
        let decoded = rebuilt_textures(set, (mi, m), packed, false)?.unwrap_or_default();
        half_float_error(set, m, decoded.as_slice())
    })
}

/// The PSNR of frames drawn from textures rebuilt from the level images held in 16 bits a
/// value against frames drawn from the textures as decoded, over every object and point
/// (SPEC.md 6.6 `level16_psnr_db`); `None` where a level image holds a value that is not
/// finite.
pub fn level16_psnr(
    set: &LoadedSet,
    models: &[ObjectModel],
    packed: &Packed,
) -> Result<Option<f64>> {
    psnr_over_objects(models, |mi, m| {
        let full = rebuilt_textures(set, (mi, m), packed, false)?.unwrap_or_default();
        let Some(held) = rebuilt_textures(set, (mi, m), packed, true)? else {
            return Ok(None);
        };
        frames_error(set, m, full.as_slice(), held.as_slice()).map(Some)
    })
}

/// The PSNR over every object of the squared errors `error` gives each (object index,
/// model); `None` as soon as one gives none.
fn psnr_over_objects(
    models: &[ObjectModel],
    mut error: impl FnMut(usize, &ObjectModel) -> Result<Option<(f64, usize)>>,
) -> Result<Option<f64>> {
    let mut errors = Vec::with_capacity(models.len());
    for (mi, m) in models.iter().enumerate() {
        match error(mi, m)? {
            Some(e) => errors.push(e),
            None => return Ok(None),
        }
    }
    Ok(Some(total_psnr(&errors)))
}

/// Every decoded chain of object model `mi`, `m`, per layer ([`for_each_rebuilt`]: from
/// level images held in 16 bits where `level16`); `None` where a level image holds a value
/// that is not finite.
fn rebuilt_textures(
    set: &LoadedSet,
    (mi, m): (usize, &ObjectModel),
    packed: &Packed,
    level16: bool,
) -> Result<Option<Vec<Textures>>> {
    let mut t: Vec<Textures> =
        m.layers.iter().map(|_| Textures::new(set.scratch.as_ref())).collect();
    let complete = for_each_rebuilt(mi, m, packed, level16, |li, k, y| t[li].insert(k, y))?;
    Ok(complete.then_some(t))
}

/// The squared display difference between object `m` drawn with chains `a` and with chains
/// `b` at every point, and the number of values it sums.
fn frames_error(
    set: &LoadedSet,
    m: &ObjectModel,
    a: &(impl Chains + ?Sized),
    b: &(impl Chains + ?Sized),
) -> Result<(f64, usize)> {
    let (mut sse, mut n) = (0.0f64, 0usize);
    let (mut ca, mut cb) = (Cursor::new(m), Cursor::new(m));
    for (p, s) in set.samples.iter().enumerate() {
        let v = m.views.get(p)?;
        let keys = ca.advance(a, s)?;
        cb.advance(b, s)?;
        let fa = m.render_view(&v, p, &keys, &ca.at());
        let fb = m.render_view(&v, p, &keys, &cb.at());
        sse += fa.iter().zip(&fb).map(|(x, y)| (display(*x) - display(*y)).powi(2)).sum::<f64>();
        n += fa.len();
    }
    Ok((sse, n))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn half_floats_round_within_their_range_and_refuse_beyond_it() {
        let h = round_to_half(&[0.0, 1.0, 0.1, -3.0e-6, 65504.0]).unwrap();
        assert_eq!(&h[..2], &[0.0, 1.0]);
        assert!((h[2] - 0.1).abs() <= 0.1 * 2f32.powi(-11) && h[2] != 0.1);
        assert!(h[3] < 0.0 && h[4] == 65504.0);
        assert_eq!(round_to_half(&[0.5, 70000.0]), None);
        assert_eq!(round_to_half(&[f32::NAN]), None);
    }
}
