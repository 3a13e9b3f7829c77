//! The adaptive Laplacian pyramid over a parameter-space block (thesis 4.3, SPEC.md 7.3 and
//! 8.4).
//!
//! A block holds one *finest sample* (a level image: the concatenated planes of a texture)
//! per parameter point of its extent `e`, row-major (the last dimension fastest). A pyramid
//! level has sample counts `c` (1 ≤ c_k ≤ e_k); its image `j` covers the finest samples `s`
//! with `floor(s_k · c_k / e_k) = j_k` in every dimension (SPEC.md's index rule), and a
//! finest sample is rebuilt by adding one image per level, top to finest.
//!
//! Levels are built from the top down. Level ℓ's target is a Gaussian-filtered, subsampled
//! version of the finest samples: along each dimension with `c_k < e_k`, image `j` weights
//! the finest samples by `exp(−(s − m_j)² / 2σ²)` with `m_j` the centre of the samples `j`
//! covers and `σ = e_k / (2 c_k)` (Burt's kernel has σ ≈ 0.95 for a factor of 2); along a
//! dimension with `c_k = e_k` it keeps each sample. The stored image is that target minus the
//! mean, over the samples it covers, of what the levels above already give them. The finest
//! level stores each sample minus the levels above, so reconstruction is exact before
//! quantization whatever the level sequence, including counts that do not nest (5 → 3 → 2).
//!
//! [`adaptive`] picks the sequence by a greedy search (thesis 4.3): from the finest level up,
//! each step tries every next-coarser level that keeps, halves (rounding up) or collapses to 1
//! each dimension (so 8×8 → 8×1 and 8×8 → 1×1 are candidates), scores the pyramid that this
//! candidate would complete if the top followed it, and keeps the cheapest.

use std::collections::HashMap;

use crate::{CodecError, CodecId, PlaneShape, Rate};

/// How a level's target is filtered from the finest samples.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PyramidFilter {
    /// Gaussian weights over parameter space (thesis 4.3).
    Gaussian,
    /// The mean of the samples a level image covers.
    Box,
}

/// One pyramid level: sample counts per dimension and one image per level sample,
/// row-major over the counts.
#[derive(Clone, Debug, PartialEq)]
pub struct PyramidLevel {
    pub counts: Vec<u32>,
    pub images: Vec<Vec<f32>>,
}

/// A block's pyramid, top (one sample) first, finest (the extent) last.
#[derive(Clone, Debug, PartialEq)]
pub struct Pyramid {
    pub extent: Vec<u32>,
    pub levels: Vec<PyramidLevel>,
}

/// SPEC.md 8.4: the index of the level image that finest sample `local` uses, row-major over
/// `floor(local_k · counts_k / extent_k)`.
pub fn level_image_index(counts: &[u32], local: &[u32], extent: &[u32]) -> usize {
    let mut idx = 0usize;
    for k in 0..counts.len() {
        let j = (local[k] as u64 * counts[k] as u64 / extent[k] as u64) as usize;
        idx = idx * counts[k] as usize + j;
    }
    idx
}

/// The sample indices (one per dimension) of entry `i` of a row-major table over `extent`.
pub fn unflatten(mut i: usize, extent: &[u32]) -> Vec<u32> {
    let mut out = vec![0; extent.len()];
    for k in (0..extent.len()).rev() {
        out[k] = (i % extent[k] as usize) as u32;
        i /= extent[k] as usize;
    }
    out
}

fn check(extent: &[u32], samples: &[Vec<f32>]) -> Result<usize, CodecError> {
    if extent.contains(&0) {
        return Err(CodecError::Input(format!("extent {extent:?} has an empty dimension")));
    }
    let count: usize = extent.iter().map(|&e| e as usize).product();
    if samples.len() != count {
        return Err(CodecError::Input(format!(
            "extent {extent:?} needs {count} samples, found {}",
            samples.len()
        )));
    }
    let n = samples[0].len();
    if samples.iter().any(|s| s.len() != n) {
        return Err(CodecError::Input("samples differ in length".into()));
    }
    Ok(n)
}

/// Weights (c × e, rows summing to 1) of one dimension's filter.
fn weights(c: u32, e: u32, filter: PyramidFilter) -> Vec<Vec<f64>> {
    let (c, e) = (c as usize, e as usize);
    let mut w = vec![vec![0.0f64; e]; c];
    for s in 0..e {
        w[s * c / e][s] = 1.0;
    }
    if c == e || filter == PyramidFilter::Box {
        for row in &mut w {
            let sum: f64 = row.iter().sum();
            row.iter_mut().for_each(|v| *v /= sum);
        }
        return w;
    }
    let sigma = e as f64 / (2.0 * c as f64);
    for row in &mut w {
        let members: Vec<usize> = (0..e).filter(|&s| row[s] > 0.0).collect();
        let centre = members.iter().sum::<usize>() as f64 / members.len() as f64;
        for (s, v) in row.iter_mut().enumerate() {
            *v = (-(s as f64 - centre).powi(2) / (2.0 * sigma * sigma)).exp();
        }
        let sum: f64 = row.iter().sum();
        row.iter_mut().for_each(|v| *v /= sum);
    }
    w
}

