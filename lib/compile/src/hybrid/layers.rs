//! Building a lens object's layered environment-map geometry (thesis 6.3.2): the hits of
//! its outgoing rays on the environment (every front-facing hit along each continued ray,
//! over every view sample at once, so that the layers are coherent across the views) are
//! clustered by distance from the lens object's origin with the LBG algorithm; whole
//! environment objects go to the one cluster holding most of their hits, so that no object
//! is torn between layers; each cluster counts a continued ray once, by its frontmost hit in
//! it. Each layer's shell is the shape (sphere, cylinder about the vertical axis, axis-aligned
//! box standing on the layer's lowest hit) whose intersections with the layer's outgoing rays
//! fall nearest the recorded hits. Then, as LBG's iteration with the shells for centres,
//! each object moves to the layer whose shell puts its hits nearest where they are and the
//! shells are fitted again, until no object moves: a floor that spans every distance ends
//! in the layer whose box stands on it, not in the one most of its hits are nearest. The
//! number of layers is the smallest after which one more no longer halves the shells' error
//! (every hit's distance from its shell, relative to its distance from the origin).
//!
//! Not built: quad shells for sparsely occupied layers (thesis 6.3.2.1; SPEC.md 7.3 shape 5).

use std::collections::BTreeMap;

use glam::DVec3;

use crate::shell::geometry::{shell_hit, Shell, ShellShape};

/// An outgoing ray of the lens object and the environment it meets.
#[derive(Clone, Debug, PartialEq)]
pub struct OutgoingRay {
    pub origin: DVec3,
    /// Unit direction.
    pub direction: DVec3,
    /// Front-facing hits along the continued ray, nearest first: distance along the ray and
    /// the object hit.
    pub hits: Vec<(f64, u32)>,
}

/// A clustering of the hits into layers.
#[derive(Clone, Debug, PartialEq)]
pub struct Layers {
    /// Per layer, its mean distance from the origin (increasing).
    pub distances: Vec<f64>,
    /// Each environment object's layer.
    pub layer_of: BTreeMap<u32, usize>,
    /// The hits clustered (every hit of every ray, hidden ones too).
    pub counted: usize,
}

/// The distance from `origin` of the point at `t` along `ray`.
fn hit_distance(ray: &OutgoingRay, t: f64, origin: DVec3) -> f64 {
    (ray.origin + ray.direction * t - origin).length()
}

/// LBG over hit distances with `n` layers: deterministic start at the distances' quantiles,
/// iterated until no hit changes layer; then whole objects assigned and each ray counted
/// once per layer (its frontmost hit there), the layer distances the means of those.
pub fn cluster(rays: &[OutgoingRay], origin: DVec3, n: usize) -> Layers {
    let mut all: Vec<(f64, u32)> = rays
        .iter()
        .flat_map(|r| r.hits.iter().map(move |&(t, o)| (hit_distance(r, t, origin), o)))
        .collect();
    if all.is_empty() || n == 0 {
        return Layers { distances: Vec::new(), layer_of: BTreeMap::new(), counted: 0 };
    }
    all.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    let n = n.min(all.len());
    let mut centres: Vec<f64> =
        (0..n).map(|k| all[((2 * k + 1) * all.len() / (2 * n)).min(all.len() - 1)].0).collect();
    let nearest = |d: f64, c: &[f64]| {
        (0..c.len()).min_by(|&a, &b| (d - c[a]).abs().total_cmp(&(d - c[b]).abs())).unwrap_or(0)
    };
    let mut assign: Vec<usize> = all.iter().map(|h| nearest(h.0, &centres)).collect();
    for _ in 0..1000 {
        let mut sum = vec![(0.0, 0usize); n];
        for (h, &a) in all.iter().zip(&assign) {
            sum[a].0 += h.0;
            sum[a].1 += 1;
        }
        for (c, s) in centres.iter_mut().zip(&sum) {
            if s.1 > 0 {
                *c = s.0 / s.1 as f64;
            }
        }
        let next: Vec<usize> = all.iter().map(|h| nearest(h.0, &centres)).collect();
        if next == assign {
            break;
        }
        assign = next;
    }
    // Whole objects: each to the layer with most of its hits (ties: the nearer layer).
    let mut votes: BTreeMap<u32, Vec<usize>> = BTreeMap::new();
    for (h, &a) in all.iter().zip(&assign) {
        votes.entry(h.1).or_insert_with(|| vec![0; n])[a] += 1;
    }
    let layer_of: BTreeMap<u32, usize> = votes
        .iter()
        .map(|(&o, v)| (o, (0..n).max_by_key(|&k| (v[k], std::cmp::Reverse(k))).unwrap_or(0)))
        .collect();
    finish_layers(rays, layer_of, origin, n)
}

