//! Parameter-space blocks with staggered origins (sections 4.1 and 4.7).
//!
//! Along a dimension with `n` samples, block size `B` and an object's origin offset `o`
//! (0 ≤ o < B), block j covers samples `max(0, j·B − o) .. min(n, (j+1)·B − o)` and there are
//! `ceil((n + o) / B)` blocks. A layer tiles only the dimensions it depends on; its blocks are
//! numbered row-major over them, the last dimension fastest.

use crate::{DepMask, ParameterSpace};

/// The block grid of one layer of one object.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BlockGrid {
    /// Per masked dimension (ascending): (dimension index, samples, block size, offset).
    axes: Vec<Axis>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Axis {
    dim: usize,
    n: u32,
    size: u32,
    offset: u32,
}

impl Axis {
    fn blocks(&self) -> u64 {
        (self.n as u64 + self.offset as u64).div_ceil(self.size as u64)
    }

    fn range(&self, j: u32) -> (u32, u32) {
        let lo = (j as u64 * self.size as u64).saturating_sub(self.offset as u64);
        let hi = ((j as u64 + 1) * self.size as u64 - self.offset as u64).min(self.n as u64);
        (lo as u32, hi as u32)
    }
}

/// Where a parameter point falls in a layer: which block, and the sample within it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BlockPosition {
    pub block: usize,
    /// Sample index within the block, per masked dimension.
    pub local: Vec<u32>,
    /// The block's extent (samples), per masked dimension.
    pub extent: Vec<u32>,
}

impl BlockGrid {
    /// The grid for a layer depending on `mask` of an object with block origin offsets
    /// `stagger`. The space, mask and stagger must already be valid.
    pub fn new(space: &ParameterSpace, mask: DepMask, stagger: &[u32]) -> Self {
        let axes = mask
            .dims()
            .map(|k| {
                let d = &space.dims[k];
                Axis { dim: k, n: d.values.len() as u32, size: d.block_size, offset: stagger[k] }
            })
            .collect();
        BlockGrid { axes }
    }

    /// Number of blocks.
    pub fn block_count(&self) -> u64 {
        self.axes.iter().map(Axis::blocks).product()
    }

    /// Blocks along each masked dimension.
    pub fn blocks_per_axis(&self) -> Vec<u64> {
        self.axes.iter().map(Axis::blocks).collect()
    }

    /// The extent (samples per masked dimension) of block `block`.
    pub fn extent(&self, block: usize) -> Vec<u32> {
        let coords = self.block_coords(block);
        self.axes
            .iter()
            .zip(coords)
            .map(|(a, j)| {
                let (lo, hi) = a.range(j);
                hi - lo
            })
            .collect()
    }

    fn block_coords(&self, mut block: usize) -> Vec<u32> {
        let mut coords = vec![0; self.axes.len()];
        for (i, a) in self.axes.iter().enumerate().rev() {
            let nb = a.blocks() as usize;
            coords[i] = (block % nb) as u32;
            block /= nb;
        }
        coords
    }

    /// The block holding parameter point `point` (sample index per dimension of the space).
    pub fn locate(&self, point: &[u32]) -> BlockPosition {
        let mut block = 0usize;
        let mut local = Vec::with_capacity(self.axes.len());
        let mut extent = Vec::with_capacity(self.axes.len());
        for a in &self.axes {
            let s = point[a.dim];
            let j = ((s + a.offset) / a.size) as usize;
            let (lo, hi) = a.range(j as u32);
            block = block * a.blocks() as usize + j;
            local.push(s - lo);
            extent.push(hi - lo);
        }
        BlockPosition { block, local, extent }
    }
}

/// The image of a pyramid level that a block-local sample reads: along each dimension,
/// level sample `floor(local · count / extent)`, numbered row-major.
pub fn level_image_index(counts: &[u32], local: &[u32], extent: &[u32]) -> usize {
    let mut index = 0usize;
    for ((&c, &s), &e) in counts.iter().zip(local).zip(extent) {
        let i = (s as u64 * c as u64 / e as u64) as usize;
        index = index * c as usize + i;
    }
    index
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Dimension, DimensionKind};

    fn space(n: &[u32], b: &[u32]) -> ParameterSpace {
        ParameterSpace {
            dims: n
                .iter()
                .zip(b)
                .enumerate()
                .map(|(k, (&n, &b))| Dimension {
                    name: format!("d{k}"),
                    kind: DimensionKind::Other,
                    periodic: false,
                    unit: String::new(),
                    block_size: b,
                    values: (0..n).map(|i| i as f32).collect(),
                })
                .collect(),
        }
    }

    #[test]
    fn staggered_blocks_cover_every_sample_once() {
        let s = space(&[19], &[8]);
        for offset in 0..8 {
            let g = BlockGrid::new(&s, DepMask::of(&[0]), &[offset]);
            let mut seen = [0; 19];
            let mut total = 0;
            for b in 0..g.block_count() as usize {
                total += g.extent(b)[0];
            }
            for p in 0..19u32 {
                let pos = g.locate(&[p]);
                assert!(pos.local[0] < pos.extent[0]);
                assert_eq!(pos.extent, g.extent(pos.block));
                seen[p as usize] += 1;
            }
            assert_eq!(total, 19, "offset {offset}");
            assert!(seen.iter().all(|&c| c == 1));
        }
        // Offset 3: blocks [0,5) [5,13) [13,19).
        let g = BlockGrid::new(&s, DepMask::of(&[0]), &[3]);
        assert_eq!(g.block_count(), 3);
        assert_eq!(g.locate(&[4]), BlockPosition { block: 0, local: vec![4], extent: vec![5] });
        assert_eq!(g.locate(&[5]), BlockPosition { block: 1, local: vec![0], extent: vec![8] });
        assert_eq!(g.locate(&[18]), BlockPosition { block: 2, local: vec![5], extent: vec![6] });
    }

    #[test]
    fn blocks_tile_only_masked_dimensions() {
        let s = space(&[16, 8, 3], &[8, 8, 8]);
        let g = BlockGrid::new(&s, DepMask::of(&[0, 2]), &[2, 0, 1]);
        // dim 0: ceil(18/8) = 3 blocks; dim 2: ceil(4/8) = 1.
        assert_eq!(g.blocks_per_axis(), vec![3, 1]);
        let pos = g.locate(&[9, 5, 2]);
        assert_eq!(pos.block, 1);
        assert_eq!(pos.local, vec![3, 2]);
        let none = BlockGrid::new(&s, DepMask::NONE, &[0, 0, 0]);
        assert_eq!(none.block_count(), 1);
        assert_eq!(none.locate(&[3, 3, 1]).block, 0);
    }

    #[test]
    fn level_images_subsample_the_extent() {
        // 8×8 block; a level 8×1 (jump) and a level 2×2.
        assert_eq!(level_image_index(&[8, 1], &[5, 7], &[8, 8]), 5);
        assert_eq!(level_image_index(&[2, 2], &[5, 3], &[8, 8]), 2);
        assert_eq!(level_image_index(&[1, 1], &[7, 7], &[8, 8]), 0);
        // Odd edge extents map proportionally.
        assert_eq!(level_image_index(&[2], &[2], &[5]), 0);
        assert_eq!(level_image_index(&[2], &[3], &[5]), 1);
        assert_eq!(level_image_index(&[], &[], &[]), 0);
    }
}
