//! The memory budgets of pis-diff and pis-reencode: what they hold at once while decoding a
//! file, estimated from `LAYR` alone ([`pis_play::memory`]) and checked before any level
//! image is decoded, so that a valid file whose textures are as large as SPEC.md section 12
//! allows (a few hundred KB declaring 4 GiB level images) is refused with its sizes (exit 5,
//! not supported) instead of exhausting memory.
//!
//! The budget is `--memory GB` (GiB), by default [`DEFAULT_BUDGET`] or half the memory
//! available where that is less.

use std::path::Path;

use anyhow::anyhow;
use pis_format::PisReader;
use pis_pack::{Exit, Failure};
use pis_play::memory::{blocks, size, BlockBytes};

/// The default budget: 4 GiB (or half the memory available, where that is less).
pub const DEFAULT_BUDGET: u64 = 4 << 30;

/// The budget in bytes: `gib` GiB where given, else the default.
pub fn budget_bytes(gib: Option<f64>) -> u64 {
    match gib {
        Some(g) => (g * (1u64 << 30) as f64) as u64,
        None => pis_trace::memory::available_memory()
            .map_or(DEFAULT_BUDGET, |a| DEFAULT_BUDGET.min(a / 2)),
    }
}

/// `--memory GB`: a number of GiB above 0.
pub fn parse_memory(s: &str) -> Result<f64, String> {
    s.parse::<f64>()
        .ok()
        .filter(|v| v.is_finite() && *v > 0.0)
        .ok_or_else(|| format!("bad memory budget {s:?}: expected a number of GB above 0"))
}

/// What decoding one block holds at once: every level image of the block and every
/// sample's rebuilt texture (pis-diff decodes a block of each file at a time).
fn block_need(b: &BlockBytes) -> u64 {
    b.all_images().saturating_add(b.all_textures())
}

/// The first block with the largest `key`.
fn largest(all: &[BlockBytes], key: impl Fn(&BlockBytes) -> u64) -> Option<&BlockBytes> {
    all.iter().fold(None, |best: Option<&BlockBytes>, b| match best {
        Some(m) if key(m) >= key(b) => Some(m),
        _ => Some(b),
    })
}

/// The blocks of the file at `path`; `None` where it cannot be opened (the tool then says
/// why as it would without the check).
fn file_blocks(path: &Path) -> Option<Vec<BlockBytes>> {
    PisReader::open(path).ok().map(|r| blocks(r.container()))
}

fn refusal(tool: &str, b: &BlockBytes, need: u64, what: &str, budget: u64) -> Failure {
    Failure::new(
        Exit::NotSupported,
        anyhow!(
            "{}: each level image and each texture decodes to {} ({} level image(s), {} sample(s)); {tool} would hold {} at once ({what}), more than its memory budget, {} (--memory GB)",
            b.name,
            size(b.image),
            b.images,
            b.samples,
            size(need),
            size(budget)
        ),
    )
}

/// pis-diff of two files: refuses (not supported) when the largest block of each file,
/// decoded together, exceeds `budget` bytes.
pub fn check_diff(a: &Path, b: &Path, budget: u64) -> Result<(), Failure> {
    let (Some(ba), Some(bb)) = (file_blocks(a), file_blocks(b)) else { return Ok(()) };
    let (Some(la), Some(lb)) = (largest(&ba, block_need), largest(&bb, block_need)) else {
        return Ok(());
    };
    let need = block_need(la).saturating_add(block_need(lb));
    if need <= budget {
        return Ok(());
    }
    let (first, file) = if block_need(la) >= block_need(lb) { (la, a) } else { (lb, b) };
    let what = format!(
        "a block of each file decoded, every level image and sample texture: {} in {}",
        size(block_need(first)),
        file.display()
    );
    Err(refusal("pis-diff", first, need, &what, budget))
}

/// pis-reencode: refuses (not supported) when what it holds at once exceeds `budget` bytes:
/// the new pyramids of the whole file (about as large as its level images), one layer's
/// decoded sample textures twice (as decoded and gamma-compensated), the level images of the
/// block being decoded, and a texture's working copy in the pyramid being built.
pub fn check_reencode(input: &Path, budget: u64) -> Result<(), Failure> {
    let Some(all) = file_blocks(input) else { return Ok(()) };
    let Some(block) = largest(&all, block_need) else { return Ok(()) };
    let pyramids: u64 = all.iter().map(BlockBytes::all_images).fold(0, u64::saturating_add);
    let mut layer_textures: u64 = 0;
    let mut layers = std::collections::HashMap::new();
    for b in &all {
        let t: &mut u64 = layers.entry((b.object, b.layer)).or_default();
        *t = t.saturating_add(b.all_textures());
        layer_textures = layer_textures.max(*t);
    }
    let need = pyramids
        .saturating_add(layer_textures.saturating_mul(2))
        .saturating_add(block.all_images())
        .saturating_add(block.image);
    if need <= budget {
        return Ok(());
    }
    let what = format!(
        "the new pyramids {}, a layer's decoded textures twice {}, a block's level images {} and a texture {}",
        size(pyramids),
        size(layer_textures.saturating_mul(2)),
        size(block.all_images()),
        size(block.image)
    );
    Err(refusal("pis-reencode", block, need, &what, budget))
}