/// [`Layers`] of an assignment of objects to `n` layers: layer distances from the frontmost
/// hit of each ray in each layer, empty layers dropped, the rest renumbered by distance.
fn finish_layers(
    rays: &[OutgoingRay],
    mut layer_of: BTreeMap<u32, usize>,
    origin: DVec3,
    n: usize,
) -> Layers {
    let mut per: Vec<Vec<f64>> = vec![Vec::new(); n];
    for r in rays {
        let mut seen = vec![false; n];
        for &(t, o) in &r.hits {
            let l = layer_of[&o];
            if !seen[l] {
                seen[l] = true;
                per[l].push(hit_distance(r, t, origin));
            }
        }
    }
    let mut kept: Vec<(f64, usize)> = per
        .iter()
        .enumerate()
        .filter(|(_, v)| !v.is_empty())
        .map(|(k, v)| (v.iter().sum::<f64>() / v.len() as f64, k))
        .collect();
    kept.sort_by(|a, b| a.0.total_cmp(&b.0));
    let renumber: BTreeMap<usize, usize> =
        kept.iter().enumerate().map(|(new, &(_, old))| (old, new)).collect();
    layer_of.values_mut().for_each(|l| *l = renumber[l]);
    let distances: Vec<f64> = kept.iter().map(|k| k.0).collect();
    let counted = rays.iter().map(|r| r.hits.len()).sum();
    Layers { distances, layer_of, counted }
}

/// The number of layers (1..=`max`) after which one more no longer halves the error of the
/// fitted shells ([`shells_error`]), its clustering and its shells. `scale`: the lens
/// object's size (its bounding radius), below which distances count as that size.
pub fn choose_layers(
    rays: &[OutgoingRay],
    origin: DVec3,
    max: usize,
    scale: f64,
) -> (Layers, Vec<FittedShell>) {
    let (mut best, mut best_shells) = refine(rays, cluster(rays, origin, 1), origin, scale);
    let mut best_error = shells_error(rays, &best, &best_shells, origin, scale);
    for n in 2..=max.max(1) {
        let start = cluster(rays, origin, n);
        if start.distances.len() <= best.distances.len() {
            break;
        }
        let (next, shells) = refine(rays, start, origin, scale);
        let error = shells_error(rays, &next, &shells, origin, scale);
        if next.distances.len() <= best.distances.len() || error > 0.5 * best_error {
            break;
        }
        (best, best_shells, best_error) = (next, shells, error);
    }
    (best, best_shells)
}

/// Shells fitted to `layers`, then each object moved to the layer whose shell puts its hits
/// nearest where they are, the shells fitted again, until no object moves (at most 8 times):
/// LBG's iteration with the shells for centres, from LBG's clustering by distance.
fn refine(
    rays: &[OutgoingRay],
    mut layers: Layers,
    origin: DVec3,
    scale: f64,
) -> (Layers, Vec<FittedShell>) {
    let fitted = |layers: &Layers| -> Vec<FittedShell> {
        (0..layers.distances.len())
            .filter_map(|l| fit_shell(rays, &layer_hits(rays, layers, l), origin, scale))
            .collect()
    };
    let mut shells = fitted(&layers);
    for _ in 0..8 {
        if shells.len() != layers.distances.len() {
            break;
        }
        let mut cost: BTreeMap<u32, Vec<f64>> = BTreeMap::new();
        for r in rays {
            for &(t, o) in &r.hits {
                let c = cost.entry(o).or_insert_with(|| vec![0.0; shells.len()]);
                for (k, f) in shells.iter().enumerate() {
                    c[k] += relative_error(
                        r,
                        t,
                        shell_hit(&f.shell, r.origin, r.direction),
                        origin,
                        scale,
                    );
                }
            }
        }
        let moved: BTreeMap<u32, usize> = cost
            .iter()
            .map(|(&o, c)| (o, (0..c.len()).min_by(|&a, &b| c[a].total_cmp(&c[b])).unwrap_or(0)))
            .collect();
        if moved == layers.layer_of {
            break;
        }
        let n = moved.values().max().map_or(0, |m| m + 1);
        let next = finish_layers(rays, moved, origin, n);
        let next_shells = fitted(&next);
        if next_shells.len() != next.distances.len() {
            break;
        }
        (layers, shells) = (next, next_shells);
    }
    (layers, shells)
}

