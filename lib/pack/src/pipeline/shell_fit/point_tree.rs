//! A bounding-box tree over points that answers "is any point in front of this plane?" by
//! branch and bound, without visiting the points a box shows to be behind it.

use glam::Vec3;

/// Points per leaf.
const LEAF: usize = 8;

struct Node {
    centre: Vec3,
    half: Vec3,
    /// The leaf's points, `points[first..first + count]`; an inner node has count 0 and its
    /// children at `first` and `first + 1`.
    first: u32,
    count: u32,
}

/// The tree: nodes with the root first, and the points reordered by leaf.
pub struct PointTree {
    nodes: Vec<Node>,
    points: Vec<Vec3>,
}

impl PointTree {
    /// Builds the tree by median splits along each node's longest axis (ties broken by the
    /// points' order, so the build is deterministic).
    pub fn new(points: &[Vec3]) -> Self {
        let mut tree = PointTree { nodes: Vec::new(), points: points.to_vec() };
        if !points.is_empty() {
            tree.nodes.push(Node { centre: Vec3::ZERO, half: Vec3::ZERO, first: 0, count: 0 });
            tree.build(0, 0, points.len());
        }
        tree
    }

    fn build(&mut self, node: usize, start: usize, end: usize) {
        let slice = &mut self.points[start..end];
        let (lo, hi) =
            slice.iter().fold((slice[0], slice[0]), |(lo, hi), &p| (lo.min(p), hi.max(p)));
        self.nodes[node].centre = (lo + hi) * 0.5;
        self.nodes[node].half = (hi - lo) * 0.5;
        if slice.len() <= LEAF {
            self.nodes[node].first = start as u32;
            self.nodes[node].count = slice.len() as u32;
            return;
        }
        let axis = (hi - lo).max_position();
        let mid = slice.len() / 2;
        slice.select_nth_unstable_by(mid, |a, b| a[axis].total_cmp(&b[axis]));
        let child = self.nodes.len();
        self.nodes[node].first = child as u32;
        for _ in 0..2 {
            self.nodes.push(Node { centre: Vec3::ZERO, half: Vec3::ZERO, first: 0, count: 0 });
        }
        self.build(child, start, start + mid);
        self.build(child + 1, start + mid, end);
    }

    /// The largest n·p over a node's box.
    fn bound(&self, node: usize, n: Vec3) -> f32 {
        let b = &self.nodes[node];
        n.dot(b.centre) + n.abs().dot(b.half)
    }

    /// Whether some point p has n·p > `limit`. Children are searched the more promising
    /// first, so a point in front is usually found after a few leaves.
    pub fn any_above(&self, n: Vec3, limit: f32) -> bool {
        if self.nodes.is_empty() || self.bound(0, n) <= limit {
            return false;
        }
        let mut stack = vec![0usize];
        while let Some(node) = stack.pop() {
            let b = &self.nodes[node];
            if b.count > 0 {
                let leaf = &self.points[b.first as usize..(b.first + b.count) as usize];
                if leaf.iter().any(|p| n.dot(*p) > limit) {
                    return true;
                }
                continue;
            }
            let (l, r) = (b.first as usize, b.first as usize + 1);
            let (bl, br) = (self.bound(l, n), self.bound(r, n));
            // Pushed last, popped first: the child with the larger bound.
            let order = if bl >= br { [(r, br), (l, bl)] } else { [(l, bl), (r, br)] };
            stack.extend(order.into_iter().filter(|&(_, bound)| bound > limit).map(|(c, _)| c));
        }
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pipeline::shell_fit::test_meshes::sphere_points;

    #[test]
    fn agrees_with_a_scan() {
        let points: Vec<Vec3> = sphere_points(1000)
            .iter()
            .enumerate()
            .map(|(k, p)| *p * (0.5 + (k % 5) as f32 * 0.1))
            .collect();
        let tree = PointTree::new(&points);
        for (k, n) in sphere_points(50).into_iter().enumerate() {
            let limit = (k % 10) as f32 * 0.1;
            let scan = points.iter().any(|p| n.dot(*p) > limit);
            assert_eq!(tree.any_above(n, limit), scan, "direction {n}, limit {limit}");
        }
        assert!(!PointTree::new(&[]).any_above(Vec3::X, 0.0));
    }
}
