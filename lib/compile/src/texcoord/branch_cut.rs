//! Branch cuts in wrapped texture dimensions (thesis 3.2, step 1): where the visible
//! extents along a periodic dimension leave a gap, the origin moves into the gap's middle,
//! `w' = (w − w_cut) − ⌊w − w_cut⌋`, and wrapping is switched off for that dimension.

/// The cut position for one periodic dimension, or `None` when the visible extents cover
/// the whole period (no gap: the dimension keeps wrapping). `extents` are the visible
/// edges' [min, max] along the dimension, the period is 1.
pub fn find_cut(extents: &[(f64, f64)]) -> Option<f64> {
    let mut spans: Vec<(f64, f64)> = Vec::with_capacity(extents.len());
    for &(lo, hi) in extents {
        if !(lo.is_finite() && hi.is_finite()) || hi - lo >= 1.0 {
            return None;
        }
        let s = lo - lo.floor();
        let e = s + (hi - lo);
        if e > 1.0 {
            spans.push((s, 1.0));
            spans.push((0.0, e - 1.0));
        } else {
            spans.push((s, e));
        }
    }
    if spans.is_empty() {
        return None;
    }
    spans.sort_by(|a, b| a.0.total_cmp(&b.0));
    // Merge, then find the largest gap on the circle.
    let mut merged: Vec<(f64, f64)> = vec![spans[0]];
    for &(s, e) in &spans[1..] {
        let last = merged.last_mut().expect("merged starts non-empty");
        if s <= last.1 {
            last.1 = last.1.max(e)
        } else {
            merged.push((s, e))
        }
    }
    let mut best: Option<(f64, f64)> = None; // (gap length, gap middle)
    for k in 0..merged.len() {
        let end = merged[k].1;
        let next = if k + 1 < merged.len() { merged[k + 1].0 } else { merged[0].0 + 1.0 };
        let gap = next - end;
        if gap > 1e-6 && best.is_none_or(|b| gap > b.0) {
            let mid = end + 0.5 * gap;
            best = Some((gap, mid - mid.floor()));
        }
    }
    best.map(|b| b.1)
}

/// Whether the cut `cut` (from [`find_cut`]) lies in the gap around the period's own seam
/// w = 0 ≡ 1, with every extent inside [0, 1]: the visible part is then contiguous in the
/// original coordinates and needs no cut.
pub fn gap_holds_the_seam(extents: &[(f64, f64)], cut: f64) -> bool {
    let eps = 1e-9;
    if extents.is_empty() || extents.iter().any(|&(lo, hi)| lo < -eps || hi > 1.0 + eps) {
        return false;
    }
    let lo = extents.iter().map(|e| e.0).fold(f64::INFINITY, f64::min);
    let hi = extents.iter().map(|e| e.1).fold(f64::NEG_INFINITY, f64::max);
    cut > hi || cut < lo
}

/// Applies a cut to one coordinate.
pub fn apply_cut(w: f64, cut: f64) -> f64 {
    let d = w - cut;
    d - d.floor()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_visible_seam_moves_the_origin_into_the_gap() {
        // visible: [0.8, 1.0] and [0.0, 0.2] (across the seam), gap (0.2, 0.8)
        let cut = find_cut(&[(0.8, 1.0), (0.0, 0.2)]).unwrap();
        assert!((cut - 0.5).abs() < 1e-9);
        assert!((apply_cut(0.9, cut) - 0.4).abs() < 1e-9);
        assert!((apply_cut(0.1, cut) - 0.6).abs() < 1e-9);
        // everything visible: no cut
        assert_eq!(find_cut(&[(0.0, 0.5), (0.4, 1.0)]), None);
        assert_eq!(find_cut(&[(0.3, 1.4)]), None);
    }

    #[test]
    fn a_gap_around_the_seam_needs_no_cut() {
        // One wall of a room, its u running over [0, 1], seen from 0.13 to 0.87: the gap
        // (0.87, 1.13) holds the seam; cutting there would move the wall's vertices at
        // u = 1 to 0.
        let extents = [(0.13, 0.4), (0.4, 0.87)];
        let cut = find_cut(&extents).unwrap();
        assert!(gap_holds_the_seam(&extents, cut));
        assert_eq!(apply_cut(1.0, cut).round(), 0.0, "the fold the check avoids");
        // A seam inside the visible part (a cylinder seen across its seam) still needs one.
        let across = [(0.8, 1.0), (0.0, 0.2)];
        assert!(!gap_holds_the_seam(&across, find_cut(&across).unwrap()));
    }
}