/// How far the shells put the environment from where it is: over every hit of every ray
/// (hidden ones too), [`relative_error`] summed.
pub fn shells_error(
    rays: &[OutgoingRay],
    layers: &Layers,
    shells: &[FittedShell],
    origin: DVec3,
    scale: f64,
) -> f64 {
    rays.iter()
        .map(|r| {
            r.hits
                .iter()
                .map(|&(t, o)| {
                    let Some(f) = layers.layer_of.get(&o).and_then(|&l| shells.get(l)) else {
                        return 1.0;
                    };
                    relative_error(r, t, shell_hit(&f.shell, r.origin, r.direction), origin, scale)
                })
                .sum::<f64>()
        })
        .sum()
}

/// The rays' frontmost hits in layer `layer`: (ray index, distance along the ray).
pub fn layer_hits(rays: &[OutgoingRay], layers: &Layers, layer: usize) -> Vec<(usize, f64)> {
    rays.iter()
        .enumerate()
        .filter_map(|(i, r)| {
            r.hits
                .iter()
                .find(|(_, o)| layers.layer_of.get(o) == Some(&layer))
                .map(|&(t, _)| (i, t))
        })
        .collect()
}

/// The error of a shell met at distance `s` along `ray` (negative: missed) where the ray's
/// hit is at `t`: the distance between the two points relative to the hit's distance from
/// the origin (at least `scale`), squared: a shell misplaced by δ at distance D moves what
/// it shows by about δ/D of the angle the lens object spans (parallax); a missed shell 1.
pub fn relative_error(ray: &OutgoingRay, t: f64, s: f64, origin: DVec3, scale: f64) -> f64 {
    if s < 0.0 {
        return 1.0;
    }
    let d = (ray.origin + ray.direction * t - origin).length().max(scale).max(1e-12);
    ((s - t) / d).powi(2).min(1.0)
}

/// A fitted shell and its mean squared relative distance error along the rays.
#[derive(Clone, Debug, PartialEq)]
pub struct FittedShell {
    pub shell: Shell,
    pub mse: f64,
}

