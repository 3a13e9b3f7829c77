//! The reflection term as an object's shells draw it at every point (SPEC.md 9): what the
//! prediction renders and the screen-error allocation weighs.

use super::super::model::ShellTerms;
use super::views::ShellView;

/// Every point of the set as the object's shells see it.
pub struct ReflectionTerms(pub Vec<ShellView>);

impl ShellTerms for ReflectionTerms {
    fn render(&self, p: usize, _rows: &[u32], maps: &[(&[f32], usize)]) -> Vec<f32> {
        reflection(&self.0[p], maps)
    }

    fn weights(&self, s: usize, texels: usize, points: &[usize]) -> Vec<f32> {
        shell_weights(&self.0, s, texels, points)
    }
}

/// The reflection term of a point per row, from its shells' cube maps (local first when
/// there is one): F ⊙ (L + (1 − α_L)·D), premultiplied "over" (SPEC.md 9).
pub fn reflection(v: &ShellView, maps: &[(&[f32], usize)]) -> Vec<f32> {
    let rows = v.fresnel.len() / 3;
    let mut acc = vec![0.0f32; rows * 3];
    let mut through = vec![1.0f32; rows];
    for (s, &(x, c)) in maps.iter().enumerate() {
        let a = &v.a[s];
        for r in 0..rows {
            let (cols, vals) = a.row(r);
            let mut px = [0.0f32; 4];
            for (&col, &w) in cols.iter().zip(vals) {
                for ch in 0..c {
                    px[ch] += w * x[col as usize * c + ch];
                }
            }
            let alpha = if c == 4 { px[3] } else { 1.0 };
            for ch in 0..3 {
                acc[r * 3 + ch] += through[r] * px[ch];
            }
            through[r] *= 1.0 - alpha;
        }
    }
    acc.iter_mut().zip(&v.fresnel).for_each(|(a, f)| *a *= f);
    acc
}

/// The screen weights of a shell sample: every level is stored, so each texel's column sums
/// as they are, each row weighed by its squared Fresnel factor (the reflection term's error
/// reaches the screen multiplied by F); scaled as a surface texture's weights scale the unweighed
/// sums, so that a shell's error counts F² times a surface texture's.
fn shell_weights(views: &[ShellView], s: usize, n: usize, points: &[usize]) -> Vec<f32> {
    let (mut weighed, mut plain) = (vec![0.0f64; n], 0.0f64);
    for &p in points {
        let v = &views[p];
        let a = &v.a[s];
        for r in 0..a.rows() {
            let f = &v.fresnel[r * 3..r * 3 + 3];
            let f2 = ((f[0] + f[1] + f[2]) as f64 / 3.0).powi(2);
            let (cols, vals) = a.row(r);
            for (&c, &w) in cols.iter().zip(vals) {
                weighed[c as usize] += w as f64 * f2;
                plain += w as f64;
            }
        }
    }
    let scale = if plain > 0.0 { n as f64 / plain } else { 0.0 };
    weighed.iter().map(|w| (w * scale) as f32).collect()
}
