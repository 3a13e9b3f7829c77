//! Storage allocation by equal slopes (thesis 4.5).
//!
//! Every level image of every block, layer and object is an [`Item`] with a rate–distortion
//! curve. The screen error to minimise is `Σ_o A_o · Ē_o`, with `A_o` the screen area of
//! object `o` and `Ē_o = Σ_{i ∈ o} w_i · D_i(r_i)` its texture MSE (`w_i` is the share of
//! the object's texture samples that item `i`'s error reaches: for a pyramid level image,
//! the finest samples it covers over all finest samples of the object, so errors of all
//! levels add up as the reconstruction does). Lighting layers are simply more items of the
//! same object. The minimum under a byte budget puts every item at the same slope
//! `−dD/dr = λ / (A_o w_i)`; a bisection on λ (the "1D root finder") finds the λ that meets
//! the target, on the lower convex hull of each curve.
//!
//! The max-MSE constraint (α > 1, default 1.25) runs two passes: the first allocation gives
//! the mean object MSE `Ē`; each object with `Ē_o > α Ē` then loses the part of its curves
//! that cannot meet `α Ē` (its items start at the cheapest allocation that meets it), and
//! the allocation is solved again, taking storage from objects with low MSE.

use crate::{RdCurve, RdPoint};

/// Default of the max-MSE constraint (thesis 4.8).
pub const DEFAULT_ALPHA: f64 = 1.25;

/// One level image to allocate storage to.
#[derive(Clone, Debug)]
pub struct Item {
    /// Its rate–distortion curve (at least one point).
    pub curve: RdCurve,
    /// The object it belongs to (index into the areas).
    pub object: usize,
    /// Weight of its MSE in its object's MSE.
    pub weight: f64,
}

/// What the allocation aims at.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Target {
    /// Spend at most this many bytes in all (a compression ratio is a byte budget).
    Bytes(usize),
    /// Reach this PSNR (dB) of the area-weighted screen MSE for a signal peak, with the
    /// fewest bytes.
    Psnr { db: f64, peak: f64 },
}

/// The result: a point of each item's curve.
#[derive(Clone, Debug, PartialEq)]
pub struct Allocation {
    /// Bytes per item (a point of its curve).
    pub bytes: Vec<usize>,
    /// MSE per item at that point.
    pub mse: Vec<f64>,
    /// `Ē_o` per object.
    pub object_mse: Vec<f64>,
    /// `Σ A_o Ē_o / Σ A_o`.
    pub screen_mse: f64,
    pub total_bytes: usize,
}

/// Why no allocation could be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum AllocError {
    #[error("item {0} has an empty rate-distortion curve")]
    EmptyCurve(usize),
    #[error("item {item} names object {object}, but there are {objects} areas")]
    Object { item: usize, object: usize, objects: usize },
    #[error("the smallest encodings need {needed} bytes, over the budget of {budget}")]
    Budget { needed: usize, budget: usize },
    #[error(
        "PSNR {db} dB is out of reach: every level image at its full rate gives {best_db:.2} dB"
    )]
    Unreachable { db: f64, best_db: f64 },
}

/// Lower convex hull of a curve: points with increasing bytes and decreasing MSE whose
/// slopes flatten.
pub fn convex_hull(curve: &RdCurve) -> Vec<RdPoint> {
    let mut pts = curve.clone().monotone().points;
    pts.sort_by_key(|p| p.bytes);
    let mut hull: Vec<RdPoint> = Vec::new();
    for p in pts {
        while hull.len() >= 2 {
            let (a, b) = (hull[hull.len() - 2], hull[hull.len() - 1]);
            // Remove b when it lies on or above the segment a → p.
            let cross = (b.bytes as f64 - a.bytes as f64) * (p.mse - a.mse)
                - (b.mse - a.mse) * (p.bytes as f64 - a.bytes as f64);
            if cross <= 0.0 {
                hull.pop();
            } else {
                break;
            }
        }
        hull.push(p);
    }
    hull
}

