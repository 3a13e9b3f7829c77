//! One object's surface layer before and while it is solved: its plan (mask, blocks and
//! their placements), and one parameter sample solved from its points' views.

use anyhow::Result;
use pis_compile::SolveSettings;
use pis_format::DepMask;

use super::mesh::Placed;
use super::model::Views;
use super::radiance::{Radiance, SampleViews};
use crate::solutions::Solver;

/// What one object's layers are before solving: mask, the block each point's sample is in,
/// each block's placement.
pub(super) struct LayerPlan {
    pub kind: pis_format::LayerKind,
    pub radiance: Radiance,
    pub depends_on: DepMask,
    pub block_placements: Vec<usize>,
    /// Per point of the set, its sample's placement.
    pub point_placement: Vec<usize>,
    /// The layer carries the object's opacity (a translucent object's first layer).
    pub alpha: bool,
}

/// One parameter sample of a layer: the points whose views it is solved from, with the
/// render matrices of placement `pid`.
pub(super) struct Sample<'a> {
    pub views: &'a Views,
    pub points: &'a [usize],
    pub placement: &'a Placed,
    pub pid: usize,
}

impl Sample<'_> {
    /// The sample's texture (RGB over the whole chain) fitted to `radiance`, warm-started
    /// from `start`, and the solver's iterations: one texture for the views of the sample
    /// stacked (eq. 3.7) where `view_independent`, else the one point of the key's.
    pub fn solve(
        &self,
        radiance: Radiance,
        view_independent: bool,
        start: Option<&[f32]>,
        settings: &SolveSettings,
        solver: &Solver,
    ) -> Result<(Vec<f32>, u64)> {
        if view_independent {
            let source = SampleViews {
                views: self.views,
                points: self.points,
                placement: self.pid,
                radiance,
            };
            let s = solver.solve_view_source(&source, start, settings)?;
            return Ok((s.texels, s.iterations as u64));
        }
        let v = self.views.get(self.points[0])?;
        let a = v.a(self.pid);
        if a.rows() == 0 {
            // The object covers no pixel.
            let zero = || vec![0.0; self.placement.layout.texel_count() * 3];
            return Ok((start.map_or_else(zero, <[f32]>::to_vec), 0));
        }
        // A view-dependent layer's rows weighed by the set's confidence in their pixels
        // (`--confidence`); the stacked solves are not (measured worse: [`super::confidence`]).
        let b = radiance.at(&v);
        let (a, b) = super::confidence::weigh(a, &b, &v.weight);
        let s = solver.solve(&a, &b, start, settings)?;
        Ok((s.texels, s.iterations as u64))
    }
}