/// The filtered, subsampled targets of a level with `counts`.
fn targets(
    extent: &[u32],
    samples: &[Vec<f32>],
    counts: &[u32],
    filter: PyramidFilter,
) -> Vec<Vec<f32>> {
    let n = samples[0].len();
    let mut shape: Vec<usize> = extent.iter().map(|&e| e as usize).collect();
    let mut data: Vec<Vec<f64>> =
        samples.iter().map(|s| s.iter().map(|&v| v as f64).collect()).collect();
    for k in 0..extent.len() {
        if counts[k] == extent[k] {
            continue;
        }
        let w = weights(counts[k], extent[k], filter);
        let (c, e) = (counts[k] as usize, extent[k] as usize);
        let stride: usize = shape[k + 1..].iter().product();
        let total: usize = shape.iter().product::<usize>() / e * c;
        let mut out = vec![vec![0.0f64; n]; total];
        for (o, img) in out.iter_mut().enumerate() {
            let j = (o / stride) % c;
            let base = (o / (stride * c)) * (stride * e) + o % stride;
            for (s, &wt) in w[j].iter().enumerate() {
                if wt != 0.0 {
                    img.iter_mut().zip(&data[base + s * stride]).for_each(|(a, v)| *a += wt * v);
                }
            }
        }
        data = out;
        shape[k] = c;
    }
    data.into_iter().map(|d| d.into_iter().map(|v| v as f32).collect()).collect()
}

/// Builds the pyramid with the given level counts (top first; the first must be all ones,
/// the last the extent, counts non-decreasing).
pub fn build(
    extent: &[u32],
    samples: &[Vec<f32>],
    level_counts: &[Vec<u32>],
    filter: PyramidFilter,
) -> Result<Pyramid, CodecError> {
    check(extent, samples)?;
    let mut cache = HashMap::new();
    build_cached(extent, samples, level_counts, filter, &mut cache)
}

fn build_cached(
    extent: &[u32],
    samples: &[Vec<f32>],
    level_counts: &[Vec<u32>],
    filter: PyramidFilter,
    cache: &mut HashMap<Vec<u32>, Vec<Vec<f32>>>,
) -> Result<Pyramid, CodecError> {
    let valid = !level_counts.is_empty()
        && level_counts[0].iter().all(|&c| c == 1)
        && level_counts.last().map(Vec::as_slice) == Some(extent)
        && level_counts.iter().all(|c| c.len() == extent.len())
        && level_counts.windows(2).all(|w| w[0].iter().zip(&w[1]).all(|(a, b)| a <= b))
        && level_counts.iter().all(|c| c.iter().zip(extent).all(|(c, e)| *c >= 1 && c <= e));
    if !valid {
        return Err(CodecError::Input(format!(
            "level counts {level_counts:?} for extent {extent:?}"
        )));
    }
    let n = samples[0].len();
    let locals: Vec<Vec<u32>> = (0..samples.len()).map(|i| unflatten(i, extent)).collect();
    let mut above = vec![vec![0.0f32; n]; samples.len()];
    let mut levels = Vec::with_capacity(level_counts.len());
    for (li, counts) in level_counts.iter().enumerate() {
        let finest = li + 1 == level_counts.len();
        let count: usize = counts.iter().map(|&c| c as usize).product();
        let mut members = vec![Vec::new(); count];
        for (s, local) in locals.iter().enumerate() {
            members[level_image_index(counts, local, extent)].push(s);
        }
        let images: Vec<Vec<f32>> = if finest {
            samples
                .iter()
                .zip(&above)
                .map(|(s, a)| s.iter().zip(a).map(|(v, a)| v - a).collect())
                .collect()
        } else {
            let target = cache
                .entry(counts.clone())
                .or_insert_with(|| targets(extent, samples, counts, filter));
            target
                .iter()
                .zip(&members)
                .map(|(t, m)| {
                    let mut mean = vec![0.0f64; n];
                    for &s in m {
                        mean.iter_mut().zip(&above[s]).for_each(|(a, v)| *a += *v as f64);
                    }
                    let k = m.len().max(1) as f64;
                    t.iter().zip(&mean).map(|(t, a)| t - (a / k) as f32).collect()
                })
                .collect()
        };
        if !finest {
            for (img, m) in images.iter().zip(&members) {
                for &s in m {
                    above[s].iter_mut().zip(img).for_each(|(a, v)| *a += v);
                }
            }
        }
        levels.push(PyramidLevel { counts: counts.clone(), images });
    }
    Ok(Pyramid { extent: extent.to_vec(), levels })
}

