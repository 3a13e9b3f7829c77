//! The pack's memory budget (`pis-pack --memory GB`, else the memory this machine has
//! available): a set whose pack would not fit in memory is streamed through the scratch file
//! ([`super::scratch`]). Its images are read point by point and each object's layers written
//! there ([`super::set_images`]); each object's render matrices and gold standard are
//! written as they are made and read back a point at a time ([`super::model::Views`]); each
//! layer sample's texture once solved ([`super::textures`]); each block's level images once
//! their rate–distortion curves are measured ([`super::storage::BlockPyramid::spill`]). The
//! file is the same, byte for byte: the pack reads the same values, in the same order.
//!
//! Whether to stream is decided before the set is read, from the bytes of its images: a pack
//! in memory holds [`HELD_PER_IMAGE_BYTE`] bytes per byte of the float images it reads
//! (measured on demo1: the images, the render matrices, the solves, the pyramids and the
//! level images; docs/benchmarks/scale.md "Scale").

use pis_trace::memory::gib;

/// Peak resident bytes of a pack in memory per byte of the set's float images it reads.
pub const HELD_PER_IMAGE_BYTE: u64 = 3;

/// How a pack holds its set.
#[derive(Clone, Debug, PartialEq)]
pub struct MemoryPlan {
    /// The budget in bytes: `--memory`, else the available memory (`None`: unknown).
    pub budget: Option<u64>,
    /// Whether the budget is the one asked for (`--memory`).
    pub asked: bool,
    /// The bytes a pack in memory is expected to take.
    pub held: u64,
    /// Whether the pack streams.
    pub stream: bool,
}

impl MemoryPlan {
    /// The plan for a set whose images read `image_bytes` bytes as floats, under `memory`
    /// GB (`--memory`), else `available` bytes.
    pub fn new(image_bytes: u64, memory: Option<f64>, available: Option<u64>) -> MemoryPlan {
        let budget = memory.map(|gib| (gib * (1u64 << 30) as f64) as u64).or(available);
        let held = image_bytes.saturating_mul(HELD_PER_IMAGE_BYTE);
        MemoryPlan {
            budget,
            asked: memory.is_some(),
            held,
            stream: budget.is_some_and(|b| held > b),
        }
    }

    /// What the report and the progress say.
    pub fn describe(&self) -> String {
        let budget = match (self.budget, self.asked) {
            (Some(b), true) => format!("the budget of {} (--memory)", gib(b)),
            (Some(b), false) => format!("the {} available", gib(b)),
            (None, _) => "an unknown budget".to_string(),
        };
        let how = if self.stream {
            "streamed: images, render matrices, gold standard, solved textures and level images in the scratch file, read back an object, point or block at a time"
        } else {
            "in memory"
        };
        format!("{how} (in memory it would take about {}, against {budget})", gib(self.held))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_pack_streams_when_its_estimate_exceeds_the_budget() {
        let gb = 1u64 << 30;
        assert!(!MemoryPlan::new(gb, Some(4.0), None).stream, "3 GB held fits 4 GB");
        assert!(MemoryPlan::new(gb, Some(2.0), None).stream);
        assert!(
            MemoryPlan::new(gb, None, Some(2 * gb)).stream,
            "without --memory, the available memory is the budget"
        );
        assert!(!MemoryPlan::new(gb, None, None).stream, "an unknown budget holds");
        assert!(!MemoryPlan::new(gb, Some(2.0), None).describe().contains("available"));
        assert!(MemoryPlan::new(gb, Some(2.0), None).describe().starts_with("streamed"));
    }
}