struct Problem {
    hulls: Vec<Vec<RdPoint>>,
    /// `A_o · w_i` per item.
    gain: Vec<f64>,
}

/// Bisection steps on a slope or an error limit: far below f64 resolution where it matters.
const BISECTIONS: usize = 100;

impl Problem {
    /// The hulls and gains of `items` over objects with screen `areas`; an item without a
    /// curve, or naming an object without an area, is an error.
    fn new(items: &[Item], areas: &[f64]) -> Result<Problem, AllocError> {
        for (i, it) in items.iter().enumerate() {
            if it.curve.points.is_empty() {
                return Err(AllocError::EmptyCurve(i));
            }
            if it.object >= areas.len() {
                return Err(AllocError::Object {
                    item: i,
                    object: it.object,
                    objects: areas.len(),
                });
            }
        }
        Ok(Problem {
            hulls: items.iter().map(|it| convex_hull(&it.curve)).collect(),
            gain: items.iter().map(|it| areas[it.object] * it.weight).collect(),
        })
    }

    /// The least screen MSE any allocation above `floor` reaches: every item at its
    /// richest point.
    fn best_screen_mse(&self, items: &[Item], areas: &[f64], floor: &[usize]) -> f64 {
        let all = vec![true; self.hulls.len()];
        screen_mse(&self.mses(&self.choose(0.0, &all, floor)), items, areas).1
    }

    /// Point index per item minimising `gain · D + λ · R`, never below `floor` (on a convex
    /// hull the walk from the floor ends where the free walk would, or at the floor).
    /// Items not `active` stay at their floor.
    fn choose(&self, lambda: f64, active: &[bool], floor: &[usize]) -> Vec<usize> {
        self.hulls
            .iter()
            .zip(&self.gain)
            .zip(active.iter().zip(floor))
            .map(|((h, &g), (&on, &f))| {
                let mut k = f;
                if !on {
                    return k;
                }
                while k + 1 < h.len() {
                    let dd = (h[k].mse - h[k + 1].mse) * g;
                    let dr = (h[k + 1].bytes - h[k].bytes) as f64;
                    if dd > lambda * dr {
                        k += 1;
                    } else {
                        break;
                    }
                }
                k
            })
            .collect()
    }

    fn bytes(&self, pick: &[usize]) -> usize {
        self.hulls.iter().zip(pick).map(|(h, &k)| h[k].bytes).sum()
    }

    /// Spends what the budget leaves on the steps with the best slope that still fit.
    fn fill(&self, pick: &mut [usize], budget: usize) {
        let mut left = budget.saturating_sub(self.bytes(pick));
        loop {
            let mut best: Option<(usize, f64)> = None;
            for (i, h) in self.hulls.iter().enumerate() {
                let k = pick[i];
                if k + 1 < h.len() {
                    let dr = h[k + 1].bytes - h[k].bytes;
                    if dr <= left {
                        let s = (h[k].mse - h[k + 1].mse) * self.gain[i] / dr.max(1) as f64;
                        if best.is_none_or(|b| s > b.1) {
                            best = Some((i, s));
                        }
                    }
                }
            }
            let Some((i, _)) = best else { break };
            left -= self.hulls[i][pick[i] + 1].bytes - self.hulls[i][pick[i]].bytes;
            pick[i] += 1;
        }
    }