impl Pyramid {
    /// Rebuilds finest sample `local` by SPEC.md 8.4: one image per level, summed in level
    /// order.
    pub fn sample(&self, local: &[u32]) -> Vec<f32> {
        let mut out = vec![0.0f32; self.levels[0].images[0].len()];
        for level in &self.levels {
            let img = &level.images[level_image_index(&level.counts, local, &self.extent)];
            out.iter_mut().zip(img).for_each(|(a, v)| *a += v);
        }
        out
    }

    /// Number of level images.
    pub fn image_count(&self) -> usize {
        self.levels.iter().map(|l| l.images.len()).sum()
    }
}

/// The next-coarser levels the greedy search tries from `counts`: each dimension kept,
/// halved (rounding up) or collapsed to 1, excluding `counts` itself.
pub fn coarser_candidates(counts: &[u32]) -> Vec<Vec<u32>> {
    let mut out: Vec<Vec<u32>> = vec![Vec::new()];
    for &c in counts {
        let mut options = vec![c, c.div_ceil(2), 1];
        options.dedup();
        out = out
            .into_iter()
            .flat_map(|prefix| {
                options.iter().map(move |&o| {
                    let mut p = prefix.clone();
                    p.push(o);
                    p
                })
            })
            .collect();
    }
    out.retain(|c| c.as_slice() != counts);
    out
}

/// A rate proxy for a level image: the sum of absolute values (what an entropy coder of a
/// Laplacian-distributed residual spends is roughly proportional to it).
pub fn l1_cost(image: &[f32]) -> f64 {
    image.iter().map(|v| v.abs() as f64).sum()
}

/// A rate score for [`adaptive`]: the bytes `codec` spends on a level image at `rate` (use a
/// quality, not a byte budget, so that the score tells levels apart).
pub fn codec_cost(
    codec: CodecId,
    planes: &[PlaneShape],
    rate: Rate,
) -> impl FnMut(&[f32]) -> f64 + '_ {
    move |img| {
        crate::encode_with(codec, planes, img, rate).map_or(f64::INFINITY, |b| b.len() as f64)
    }
}

