//! A frame's relightable layers drawn as sums (`crate::relit`): the coefficient layers of
//! one term, order, block and parameter sample, each to be drawn times its weight for the
//! frame's lights, drawn once as Σ_c w_c · x_c. Each group's coefficient textures are
//! gathered into an array while they stay resident, and each sum is kept while the lights
//! and the textures it sums stay: a frame whose lights do not move sums nothing. A group
//! whose textures differ in layout, placement or blend weight is drawn coefficient by
//! coefficient.

use std::collections::HashMap;

use super::plan::{TextureKey, Wanted};
use super::resident::{GpuTexture, Textures};
use crate::gpu::Gpu;
use crate::relit::{CoefficientArray, RelitSum, MAX_COEFFICIENTS};
use crate::textured::ObjectTexture;

/// A sum: the textures it adds and their weights (RGB, as bits).
pub(super) type SumKey = (Vec<TextureKey>, Vec<[u32; 3]>);

/// What one surface draw of a frame shows: `plan.surfaces[i]` as it is, or the sum `key`
/// in place of the group that `plan.surfaces[i]` heads.
pub(super) struct SurfaceItem {
    pub(super) surface: usize,
    pub(super) sum: Option<SumKey>,
}

/// The sums and coefficient arrays on the GPU, with the frame that last used each.
pub(super) struct RelitTextures {
    summing: RelitSum,
    arrays: HashMap<Vec<TextureKey>, (CoefficientArray, u64)>,
    sums: HashMap<SumKey, (ObjectTexture, u64)>,
    /// Sums no longer drawn, whose textures a new sum of their layout writes into: while a
    /// light moves, each frame's sums replace the last frame's without allocating.
    spare: Vec<ObjectTexture>,
    frame: u64,
}

impl RelitTextures {
    pub(super) fn new(gpu: &Gpu) -> RelitTextures {
        RelitTextures {
            summing: RelitSum::new(gpu),
            arrays: HashMap::new(),
            sums: HashMap::new(),
            spare: Vec::new(),
            frame: 0,
        }
    }

    /// The frame's surface draws: every surface not a relightable coefficient as it is, each
    /// group of coefficients that can be summed as its sum (made now where missing, recorded
    /// into `encoder`), the others coefficient by coefficient.
    pub(super) fn items(
        &mut self,
        gpu: &Gpu,
        textures: &Textures,
        surfaces: &[Wanted],
        encoder: &mut wgpu::CommandEncoder,
    ) -> Vec<SurfaceItem> {
        let mut groups: Vec<(&Vec<u32>, Vec<usize>)> = Vec::new();
        let mut items = Vec::with_capacity(surfaces.len());
        for (i, w) in surfaces.iter().enumerate() {
            match &w.relit {
                None => items.push(SurfaceItem { surface: i, sum: None }),
                Some(g) => match groups.iter_mut().find(|(k, _)| *k == g) {
                    Some((_, members)) => members.push(i),
                    None => groups.push((g, vec![i])),
                },
            }
        }
        for (_, members) in groups {
            match self.sum_of(gpu, textures, surfaces, &members, encoder) {
                Some(key) => items.push(SurfaceItem { surface: members[0], sum: Some(key) }),
                None => {
                    items.extend(members.into_iter().map(|i| SurfaceItem { surface: i, sum: None }))
                }
            }
        }
        items
    }

    /// The sum of the coefficients `members` of `surfaces`, made where missing; `None` where
    /// they cannot be summed.
    fn sum_of(
        &mut self,
        gpu: &Gpu,
        textures: &Textures,
        surfaces: &[Wanted],
        members: &[usize],
        encoder: &mut wgpu::CommandEncoder,
    ) -> Option<SumKey> {
        if members.len() < 2 || members.len() > MAX_COEFFICIENTS {
            return None;
        }
        let first = &surfaces[members[0]];
        let mut maps = Vec::with_capacity(members.len());
        for &i in members {
            let w = &surfaces[i];
            let GpuTexture::Surface(t) = textures.get(&w.key) else { return None };
            maps.push(t);
            let same = w.transform == first.transform
                && w.repeat == first.repeat
                && w.weight == first.weight
                && t.layout == maps[0].layout;
            if !same {
                return None;
            }
        }
        let keys: Vec<TextureKey> = members.iter().map(|&i| surfaces[i].key.clone()).collect();
        let weights: Vec<[f32; 3]> = members.iter().map(|&i| surfaces[i].tint).collect();
        let key: SumKey = (keys.clone(), weights.iter().map(|w| w.map(f32::to_bits)).collect());
        let frame = self.frame;
        if let Some(sum) = self.sums.get_mut(&key) {
            sum.1 = frame;
            return Some(key);
        }
        let array = self
            .arrays
            .entry(keys)
            .or_insert_with(|| (self.summing.gather(gpu, &maps, encoder), frame));
        array.1 = frame;
        let layout = array.0.layout();
        let reuse =
            self.spare.iter().position(|t| t.layout == layout).map(|i| self.spare.swap_remove(i));
        let sum = self.summing.sum(gpu, (&array.0, &weights), (textures.mips(), reuse), encoder);
        self.sums.insert(key.clone(), (sum, frame));
        Some(key)
    }

    /// The sum of `key`, made this frame by [`Self::items`].
    pub(super) fn get(&self, key: &SumKey) -> &ObjectTexture {
        &self.sums[key].0
    }

    /// Ends the frame: the arrays it did not use released, the sums it did not use kept as
    /// spares for the next frame's sums (those it does not take then released).
    pub(super) fn end_frame(&mut self) {
        let frame = self.frame;
        let (kept, stale): (HashMap<_, _>, HashMap<_, _>) =
            std::mem::take(&mut self.sums).into_iter().partition(|(_, s)| s.1 == frame);
        self.sums = kept;
        self.spare = stale.into_values().map(|(t, _)| t).collect();
        self.arrays.retain(|_, a| a.1 == frame);
        self.frame += 1;
    }
}