/// The shell for one layer's hits (`hits`: ray index and distance along it): a sphere at
/// the layer's mean distance from `origin`, a cylinder about the vertical axis through
/// `origin` at the mean horizontal distance and spanning the hits' heights, and the
/// axis-aligned box whose faces lie at the mean distance of the hits nearest each; the one
/// whose intersection with each ray is nearest the recorded hit (in distance along the ray,
/// relative to the hit's, squared).
pub fn fit_shell(
    rays: &[OutgoingRay],
    hits: &[(usize, f64)],
    origin: DVec3,
    scale: f64,
) -> Option<FittedShell> {
    if hits.is_empty() {
        return None;
    }
    let points: Vec<DVec3> =
        hits.iter().map(|&(i, t)| rays[i].origin + rays[i].direction * t).collect();
    let n = points.len() as f64;
    let radius = points.iter().map(|p| (*p - origin).length()).sum::<f64>() / n;
    let horizontal = points
        .iter()
        .map(|p| ((p.x - origin.x).powi(2) + (p.z - origin.z).powi(2)).sqrt())
        .sum::<f64>()
        / n;
    let (y_min, y_max) = points
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| (lo.min(p.y), hi.max(p.y)));
    // Box: its bottom on the lowest hit (the supporting plane, where the layer has one), its
    // top on the highest; each other hit votes for the side its horizontal offset from the
    // origin points at most, a side's plane at its voters' mean, a side without voters at
    // the layer's mean distance.
    let floor = y_min + 1e-3 * (y_max - y_min).max(1e-9);
    let mut sums = [[0.0f64; 2]; 4];
    for p in points.iter().filter(|p| p.y > floor) {
        let q = *p - origin;
        let (axis, k) = if q.x.abs() >= q.z.abs() { (q.x, 0) } else { (q.z, 2) };
        let face = k + usize::from(axis > 0.0);
        sums[face][0] += axis;
        sums[face][1] += 1.0;
    }
    let side = |f: usize| {
        if sums[f][1] > 0.0 {
            sums[f][0] / sums[f][1]
        } else if f % 2 == 1 {
            radius
        } else {
            -radius
        }
    };
    let lo = DVec3::new(side(0).min(-1e-6), (y_min - origin.y).min(-1e-6), side(2).min(-1e-6));
    let hi = DVec3::new(side(1).max(1e-6), (y_max - origin.y).max(1e-6), side(3).max(1e-6));
    let candidates = [
        Shell { origin, shape: ShellShape::Sphere { radius } },
        Shell {
            origin,
            shape: ShellShape::Cylinder {
                radius: horizontal.max(1e-6),
                y_min: y_min.min(origin.y - 1e-6),
                y_max: y_max.max(origin.y + 1e-6),
            },
        },
        Shell { origin, shape: ShellShape::Box { min: origin + lo, max: origin + hi } },
    ];
    candidates
        .into_iter()
        .map(|shell| {
            let mse = hits
                .iter()
                .map(|&(i, t)| {
                    let s = shell_hit(&shell, rays[i].origin, rays[i].direction);
                    relative_error(&rays[i], t, s, origin, scale)
                })
                .sum::<f64>()
                / n;
            FittedShell { shell, mse }
        })
        .min_by(|a, b| a.mse.total_cmp(&b.mse))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rays from the origin in a fan of directions, hitting a sphere of radius `r` (object
    /// `o`) and, behind it, a cylinder of radius `r2` (object `o2`).
    fn rays(r: f64, r2: f64) -> Vec<OutgoingRay> {
        (0..200)
            .map(|k| {
                let a = k as f64 * 0.0314;
                let d = DVec3::new(a.cos(), 0.2 * (k as f64 * 0.7).sin(), a.sin()).normalize();
                let horizontal = (d.x * d.x + d.z * d.z).sqrt();
                OutgoingRay {
                    origin: DVec3::ZERO,
                    direction: d,
                    hits: vec![(r, 1 + (k % 3) as u32), (r2 / horizontal, 9)],
                }
            })
            .collect()
    }

    #[test]
    fn two_shells_of_hits_give_two_layers_at_their_distances() {
        let rays = rays(1.0, 5.0);
        let (layers, shells) = choose_layers(&rays, DVec3::ZERO, 4, 0.1);
        assert_eq!(layers.distances.len(), 2, "{layers:?}");
        assert_eq!(shells.len(), 2);
        assert!((layers.distances[0] - 1.0).abs() < 1e-9);
        assert!((layers.distances[1] - 5.0).abs() < 0.2, "{:?}", layers.distances);
        // The three near objects share the near layer, the far one the far layer.
        assert_eq!(layers.layer_of.values().copied().collect::<Vec<_>>(), vec![0, 0, 0, 1]);
        // The near layer fits a sphere, the far one a cylinder, exactly.
        let near = fit_shell(&rays, &layer_hits(&rays, &layers, 0), DVec3::ZERO, 0.1).unwrap();
        assert!(
            matches!(near.shell.shape, ShellShape::Sphere { .. }) && near.mse < 1e-12,
            "{near:?}"
        );
        let far = fit_shell(&rays, &layer_hits(&rays, &layers, 1), DVec3::ZERO, 0.1).unwrap();
        assert!(
            matches!(far.shell.shape, ShellShape::Cylinder { .. }) && far.mse < 1e-9,
            "{far:?}"
        );
    }

    #[test]
    fn an_object_is_never_torn_between_layers() {
        // Object 7's hits spread from 1 to 6: LBG alone would split them.
        let rays: Vec<OutgoingRay> = (0..100)
            .map(|k| OutgoingRay {
                origin: DVec3::ZERO,
                direction: DVec3::X,
                hits: vec![(1.0 + 0.05 * k as f64, 7), (20.0, 8)],
            })
            .collect();
        let layers = cluster(&rays, DVec3::ZERO, 3);
        let near: Vec<usize> = layers.layer_of.values().copied().collect();
        assert_eq!(near.len(), 2);
        assert_ne!(near[0], near[1]);
        assert!(layers.distances.len() <= 2);
    }

    #[test]
    fn one_layer_when_a_second_does_not_halve_the_error() {
        let rays: Vec<OutgoingRay> = (0..50)
            .map(|k| OutgoingRay {
                origin: DVec3::ZERO,
                direction: DVec3::Y,
                hits: vec![(3.0 + 0.01 * (k % 5) as f64, k % 4)],
            })
            .collect();
        let (layers, _) = choose_layers(&rays, DVec3::ZERO, 4, 0.1);
        // Four objects, each with hits spread over 3.00–3.04: whole objects in two layers
        // hardly lower the error, so one layer is kept.
        assert_eq!(layers.distances.len(), 1, "{layers:?}");
        assert!((layers.distances[0] - 3.02).abs() < 1e-9, "{layers:?}");
    }
}
