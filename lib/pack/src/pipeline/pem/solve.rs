//! Inferring a layered environment map (thesis 5.8): per parameter sample, each shell's cube
//! map — every MIP level at once (5.8.1) — by chapter 3's regularized least squares
//! against the tracer's incident specular layer, through the shell's render matrix. The
//! local shell's premultiplied colour and its alpha are solved apart (the same A), the
//! distant shell's colour alone; each sample starts from the last sample's solution.

use std::collections::BTreeMap;

use anyhow::Result;
use pis_compile::{RenderMatrix, SolveSettings, TextureLayout, View};

use crate::solutions::Solver;

/// The amplitude weight of a neighbouring sample's rows in a sample's solve (its squared
/// error counts this squared: 1/16).
pub const NEIGHBOUR_SCALE: f32 = 0.25;

use super::views::ShellView;

/// Which traced layer a shell is solved for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Target {
    /// The local layer: premultiplied RGB and alpha (4 channels).
    Local,
    /// The distant layer (3 channels).
    Distant,
    /// All incident light: the local layer over the distant (3 channels), for a single
    /// shell.
    Incident,
}

impl Target {
    pub fn channels(self) -> usize {
        match self {
            Target::Local => 4,
            Target::Distant | Target::Incident => 3,
        }
    }
}

/// One shell's samples: per key, the cube map (texels × channels, the layout's order).
pub struct SolvedShell {
    pub textures: BTreeMap<Vec<u32>, Vec<f32>>,
    pub iterations: u64,
    pub residual_rms: f64,
}

/// Solves shell `s` (of the views' shells) for `target` at every point, keyed by `keys`
/// (one key per point: shells are view-dependent), each point's rows stacked with its
/// neighbours' (the points before and after it) weighed by [`NEIGHBOUR_SCALE`].
pub fn solve_shell(
    views: &[ShellView],
    s: usize,
    layout: TextureLayout,
    target: Target,
    keys: &[Vec<u32>],
    settings: &SolveSettings,
    solver: &Solver,
) -> Result<SolvedShell> {
    let n = layout.texel_count();
    let c = target.channels();
    let mut textures = BTreeMap::new();
    let (mut iterations, mut sq, mut count) = (0u64, 0.0f64, 0usize);
    let mut warm_rgb: Option<Vec<f32>> = None;
    let mut warm_alpha: Option<Vec<f32>> = None;
    // Each neighbour's rows, weighed down: the parts of the environment a sample's view does
    // not see are inferred from its neighbours' views (thesis 6.3: matching over several
    // nearby viewpoints keeps the maps complete for cameras off the samples).
    let scaled: Vec<(RenderMatrix, Vec<f32>, Option<Vec<f32>>)> = views
        .iter()
        .map(|v| {
            let mut a = v.a[s].clone();
            a.vals.iter_mut().for_each(|x| *x *= NEIGHBOUR_SCALE);
            let (rgb, alpha) = split(v, target);
            let scale =
                |b: Vec<f32>| b.into_iter().map(|x| x * NEIGHBOUR_SCALE).collect::<Vec<f32>>();
            (a, scale(rgb), alpha.map(scale))
        })
        .collect();
    for (i, (v, k)) in views.iter().zip(keys).enumerate() {
        let a = &v.a[s];
        let mut texels = vec![0.0f32; n * c];
        let neighbours: Vec<usize> = [i.wrapping_sub(1), i + 1]
            .into_iter()
            .filter(|&j| j < views.len() && scaled[j].0.rows() > 0)
            .collect();
        if a.rows() > 0 {
            let (rgb, alpha) = split(v, target);
            let rgb_n: Vec<(&RenderMatrix, &[f32])> =
                neighbours.iter().map(|&j| (&scaled[j].0, scaled[j].1.as_slice())).collect();
            let x = solve_stacked(a, &rgb, &rgb_n, warm_rgb.as_deref(), settings, solver)?;
            iterations += x.iterations as u64;
            sq += x.residual_rms * x.residual_rms * a.rows() as f64;
            count += a.rows();
            for t in 0..n {
                texels[t * c..t * c + 3].copy_from_slice(&x.texels[t * 3..t * 3 + 3]);
            }
            warm_rgb = Some(x.texels);
            if let Some(alpha) = alpha {
                let alpha_n: Vec<(&RenderMatrix, &[f32])> = neighbours
                    .iter()
                    .filter_map(|&j| scaled[j].2.as_deref().map(|b| (&scaled[j].0, b)))
                    .collect();
                let y =
                    solve_stacked(a, &alpha, &alpha_n, warm_alpha.as_deref(), settings, solver)?;
                iterations += y.iterations as u64;
                for t in 0..n {
                    texels[t * c + 3] = y.texels[t * 3];
                }
                warm_alpha = Some(y.texels);
            }
        } else if let Some(w) = &warm_rgb {
            // A sample where the object covers no pixel keeps its neighbour's map.
            for t in 0..n {
                texels[t * c..t * c + 3].copy_from_slice(&w[t * 3..t * 3 + 3]);
                if c == 4 {
                    texels[t * c + 3] = warm_alpha.as_ref().map_or(0.0, |a| a[t * 3]);
                }
            }
        }
        textures.insert(k.clone(), texels);
    }
    Ok(SolvedShell { textures, iterations, residual_rms: (sq / count.max(1) as f64).sqrt() })
}