    /// The allocation meeting `target` with every item at or above its `floor`;
    /// `Budget` when the floors alone do not fit a byte budget.
    fn solve(
        &self,
        target: Target,
        areas: &[f64],
        items: &[Item],
        floor: &[usize],
    ) -> Result<Vec<usize>, AllocError> {
        let all = vec![true; self.hulls.len()];
        let max_slope = self
            .hulls
            .iter()
            .zip(&self.gain)
            .flat_map(|(h, g)| {
                h.windows(2).map(move |w| {
                    (w[0].mse - w[1].mse) * g / (w[1].bytes - w[0].bytes).max(1) as f64
                })
            })
            .fold(0.0f64, f64::max);
        // λ above every slope: the cheapest points; λ → 0: the richest points.
        let (mut lo, mut hi) = (0.0f64, max_slope * 2.0 + 1e-300);
        match target {
            Target::Bytes(budget) => {
                let needed = self.bytes(floor);
                if needed > budget {
                    return Err(AllocError::Budget { needed, budget });
                }
                for _ in 0..BISECTIONS {
                    let mid = 0.5 * (lo + hi);
                    if self.bytes(&self.choose(mid, &all, floor)) <= budget {
                        hi = mid;
                    } else {
                        lo = mid;
                    }
                }
                let mut pick = self.choose(hi, &all, floor);
                self.fill(&mut pick, budget);
                Ok(pick)
            }
            Target::Psnr { db, peak } => {
                let goal = peak * peak / 10f64.powf(db / 10.0);
                let screen = |pick: &[usize]| screen_mse(&self.mses(pick), items, areas).1;
                let best = self.best_screen_mse(items, areas, floor);
                // A goal at the reachable PSNR itself is met (by the richest allocation): the
                // dB → MSE round trip may put it a rounding error beyond `best`.
                if best > goal * (1.0 + 1e-9) {
                    let best_db = 10.0 * (peak * peak / best).log10();
                    return Err(AllocError::Unreachable { db, best_db });
                }
                for _ in 0..BISECTIONS {
                    let mid = 0.5 * (lo + hi);
                    if screen(&self.choose(mid, &all, floor)) <= goal {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                Ok(self.choose(lo, &all, floor))
            }
        }
    }

    fn mses(&self, pick: &[usize]) -> Vec<f64> {
        self.hulls.iter().zip(pick).map(|(h, &k)| h[k].mse).collect()
    }

    /// The floors that make every object's MSE at most `limit` with the fewest bytes: per
    /// object the cheapest equal-slope allocation of its items that meets the limit. An
    /// object that meets it with nothing, or cannot meet it at all, gets no floor; the
    /// second vector marks the objects that cannot.
    fn floors(&self, items: &[Item], objects: usize, limit: f64) -> (Vec<usize>, Vec<bool>) {
        let none = vec![0usize; items.len()];
        let mut floor = none.clone();
        let mut beyond = vec![false; objects];
        for (o, cannot) in beyond.iter_mut().enumerate() {
            let mine: Vec<bool> = items.iter().map(|it| it.object == o).collect();
            let object_mse = |p: &[usize]| -> f64 {
                items
                    .iter()
                    .enumerate()
                    .filter(|(i, _)| mine[*i])
                    .map(|(i, it)| it.weight * self.hulls[i][p[i]].mse)
                    .sum()
            };
            let (mut lo, mut hi) = (0.0f64, 1.0f64);
            while object_mse(&self.choose(hi, &mine, &none)) <= limit && hi < 1e300 {
                hi *= 16.0;
            }
            if object_mse(&self.choose(0.0, &mine, &none)) > limit {
                *cannot = true;
                continue;
            }
            if object_mse(&self.choose(hi, &mine, &none)) <= limit {
                continue;
            }
            for _ in 0..BISECTIONS {
                let mid = 0.5 * (lo + hi);
                if object_mse(&self.choose(mid, &mine, &none)) <= limit {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            for (i, k) in self.choose(lo, &mine, &none).into_iter().enumerate() {
                if mine[i] {
                    floor[i] = k;
                }
            }
        }
        (floor, beyond)
    }
}

fn screen_mse(mses: &[f64], items: &[Item], areas: &[f64]) -> (Vec<f64>, f64) {
    let mut obj = vec![0.0f64; areas.len()];
    for (i, it) in items.iter().enumerate() {
        obj[it.object] += it.weight * mses[i];
    }
    let area: f64 = areas.iter().sum();
    let s: f64 = obj.iter().zip(areas).map(|(e, a)| e * a).sum();
    (obj, if area > 0.0 { s / area } else { 0.0 })
}

/// Steps of the search for the tightest consistent error limit (log-spaced bisection).
const LIMIT_STEPS: usize = 40;

/// Equal-slope allocation of `items` over objects with screen `areas`, meeting `target`,
/// with the max-MSE constraint when `alpha` is given (thesis 4.8: 1.25).
///
/// The constraint (thesis 4.8): no object's MSE above a limit `L`, `alpha` times the mean
/// object MSE `Ē` of the free allocation. The free allocation is kept when it meets it.
/// Otherwise every object is given a floor, the cheapest allocation that holds its MSE
/// under `L` (an object that cannot get there at any rate keeps its whole curve), and the
/// allocation is solved again above the floors, taking storage from the objects with low
/// MSE. When the floors do not fit the budget, or fit only by pushing other objects above
/// `L`, the limit is raised to the smallest one (found by bisection) whose result keeps
/// every object under it; the free allocation's largest MSE always does. So every budget
/// the curves reach gives an allocation, and the constraint never leaves an object worse
/// than the free allocation's worst.
pub fn allocate(
    items: &[Item],
    areas: &[f64],
    target: Target,
    alpha: Option<f64>,
) -> Result<Allocation, AllocError> {
    let problem = Problem::new(items, areas)?;
    let no_floor = vec![0usize; items.len()];
    let mut pick = problem.solve(target, areas, items, &no_floor)?;
    if let Some(alpha) = alpha {
        if let Some(balanced) = balance(&problem, items, areas, target, alpha, &pick) {
            pick = balanced;
        }
    }
    let mse = problem.mses(&pick);
    let bytes: Vec<usize> = problem.hulls.iter().zip(&pick).map(|(h, &k)| h[k].bytes).collect();
    let (object_mse, screen) = screen_mse(&mse, items, areas);
    Ok(Allocation { total_bytes: bytes.iter().sum(), bytes, mse, object_mse, screen_mse: screen })
}

/// The highest PSNR (dB, for a signal `peak`) of the area-weighted screen MSE that an
/// allocation of `items` reaches: every item at its richest point (infinite where that is
/// exact).
pub fn reachable_psnr(items: &[Item], areas: &[f64], peak: f64) -> Result<f64, AllocError> {
    let problem = Problem::new(items, areas)?;
    let best = problem.best_screen_mse(items, areas, &vec![0; items.len()]);
    Ok(10.0 * (peak * peak / best).log10())
}

/// The objects that hold any item: objects without level images have no MSE to balance.
fn present(items: &[Item], objects: usize) -> Vec<bool> {
    let mut p = vec![false; objects];
    items.iter().for_each(|it| p[it.object] = true);
    p
}

/// Largest object MSE and `alpha` times the mean, over the objects that hold items.
fn spread(obj: &[f64], present: &[bool], alpha: f64) -> (f64, f64) {
    let (mut max, mut sum, mut n) = (0.0f64, 0.0f64, 0usize);
    for (e, _) in obj.iter().zip(present).filter(|(_, p)| **p) {
        max = max.max(*e);
        sum += e;
        n += 1;
    }
    (max, alpha * sum / n.max(1) as f64)
}

/// The max-MSE constrained allocation (see [`allocate`]), or `None` when the free one
/// `free` already meets the constraint.
fn balance(
    problem: &Problem,
    items: &[Item],
    areas: &[f64],
    target: Target,
    alpha: f64,
    free: &[usize],
) -> Option<Vec<usize>> {
    let present = present(items, areas.len());
    let (max, bound) = spread(&screen_mse(&problem.mses(free), items, areas).0, &present, alpha);
    if max <= bound * (1.0 + 1e-9) || bound <= 0.0 {
        return None;
    }
    // A limit holds when its floors fit and no object that can meet it ends above it.
    let attempt = |limit: f64| -> Option<Vec<usize>> {
        let (floor, beyond) = problem.floors(items, areas.len(), limit);
        let pick = problem.solve(target, areas, items, &floor).ok()?;
        let obj = screen_mse(&problem.mses(&pick), items, areas).0;
        let holds = obj
            .iter()
            .zip(&beyond)
            .zip(&present)
            .all(|((&e, &out), &p)| out || !p || e <= limit * (1.0 + 1e-9));
        holds.then_some(pick)
    };
    // The thesis's two passes.
    if let Some(pick) = attempt(bound) {
        return Some(pick);
    }
    // Else the smallest limit above it that holds.
    let (mut lo, mut hi) = (bound.ln(), max.ln());
    let mut best = attempt(max)?;
    for _ in 0..LIMIT_STEPS {
        let mid = 0.5 * (lo + hi);
        match attempt(mid.exp()) {
            Some(pick) => {
                best = pick;
                hi = mid;
            }
            None => lo = mid,
        }
    }
    Some(best)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// D(r) = σ² · 2^(−2r/n) sampled every 8 bytes: convex, like a real codec's curve.
    fn curve(var: f64, n: f64) -> RdCurve {
        RdCurve {
            points: (0..=400)
                .map(|k| {
                    let r = k * 8;
                    RdPoint { bytes: r, mse: var * 2f64.powf(-2.0 * r as f64 / n) }
                })
                .collect(),
        }
    }

    fn items() -> (Vec<Item>, Vec<f64>) {
        let items = vec![
            Item { curve: curve(1.0, 400.0), object: 0, weight: 1.0 },
            Item { curve: curve(0.1, 300.0), object: 0, weight: 0.5 },
            Item { curve: curve(4.0, 800.0), object: 1, weight: 1.0 },
            Item { curve: curve(0.01, 200.0), object: 2, weight: 1.0 },
            Item { curve: curve(2.0, 600.0), object: 2, weight: 0.25 },
        ];
        (items, vec![1000.0, 50.0, 300.0])
    }

    #[test]
    fn equal_slope_beats_uniform_and_meets_the_budget() {
        let (items, areas) = items();
        let budget = 2000;
        let a = allocate(&items, &areas, Target::Bytes(budget), None).unwrap();
        assert!(a.total_bytes <= budget);
        let per = budget / items.len();
        let uniform: Vec<f64> = items.iter().map(|it| it.curve.mse_at(per)).collect();
        let (_, uniform_screen) = screen_mse(&uniform, &items, &areas);
        assert!(a.screen_mse < uniform_screen, "{} vs {uniform_screen}", a.screen_mse);
    }

    #[test]
    fn alpha_bounds_every_object() {
        let (items, areas) = items();
        let free = allocate(&items, &areas, Target::Bytes(1500), None).unwrap();
        let mean = free.object_mse.iter().sum::<f64>() / 3.0;
        assert!(free.object_mse.iter().any(|&e| e > 1.25 * mean), "{:?}", free.object_mse);
        let a = allocate(&items, &areas, Target::Bytes(1500), Some(DEFAULT_ALPHA)).unwrap();
        assert!(a.total_bytes <= 1500);
        for &e in &a.object_mse {
            assert!(e <= 1.25 * mean * 1.0001, "{e} > 1.25 × {mean}");
        }
        assert!(a.screen_mse >= free.screen_mse);
    }

    /// One object on a small screen area with a costly curve, one cheap: the free
    /// allocation leaves the costly one far above the mean, and at small budgets the
    /// thesis's floor for it does not fit.
    fn lopsided() -> (Vec<Item>, Vec<f64>) {
        let items = vec![
            Item { curve: curve(50.0, 3000.0), object: 0, weight: 1.0 },
            Item { curve: curve(0.5, 200.0), object: 1, weight: 1.0 },
            Item { curve: curve(0.2, 100.0), object: 2, weight: 1.0 },
        ];
        (items, vec![1.0, 500.0, 400.0])
    }

    #[test]
    fn a_budget_below_the_max_mse_floors_still_allocates() {
        let (items, areas) = lopsided();
        for budget in [0, 8, 40, 200, 600] {
            let a = allocate(&items, &areas, Target::Bytes(budget), Some(DEFAULT_ALPHA))
                .unwrap_or_else(|e| panic!("budget {budget}: {e}"));
            assert!(a.total_bytes <= budget, "{} > {budget}", a.total_bytes);
        }
    }

    #[test]
    fn the_max_mse_floors_never_starve_the_other_objects() {
        // At every budget: the constraint never leaves any object above the free
        // allocation's worst, and the limit it settles on is met by every object.
        let (items, areas) = lopsided();
        for budget in (0..=3200).step_by(160) {
            let a = allocate(&items, &areas, Target::Bytes(budget), Some(DEFAULT_ALPHA)).unwrap();
            let free = allocate(&items, &areas, Target::Bytes(budget), None).unwrap();
            let worst = |v: &[f64]| v.iter().cloned().fold(0.0, f64::max);
            assert!(
                worst(&a.object_mse) <= worst(&free.object_mse) * (1.0 + 1e-9),
                "budget {budget}: {:?} against free {:?}",
                a.object_mse,
                free.object_mse
            );
            let mean = free.object_mse.iter().sum::<f64>() / 3.0;
            // object 0 is the worst; where its whole curve can meet the limit, it gets it
            let reachable = items[0].curve.points.last().unwrap().mse <= 1.25 * mean;
            if worst(&free.object_mse) > 1.25 * mean && reachable && budget > 0 {
                assert!(
                    worst(&a.object_mse) < worst(&free.object_mse),
                    "budget {budget}: the constraint did nothing"
                );
            }
        }
    }

    #[test]
    fn a_smaller_budget_never_gives_a_better_allocation() {
        for (items, areas) in [items(), lopsided()] {
            let mut last = 0.0f64;
            for budget in (0..=4000).rev().step_by(37) {
                let a =
                    allocate(&items, &areas, Target::Bytes(budget), Some(DEFAULT_ALPHA)).unwrap();
                let free = allocate(&items, &areas, Target::Bytes(budget), None).unwrap();
                assert!(a.screen_mse >= free.screen_mse * (1.0 - 1e-12));
                assert!(
                    a.screen_mse >= last * (1.0 - 1e-9),
                    "budget {budget}: screen MSE {} below {last} of a larger budget",
                    a.screen_mse
                );
                last = a.screen_mse;
            }
        }
    }

    #[test]
    fn psnr_target_is_met_with_fewer_bytes_for_less_quality() {
        let (items, areas) = items();
        let hi = allocate(&items, &areas, Target::Psnr { db: 30.0, peak: 1.0 }, None).unwrap();
        let lo = allocate(&items, &areas, Target::Psnr { db: 20.0, peak: 1.0 }, None).unwrap();
        assert!(hi.screen_mse <= 1e-3 && lo.screen_mse <= 1e-2);
        assert!(lo.total_bytes < hi.total_bytes);
        assert!(matches!(
            allocate(&items, &areas, Target::Psnr { db: 400.0, peak: 1.0 }, None),
            Err(AllocError::Unreachable { .. })
        ));
    }

    /// The reachable PSNR is the one an out-of-reach target reports, and a target at it is
    /// met.
    #[test]
    fn the_reachable_psnr_is_the_richest_allocations() {
        let (items, areas) = items();
        let best = reachable_psnr(&items, &areas, 1.0).unwrap();
        let err = allocate(&items, &areas, Target::Psnr { db: best + 1.0, peak: 1.0 }, None);
        assert_eq!(err, Err(AllocError::Unreachable { db: best + 1.0, best_db: best }));
        assert!(allocate(&items, &areas, Target::Psnr { db: best - 1e-9, peak: 1.0 }, None).is_ok());
        for db in [best, best + 1e-12, best * (1.0 + 1e-15)] {
            assert!(allocate(&items, &areas, Target::Psnr { db, peak: 1.0 }, None).is_ok(), "{db}");
        }
    }

    #[test]
    fn hull_drops_points_above_it() {
        let c = RdCurve {
            points: vec![
                RdPoint { bytes: 0, mse: 10.0 },
                RdPoint { bytes: 10, mse: 9.5 },
                RdPoint { bytes: 20, mse: 2.0 },
                RdPoint { bytes: 30, mse: 1.0 },
            ],
        };
        let h = convex_hull(&c);
        assert_eq!(h.iter().map(|p| p.bytes).collect::<Vec<_>>(), vec![0, 20, 30]);
    }
}
