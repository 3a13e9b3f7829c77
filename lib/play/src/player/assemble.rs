//! The workers' rebuild of one texture of a frame or of a prediction: the job that sums its
//! level images (decode.rs's `assemble` and `assemble_cube` run it).

use std::sync::Arc;

use pis_compile::TextureLayout;
use pis_format::texture::LevelLayout;
use pis_format::PisReader;

use super::plan::TextureKey;
use crate::decode::AssembleJob;

/// The job that rebuilds texture `k` from its level images (`levels`, top first), its
/// `drop_levels` finest levels dropped (at most all but one).
pub(super) fn assemble_job<'r>(
    reader: &'r PisReader,
    levels: Vec<Arc<Vec<f32>>>,
    k: &TextureKey,
    drop_levels: u32,
) -> AssembleJob<'r> {
    let c = reader.container();
    let layer = &c.objects[k.object as usize].layers[k.layer as usize];
    let block = &layer.blocks[k.block as usize];
    let full = TextureLayout::full(block.width, block.height).levels;
    AssembleJob {
        layer,
        layout: LevelLayout::of(layer, block),
        levels,
        drop_levels: drop_levels.min(full.saturating_sub(1)),
    }
}
