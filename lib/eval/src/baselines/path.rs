//! The zig-zag path through a sampled parameter space (thesis 4.8): the last dimension runs
//! fastest and reverses direction at every step of the one before it, so consecutive frames
//! are always parameter-space neighbours.

/// The sample indices of every point of the grid `counts`, in zig-zag order: a snake
/// (boustrophedon) order in which consecutive entries differ by one step in one dimension.
pub fn zigzag(counts: &[u32]) -> Vec<Vec<u32>> {
    if counts.is_empty() || counts.contains(&0) {
        return if counts.is_empty() { vec![vec![]] } else { vec![] };
    }
    let inner = zigzag(&counts[1..]);
    let mut out = Vec::with_capacity(inner.len() * counts[0] as usize);
    for i in 0..counts[0] {
        let forward = i % 2 == 0;
        let rows: Box<dyn Iterator<Item = &Vec<u32>>> =
            if forward { Box::new(inner.iter()) } else { Box::new(inner.iter().rev()) };
        for r in rows {
            let mut p = Vec::with_capacity(counts.len());
            p.push(i);
            p.extend_from_slice(r);
            out.push(p);
        }
    }
    out
}

/// The row-major linear index (last dimension fastest) of `samples` in the grid `counts`.
pub fn linear_index(samples: &[u32], counts: &[u32]) -> usize {
    samples.iter().zip(counts).fold(0usize, |a, (&s, &c)| a * c as usize + s as usize)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zigzag_visits_every_point_once_by_unit_steps() {
        for counts in [vec![4u32], vec![4, 4], vec![3, 2, 5], vec![1, 3]] {
            let path = zigzag(&counts);
            let total: usize = counts.iter().map(|&c| c as usize).product();
            assert_eq!(path.len(), total, "{counts:?}");
            let mut seen: Vec<usize> = path.iter().map(|p| linear_index(p, &counts)).collect();
            seen.sort();
            seen.dedup();
            assert_eq!(seen.len(), total, "{counts:?}: a point is visited twice");
            for w in path.windows(2) {
                let steps: u32 = w[0].iter().zip(&w[1]).map(|(a, b)| a.abs_diff(*b)).sum();
                assert_eq!(steps, 1, "{counts:?}: {:?} → {:?}", w[0], w[1]);
            }
        }
        assert_eq!(zigzag(&[2, 2]), vec![vec![0, 0], vec![0, 1], vec![1, 1], vec![1, 0]]);
    }
}
