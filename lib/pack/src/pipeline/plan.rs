//! A pack's settings resolved against its set, once, before any work: the high-level half of
//! [`super::PackSettings`] (as ripgrep's `hiargs` follow its `lowargs`). The parameter
//! blocks and the container's parameter space, how objects' block origins are staggered
//! (thesis 4.7), and what the storage allocation aims at: every stage reads them here and
//! none resolves them again.

use anyhow::Result;
use pis_codec::allocate;
use pis_format::{CameraTable, ParameterSpace};

use super::blocks::{block_sizes, geometry, samples_per_dimension, stagger};
use super::input::LoadedSet;
use super::settings::{PackSettings, Stagger, Target};

/// The resolved layout and budget of a pack.
#[derive(Clone, Debug)]
pub struct Plan {
    /// Samples per block along each dimension.
    pub sizes: Vec<u32>,
    /// The samples along each dimension of the set's parameter space.
    pub samples: Vec<usize>,
    /// The container's parameter space for blocks of `sizes`, and its camera table.
    pub space: ParameterSpace,
    pub cameras: CameraTable,
    /// How the objects' block origins are offset.
    pub stagger: Stagger,
    /// What the allocation aims at: a ratio as its byte budget of level images against the
    /// set's raw images (thesis 4.8; geometry and tables come on top), a PSNR of the coded
    /// textures, or a played quality.
    pub target: Aim,
}

/// The storage allocation's aim.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Aim {
    /// One allocation: a byte budget or a PSNR of the coded textures.
    Fixed(allocate::Target),
    /// The fewest bytes whose predicted played PSNR reaches `goal_db`, or, where no goal is
    /// set, comes within `within_db` of the file's textures as solved: a search over
    /// allocations, each encoded and predicted ([`super::played`]).
    Played { within_db: f64, goal_db: Option<f64> },
}

impl Aim {
    /// The aim of `target` over raw images of `raw` bytes: a ratio as the byte budget of
    /// level images (raw / ratio), a PSNR of the coded textures at peak 1, a played quality
    /// as the search it asks for.
    pub fn of(target: Target, raw: u64) -> Aim {
        match target.fixed_allocation(raw) {
            Some(fixed) => Aim::Fixed(fixed),
            // The one target without a fixed allocation: a played quality.
            None => Aim::Played { within_db: target.within().unwrap_or_default(), goal_db: None },
        }
    }
}

impl Plan {
    /// `settings` resolved against `set`: fails where `--block` does not fit the space.
    pub fn new(set: &LoadedSet, settings: &PackSettings) -> Result<Plan> {
        let sizes = block_sizes(settings.block.as_slice(), set.scene.space.dims.len())?;
        let (space, cameras) = geometry(set, &sizes);
        Ok(Plan {
            samples: samples_per_dimension(set),
            sizes,
            space,
            cameras,
            stagger: settings.stagger,
            target: Aim::of(settings.target, set.raw_image_bytes()),
        })
    }

    /// The same layout aiming at `target` (a sweep over the targets of one inference).
    pub fn aiming_at(&self, target: Target, raw_image_bytes: u64) -> Plan {
        Plan { target: Aim::of(target, raw_image_bytes), ..self.clone() }
    }

    /// The same layout aiming at a predicted played PSNR of `goal_db` (`--representation
    /// auto` weighing files at one goal); a fixed aim is kept.
    pub fn played_at(&self, goal_db: f64) -> Plan {
        let target = match self.target {
            Aim::Played { within_db, .. } => Aim::Played { within_db, goal_db: Some(goal_db) },
            fixed => fixed,
        };
        Plan { target, ..self.clone() }
    }

    /// Block origin offsets of object model `i` of `n` ([`stagger`]).
    pub fn stagger(&self, i: usize, n: usize) -> Vec<u32> {
        stagger(i, n, &self.sizes, &self.samples, self.stagger)
    }

    /// The level-image bytes the allocation may spend, where it aims at a ratio.
    pub fn budget(&self) -> Option<u64> {
        match self.target {
            Aim::Fixed(allocate::Target::Bytes(b)) => Some(b as u64),
            _ => None,
        }
    }
}
