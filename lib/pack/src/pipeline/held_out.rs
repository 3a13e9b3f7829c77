//! The points an object's textures are judged at where they were not solved from (thesis
//! 3.4's test of filters away from the inferred views), for the choices of its filter
//! ([`super::filter_choice`]) and texel density ([`super::density_choice`]).
//!
//! A view-independent layer is one texture per sample of the non-view dimensions (a light's
//! place, an animation frame): a texture solved over points lit differently predicts none of
//! them, so the split is made within each such sample, and each sample's texture is solved
//! from its own points and drawn at its own held-out ones.

use std::collections::BTreeMap;

use anyhow::Result;
use pis_compile::SolveSettings;

use super::model::{key, Views};
use super::radiance::{Radiance, SampleViews};
use super::represent::Job;
use crate::solutions::Solver;

/// Per sample of the non-view dimensions, the points its texture is solved from and those it
/// is measured at: of the sample's points where the object covers a pixel, every second one
/// strictly between the first and the last is held out.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Split {
    samples: Vec<(Vec<usize>, Vec<usize>)>,
}

impl Split {
    /// The split of `views`, whose point `p` belongs to the sample keyed `keys[p]`.
    pub fn new(views: &Views, keys: &[Vec<u32>]) -> Split {
        let mut covered: BTreeMap<&Vec<u32>, Vec<usize>> = BTreeMap::new();
        for p in (0..views.len()).filter(|&p| views.rows(p) > 0) {
            covered.entry(&keys[p]).or_default().push(p);
        }
        let samples = covered
            .into_values()
            .map(|covered| {
                let n = covered.len();
                let (mut train, mut test) = (Vec::new(), Vec::new());
                for (i, &p) in covered.iter().enumerate() {
                    if i % 2 == 1 && i + 1 < n {
                        test.push(p);
                    } else {
                        train.push(p);
                    }
                }
                (train, test)
            })
            .filter(|(_, test)| !test.is_empty())
            .collect();
        Split { samples }
    }

    /// The split of an object's `views` by the job's non-view dimensions.
    pub fn of(job: &Job<'_>, views: &Views) -> Split {
        let keys: Vec<Vec<u32>> = (0..views.len())
            .map(|p| job.set.samples.get(p).map(|s| key(s, job.non_view)).unwrap_or_default())
            .collect();
        Split::new(views, &keys)
    }

    /// Whether no point is held out (no sample has three covered points).
    pub fn is_empty(&self) -> bool {
        self.samples.is_empty()
    }

    /// How many points the textures are solved from, and how many they are measured at.
    pub fn counts(&self) -> (usize, usize) {
        let train = self.samples.iter().map(|(t, _)| t.len()).sum();
        let test = self.samples.iter().map(|(_, t)| t.len()).sum();
        (train, test)
    }

    /// The squared error of each covered pixel of the held-out points (sample by sample, in
    /// order; its channels' mean) of each sample's texture, solved view-independently for the
    /// object's radiance from the sample's other points.
    pub fn errors(
        &self,
        views: &Views,
        settings: &SolveSettings,
        solver: &Solver,
    ) -> Result<Vec<f64>> {
        let mut errors = Vec::new();
        for (train, test) in &self.samples {
            let source =
                SampleViews { views, points: train, placement: 0, radiance: Radiance::Sum };
            let x = solver.solve_view_source(&source, None, settings)?.texels;
            for &p in test {
                let v = views.get(p)?;
                let (a, b) = (v.a(0), Radiance::Sum.at(&v));
                for r in 0..a.rows() {
                    let (cols, vals) = a.row(r);
                    let mut e = 0.0f64;
                    for k in 0..3 {
                        let y: f32 =
                            cols.iter().zip(vals).map(|(&c, &w)| w * x[c as usize * 3 + k]).sum();
                        e += f64::from(y - b[r * 3 + k]).powi(2);
                    }
                    errors.push(e / 3.0);
                }
            }
        }
        Ok(errors)
    }
}

/// The mean of `v` (0 when empty).
pub fn mean(v: &[f64]) -> f64 {
    if v.is_empty() {
        0.0
    } else {
        v.iter().sum::<f64>() / v.len() as f64
    }
}

/// The PSNR (dB, peak 1) of a mean squared error.
pub fn psnr(mse: f64) -> f64 {
    -10.0 * mse.max(1e-20).log10()
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::pipeline::model::PointView;
    use pis_compile::{RenderMatrix, TextureLayout};

    /// Views of `rows` covered pixels per point (0: the object covers none there).
    pub(crate) fn views(rows: &[usize]) -> Views {
        let mut v = Views::new(None);
        for &n in rows {
            let layout = TextureLayout::full(4, 4);
            let taps: Vec<pis_compile::filter::Taps> = (0..n)
                .map(|i| {
                    let mut t = pis_compile::filter::Taps::default();
                    t.add((i % 16) as u32, 0.75);
                    t.add(16 + (i % 4) as u32, 0.25);
                    t
                })
                .collect();
            let a = RenderMatrix::from_taps(
                pis_compile::Viewport { width: 8, height: 8 },
                layout,
                (0..n as u32).collect(),
                &taps,
            );
            let b = vec![0.5; n * 3];
            v.push(PointView {
                a: vec![(0, a)],
                diffuse: b.clone(),
                specular: b,
                alpha: vec![],
                weight: vec![],
            })
            .unwrap();
        }
        v
    }

    fn split(rows: &[usize], keys: &[u32]) -> Vec<(Vec<usize>, Vec<usize>)> {
        let keys: Vec<Vec<u32>> = keys.iter().map(|&k| vec![k]).collect();
        Split::new(&views(rows), &keys).samples
    }

    #[test]
    fn every_second_covered_point_between_the_ends_is_held_out() {
        assert_eq!(split(&[4, 4, 4, 4], &[0; 4]), [(vec![0, 2, 3], vec![1])]);
        assert_eq!(split(&[4, 0, 4, 4, 4, 4], &[0; 6]), [(vec![0, 3, 5], vec![2, 4])]);
        assert!(split(&[4, 4], &[0; 2]).is_empty(), "two points: none");
    }

    #[test]
    fn points_are_held_out_within_their_sample_of_the_non_view_dimensions() {
        // Two light places × four views, the view fastest: one view of each light held out,
        // each light's texture solved from its own three.
        let s = split(&[4; 8], &[0, 0, 0, 0, 1, 1, 1, 1]);
        assert_eq!(s, [(vec![0, 2, 3], vec![1]), (vec![4, 6, 7], vec![5])]);
        // A sample of two points holds none out, and is not solved.
        assert_eq!(split(&[4; 6], &[0, 0, 0, 0, 1, 1]), [(vec![0, 2, 3], vec![1])]);
        let both =
            Split::new(&views(&[4; 8]), &[[0], [0], [0], [0], [1], [1], [1], [1]].map(Vec::from));
        assert_eq!(both.counts(), (6, 2));
    }
}
