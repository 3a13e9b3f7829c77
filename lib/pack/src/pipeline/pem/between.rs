//! A distant shell judged between the samples (thesis 5.8's shells drawn off the sampled
//! views): solved from two points with a third between them held out, and drawn there as
//! the player draws a point between samples — a view-dependent shell blended from the two
//! points' maps, a depth shell's one map over the views looked up along the held-out
//! point's own rays. The error at the held-out point tells a shell that follows the
//! reflected geometry (its map consistent from view to view) from one fitted to each view.

use anyhow::Result;
use pis_compile::shell::Shell;
use pis_compile::{RenderMatrix, SolveSettings, TextureLayout};

use super::super::model::key;
use super::super::represent::Job;
use super::fit::is_depth;
use super::solve::{distant_values, solve_shell, solve_shell_shared, Target};
use super::views::shell_views;

/// The three points of the trial, two solved from and the middle one held out: of the
/// points that share the middle point's sample of the non-view dimensions (`keys`, one per
/// point), the middle three in order; `None` where fewer than three share it.
pub fn held_out_points(keys: &[Vec<u32>]) -> Option<[usize; 3]> {
    let middle = keys.get(keys.len() / 2)?;
    let class: Vec<usize> = (0..keys.len()).filter(|&p| &keys[p] == middle).collect();
    let m = class.len() / 2;
    (class.len() >= 3).then(|| [class[m - 1], class[m], class[m + 1]])
}

/// The RMS error, against the traced distant layer (clipped as the solve clips it), of
/// distant shell `shell` with `n`-texel faces at the middle of `points`, solved from the
/// other two; `None` where the held-out point covers no pixel.
pub fn between_error(
    job: &Job<'_>,
    o: usize,
    (shell, n): (&Shell, u32),
    f0: [f32; 3],
    (pixels, points): (&[Vec<u32>], [usize; 3]),
    settings: &SolveSettings,
) -> Result<Option<f64>> {
    let set = job.set;
    let [a, m, b] = points;
    let layout = TextureLayout::cube(n);
    let geometry = [(shell.clone(), layout, None)];
    let lookups = job.req.shell_lookups;
    let train_pixels = [pixels[a].clone(), pixels[b].clone()];
    let train = shell_views(set, o, &job.meshes, &geometry, lookups, f0, (&train_pixels, &[a, b]))?;
    let held = shell_views(set, o, &job.meshes, &geometry, lookups, f0, (&pixels[m..=m], &[m]))?;
    let Some(held) = held.first().filter(|v| v.a[0].rows() > 0) else { return Ok(None) };
    let shared: Vec<Vec<u32>> = [a, b].map(|p| key(&set.samples[p], job.non_view)).to_vec();
    let maps: Vec<Vec<f32>> = if is_depth(shell) {
        let solved = solve_shell_shared(&train, 0, layout, &shared, settings, &job.solver)?;
        solved.textures.into_values().collect()
    } else {
        let keys: Vec<Vec<u32>> = [a, b].map(|p| key(&set.samples[p], job.all)).to_vec();
        let solved = solve_shell(&train, 0, layout, Target::Distant, &keys, settings, &job.solver)?;
        solved.textures.into_values().collect()
    };
    let want = distant_values(held);
    Ok(Some(rms(&held.a[0], &maps, &want)))
}

/// The RMS difference between `want` (RGB per row) and the mean of `maps` drawn through `a`.
fn rms(a: &RenderMatrix, maps: &[Vec<f32>], want: &[f32]) -> f64 {
    let w = 1.0 / maps.len().max(1) as f64;
    let mut sq = 0.0f64;
    for r in 0..a.rows() {
        let (cols, vals) = a.row(r);
        for ch in 0..3 {
            let got: f64 = maps
                .iter()
                .map(|x| {
                    cols.iter().zip(vals).map(|(&c, &v)| v as f64 * x[c as usize * 3 + ch] as f64)
                })
                .map(|terms| terms.sum::<f64>() * w)
                .sum();
            sq += (got - want[r * 3 + ch] as f64).powi(2);
        }
    }
    (sq / (a.rows() * 3).max(1) as f64).sqrt()
}

#[cfg(test)]
mod tests {
    use super::held_out_points;

    #[test]
    fn the_held_out_point_lies_between_two_of_its_own_light_sample() {
        // 2 light places × 4 views, row-major (the view fastest): the middle point, 4, is
        // the second light's first view, so the trial is that light's views 1, 2, 3.
        let keys: Vec<Vec<u32>> = (0..8).map(|p| vec![p / 4]).collect();
        assert_eq!(held_out_points(&keys), Some([5, 6, 7]));
        // A view-only set: one class.
        assert_eq!(held_out_points(&vec![vec![]; 4]), Some([1, 2, 3]));
        assert_eq!(held_out_points(&vec![vec![]; 2]), None);
        assert_eq!(held_out_points(&[vec![0], vec![1], vec![2]]), None);
    }
}
