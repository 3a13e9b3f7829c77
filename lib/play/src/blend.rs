//! From a continuous parameter point to the parameter samples whose textures a frame draws:
//! the nearest sample (thesis 4.7), or the 2^d samples around the point with multilinear
//! weights.

use pis_format::{DepMask, Dimension};

/// How a frame between parameter samples is drawn.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Blend {
    /// The textures of the nearest parameter sample.
    #[default]
    Nearest,
    /// The textures of the 2 nearest samples per dimension (2^d in all), blended with
    /// multilinear weights.
    Multilinear,
}

impl Blend {
    /// The name `--blend` takes.
    pub fn name(self) -> &'static str {
        match self {
            Blend::Nearest => "nearest",
            Blend::Multilinear => "multilinear",
        }
    }

    /// Every blend, in the order the tools list them.
    pub const ALL: [Blend; 2] = [Blend::Nearest, Blend::Multilinear];
}

/// Along one dimension: the samples bracketing `x` and the weight of the upper one. Values
/// outside the sampled range clamp to the end samples.
fn bracket(values: &[f32], x: f32) -> (u32, u32, f32) {
    let n = values.len();
    if n <= 1 || x <= values[0] {
        return (0, 0, 0.0);
    }
    if x >= values[n - 1] {
        return ((n - 1) as u32, (n - 1) as u32, 0.0);
    }
    // values ascend (SPEC.md: PSPC values are strictly monotonic); find values[i] ≤ x < values[i+1].
    let ascending = values[n - 1] > values[0];
    let i = if ascending { values.partition_point(|&v| v <= x).saturating_sub(1) } else { 0 };
    let i = i.min(n - 2);
    let (a, b) = (values[i], values[i + 1]);
    let w = if b != a { ((x - a) / (b - a)).clamp(0.0, 1.0) } else { 0.0 };
    (i as u32, i as u32 + 1, w)
}

/// The nearest sample along one dimension (ties to the lower one).
fn nearest(values: &[f32], x: f32) -> u32 {
    let (lo, hi, w) = bracket(values, x);
    if w > 0.5 {
        hi
    } else {
        lo
    }
}

/// Checks a point against the space: one finite value per dimension.
pub fn check_point(dims: &[Dimension], point: &[f32]) -> Result<(), String> {
    if point.len() != dims.len() {
        let names: Vec<&str> = dims.iter().map(|d| d.name.as_str()).collect();
        return Err(format!(
            "a parameter point needs {} values ({}), got {}",
            dims.len(),
            names.join(", "),
            point.len()
        ));
    }
    if let Some(k) = point.iter().position(|v| !v.is_finite()) {
        return Err(format!("value {} of dimension '{}' is not finite", point[k], dims[k].name));
    }
    Ok(())
}

/// The nearest parameter sample (sample index per dimension).
pub fn nearest_sample(dims: &[Dimension], point: &[f32]) -> Vec<u32> {
    dims.iter().zip(point).map(|(d, &x)| nearest(&d.values, x)).collect()
}

/// The samples a frame draws at `point` with their weights (summing to 1); samples of zero
/// weight are left out, so a point on a sample draws that sample alone.
pub fn weighted_samples(dims: &[Dimension], point: &[f32], blend: Blend) -> Vec<(Vec<u32>, f32)> {
    match blend {
        Blend::Nearest => vec![(nearest_sample(dims, point), 1.0)],
        Blend::Multilinear => {
            let mut out: Vec<(Vec<u32>, f32)> = vec![(Vec::with_capacity(dims.len()), 1.0)];
            for (d, &x) in dims.iter().zip(point) {
                let (lo, hi, w) = bracket(&d.values, x);
                let mut next = Vec::with_capacity(out.len() * 2);
                for (s, wt) in out {
                    if w < 1.0 {
                        let mut a = s.clone();
                        a.push(lo);
                        next.push((a, wt * (1.0 - w)));
                    }
                    if w > 0.0 {
                        let mut b = s;
                        b.push(hi);
                        next.push((b, wt * w));
                    }
                }
                out = next;
            }
            out
        }
    }
}

/// Merges weighted samples that a layer depending on `mask` cannot tell apart (equal on the
/// masked dimensions): their weights add. The result keeps the first sample of each class.
pub fn merge_for_mask(samples: &[(Vec<u32>, f32)], mask: DepMask) -> Vec<(Vec<u32>, f32)> {
    let mut out: Vec<(Vec<u32>, f32)> = Vec::new();
    for (s, w) in samples {
        match out.iter_mut().find(|(t, _)| mask.dims().all(|k| t[k] == s[k])) {
            Some(e) => e.1 += w,
            None => out.push((s.clone(), *w)),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use pis_format::DimensionKind;

    fn dim(values: &[f32]) -> Dimension {
        Dimension {
            name: "d".into(),
            kind: DimensionKind::Other,
            periodic: false,
            unit: String::new(),
            block_size: 8,
            values: values.to_vec(),
        }
    }

    #[test]
    fn multilinear_weights_bracket_the_point() {
        let dims = [dim(&[0.0, 1.0, 2.0]), dim(&[10.0, 20.0])];
        let s = weighted_samples(&dims, &[1.25, 12.5], Blend::Multilinear);
        assert_eq!(s.len(), 4);
        let w = |p: [u32; 2]| s.iter().find(|(q, _)| q == &p).map(|x| x.1).unwrap();
        assert!((w([1, 0]) - 0.75 * 0.75).abs() < 1e-6);
        assert!((w([2, 1]) - 0.25 * 0.25).abs() < 1e-6);
        assert!((s.iter().map(|x| x.1).sum::<f32>() - 1.0).abs() < 1e-6);
        // On a sample: that sample alone; outside the range: clamped.
        assert_eq!(
            weighted_samples(&dims, &[2.0, 10.0], Blend::Multilinear),
            vec![(vec![2, 0], 1.0)]
        );
        assert_eq!(
            weighted_samples(&dims, &[-5.0, 99.0], Blend::Multilinear),
            vec![(vec![0, 1], 1.0)]
        );
        assert_eq!(weighted_samples(&dims, &[1.6, 14.0], Blend::Nearest), vec![(vec![2, 0], 1.0)]);
        let merged = merge_for_mask(&s, DepMask::of(&[0]));
        assert_eq!(merged.len(), 2);
        assert!((merged[0].1 - 0.75).abs() < 1e-6);
    }
}