/// The adaptive pyramid: greedy choice of each level's counts (module docs) under `cost`, a
/// rate (or rate–distortion) score of one level image, e.g. [`l1_cost`] or the byte count
/// of an encode at a fixed quality. Returns the pyramid and its total cost.
pub fn adaptive(
    extent: &[u32],
    samples: &[Vec<f32>],
    filter: PyramidFilter,
    mut cost: impl FnMut(&[f32]) -> f64,
) -> Result<(Pyramid, f64), CodecError> {
    check(extent, samples)?;
    let mut cache = HashMap::new();
    let ones = vec![1u32; extent.len()];
    // Chosen levels, finest first.
    let mut chosen = vec![extent.to_vec()];
    let mut total_of =
        |p: &Pyramid| -> f64 { p.levels.iter().flat_map(|l| &l.images).map(|i| cost(i)).sum() };
    let sequence = |chosen: &[Vec<u32>], next: &[u32]| {
        let mut seq = vec![ones.clone()];
        if next != ones.as_slice() {
            seq.push(next.to_vec());
        }
        seq.extend(chosen.iter().rev().cloned());
        seq.dedup();
        seq
    };
    if chosen[0] == ones {
        let p = build_cached(extent, samples, std::slice::from_ref(&ones), filter, &mut cache)?;
        let total = total_of(&p);
        return Ok((p, total));
    }
    loop {
        let current = chosen.last().cloned().unwrap_or_default();
        // A candidate's pyramid is scored and dropped: the search holds one at a time, and
        // builds the one chosen again at the end.
        let mut best: Option<(Vec<u32>, f64)> = None;
        for cand in coarser_candidates(&current) {
            let total = total_of(&build_cached(
                extent,
                samples,
                &sequence(&chosen, &cand),
                filter,
                &mut cache,
            )?);
            if best.as_ref().is_none_or(|b| total < b.1) {
                best = Some((cand, total));
            }
        }
        let Some((cand, total)) = best else {
            return Err(CodecError::Input("no coarser level".into()));
        };
        if cand == ones {
            let p = build_cached(extent, samples, &sequence(&chosen, &cand), filter, &mut cache)?;
            return Ok((p, total));
        }
        chosen.push(cand);
        // Later sequences hold the chosen levels and candidates coarser than the last: the
        // targets of no other counts are asked for again.
        let last = &chosen[chosen.len() - 1];
        cache.retain(|c, _| chosen.contains(c) || c.iter().zip(last).all(|(a, b)| a <= b));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Samples varying smoothly along dimension 0 and fast along dimension 1.
    fn block(extent: &[u32], n: usize) -> Vec<Vec<f32>> {
        let count: usize = extent.iter().map(|&e| e as usize).product();
        (0..count)
            .map(|i| {
                let l = unflatten(i, extent);
                (0..n)
                    .map(|t| {
                        let a = l.first().copied().unwrap_or(0) as f32;
                        let b = l.get(1).copied().unwrap_or(0) as f32;
                        (t as f32 * 0.3).sin()
                            + 0.05 * a
                            + if (b as u32).is_multiple_of(2) { 0.5 } else { -0.5 }
                    })
                    .collect()
            })
            .collect()
    }

    fn assert_exact(p: &Pyramid, samples: &[Vec<f32>]) {
        for (i, s) in samples.iter().enumerate() {
            let back = p.sample(&unflatten(i, &p.extent));
            for (a, b) in s.iter().zip(&back) {
                assert!((a - b).abs() < 1e-5, "sample {i}: {a} vs {b}");
            }
        }
    }

    #[test]
    fn exact_reconstruction_for_fixed_sequences() {
        for (extent, seq) in [
            (vec![8, 8], vec![vec![1, 1], vec![2, 2], vec![4, 4], vec![8, 8]]),
            (vec![8, 8], vec![vec![1, 1], vec![8, 1], vec![8, 8]]),
            (vec![5, 3], vec![vec![1, 1], vec![3, 2], vec![5, 3]]),
            (vec![5, 3], vec![vec![1, 1], vec![2, 1], vec![3, 3], vec![5, 3]]),
            (vec![7], vec![vec![1], vec![2], vec![4], vec![7]]),
            (vec![1], vec![vec![1]]),
        ] {
            let s = block(&extent, 13);
            for f in [PyramidFilter::Gaussian, PyramidFilter::Box] {
                let p = build(&extent, &s, &seq, f).unwrap();
                assert_exact(&p, &s);
            }
        }
    }

    #[test]
    fn adaptive_is_exact_and_prefers_the_coherent_dimension() {
        for extent in [vec![8, 8], vec![5, 3], vec![8], vec![]] {
            let s = block(&extent, 11);
            let (p, _) = adaptive(&extent, &s, PyramidFilter::Gaussian, l1_cost).unwrap();
            assert_exact(&p, &s);
            assert_eq!(p.levels[0].counts, vec![1; extent.len()]);
            assert_eq!(p.levels.last().unwrap().counts, extent);
        }
        // Dimension 1 alternates (incoherent), dimension 0 is smooth: the level under the
        // finest should subdivide dimension 1 fully and dimension 0 less.
        let s = block(&[8, 8], 11);
        let (p, _) = adaptive(&[8, 8], &s, PyramidFilter::Box, l1_cost).unwrap();
        let below = &p.levels[p.levels.len() - 2].counts;
        assert_eq!(below[1], 8, "{:?}", p.levels.iter().map(|l| &l.counts).collect::<Vec<_>>());
    }

    #[test]
    fn adaptive_with_a_codec_as_the_rate_score() {
        let extent = [4u32, 4];
        let s = block(&extent, 5 * 4 * 3);
        let planes = [PlaneShape::new(5, 4, 3)];
        let cost = codec_cost(CodecId::Dct, &planes, Rate::Quality(75));
        let (p, total) = adaptive(&extent, &s, PyramidFilter::Gaussian, cost).unwrap();
        assert_exact(&p, &s);
        assert!(total > 0.0 && total.is_finite());
    }

    #[test]
    fn index_rule_matches_the_spec_example() {
        // 5 samples, 2 level samples: floor(s·2/5) = 0,0,0,1,1.
        let idx: Vec<usize> = (0..5).map(|s| level_image_index(&[2], &[s], &[5])).collect();
        assert_eq!(idx, vec![0, 0, 0, 1, 1]);
    }

    #[test]
    fn candidates_include_jumps() {
        let c = coarser_candidates(&[8, 8]);
        assert!(c.contains(&vec![8, 1]) && c.contains(&vec![4, 4]) && c.contains(&vec![1, 1]));
        assert!(!c.contains(&vec![8, 8]));
    }
}