/// Solves shell `s` for the distant layer once per class of points with equal `keys`, over
/// all the class's views at once (thesis eq. 3.7, as a view-independent texture): a depth
/// shell's texels are points of the scene's surfaces, which every view sees alike, so one
/// map serves the views between and beyond the samples too.
pub fn solve_shell_shared(
    views: &[ShellView],
    s: usize,
    layout: TextureLayout,
    keys: &[Vec<u32>],
    settings: &SolveSettings,
    solver: &Solver,
) -> Result<SolvedShell> {
    let mut classes: BTreeMap<&Vec<u32>, Vec<usize>> = BTreeMap::new();
    for (i, k) in keys.iter().enumerate() {
        classes.entry(k).or_default().push(i);
    }
    let mut textures = BTreeMap::new();
    let (mut iterations, mut sq, mut count) = (0u64, 0.0f64, 0usize);
    for (k, members) in classes {
        let rhs: Vec<Vec<f32>> =
            members.iter().map(|&i| split(&views[i], Target::Distant).0).collect();
        let stacked: Vec<View> = members
            .iter()
            .zip(&rhs)
            .filter(|(&i, _)| views[i].a[s].rows() > 0)
            .map(|(&i, b)| View { a: &views[i].a[s], b })
            .collect();
        let texels = if stacked.is_empty() {
            vec![0.0; layout.texel_count() * 3]
        } else {
            let rows: usize = stacked.iter().map(|v| v.a.rows()).sum();
            let x = solver.solve_view_independent(&stacked, None, settings)?;
            iterations += x.iterations as u64;
            sq += x.residual_rms * x.residual_rms * rows as f64;
            count += rows;
            x.texels
        };
        textures.insert(k.clone(), texels);
    }
    Ok(SolvedShell { textures, iterations, residual_rms: (sq / count.max(1) as f64).sqrt() })
}

/// One sample's solve: its own rows, stacked with its weighed-down neighbours' when it has
/// any (eq. 3.7's stacking, in the AᵀA form).
fn solve_stacked(
    a: &RenderMatrix,
    b: &[f32],
    neighbours: &[(&RenderMatrix, &[f32])],
    warm: Option<&[f32]>,
    settings: &SolveSettings,
    solver: &Solver,
) -> Result<pis_compile::Solution> {
    if neighbours.is_empty() {
        return Ok(solver.solve(a, b, warm, settings)?);
    }
    let views: Vec<View> = std::iter::once(View { a, b })
        .chain(neighbours.iter().map(|&(a, b)| View { a, b }))
        .collect();
    Ok(solver.solve_view_independent(&views, warm, settings)?)
}

/// The traced distant layer of a point's rows, clipped as its solve clips it (RGB per row).
pub fn distant_values(v: &ShellView) -> Vec<f32> {
    split(v, Target::Distant).0
}

/// The right-hand sides of a point: RGB per row, and for the local layer its alpha in the
/// first channel (the other two zero, so their solves stop at once). Incident radiance is
/// clipped at 1/F per channel (thesis 5.9 clips samples too bright): beyond it the
/// reflection term alone is white on a display, so the clip changes no displayed pixel,
/// while a light's reflection, orders of magnitude brighter than the rest, would otherwise
/// dominate the least-squares fit of its neighbourhood.
fn split(v: &ShellView, target: Target) -> (Vec<f32>, Option<Vec<f32>>) {
    let clip = |x: f32, f: f32| if f > 0.0 { x.min(1.0 / f) } else { x };
    match target {
        Target::Distant => {
            (v.distant.iter().zip(&v.fresnel).map(|(&x, &f)| clip(x, f)).collect(), None)
        }
        Target::Incident => {
            let rgb = v
                .local
                .chunks_exact(4)
                .zip(v.distant.chunks_exact(3))
                .zip(v.fresnel.chunks_exact(3))
                .flat_map(|((l, d), f)| [0, 1, 2].map(|c| clip(l[c] + (1.0 - l[3]) * d[c], f[c])))
                .collect();
            (rgb, None)
        }
        Target::Local => {
            let rgb = v
                .local
                .chunks_exact(4)
                .zip(v.fresnel.chunks_exact(3))
                .flat_map(|(p, f)| [clip(p[0], f[0]), clip(p[1], f[1]), clip(p[2], f[2])])
                .collect();
            let alpha = v.local.chunks_exact(4).flat_map(|p| [p[3], 0.0, 0.0]).collect();
            (rgb, Some(alpha))
        }
    }
}
