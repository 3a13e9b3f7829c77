//! Playback: the point moving along a path through the parameter space.
//!
//! The path is a phase `s` that grows with time, one traverse of the space per
//! `seconds_per_traverse`. Every moving dimension maps the phase to its slider position: a
//! bounded dimension goes back and forth (a triangle wave, so it never jumps), a periodic one
//! goes round (from its last sample, which neighbours the first, to its first). On the diagonal every dimension moves at once, from the corner of first samples
//! to the corner of last samples and back; along one dimension the others keep their values.

use super::space::Space;

/// Which dimensions move.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PathKind {
    /// Every dimension at once.
    Diagonal,
    /// Only dimension `k`.
    Along(usize),
}

/// Play/pause state and the phase along the path.
#[derive(Clone, Debug, PartialEq)]
pub struct Playback {
    pub kind: PathKind,
    pub playing: bool,
    /// Seconds for one traverse of the space (first sample to last).
    pub seconds_per_traverse: f32,
    /// Phase in traverses, in [0, 2): [0, 1) forward, [1, 2) back.
    pub phase: f32,
}

impl Playback {
    pub fn new(kind: PathKind) -> Playback {
        Playback { kind, playing: false, seconds_per_traverse: 8.0, phase: 0.0 }
    }

    /// Starts playing from `point`: the phase is chosen so that the path passes through the
    /// current position of the first moving dimension, and the frame does not jump there.
    pub fn play_from(&mut self, space: &Space, point: &[f32]) {
        let k = match self.kind {
            PathKind::Diagonal => 0,
            PathKind::Along(k) => k,
        };
        self.phase = space.axes.get(k).map_or(0.0, |a| a.position_of(point[k]));
        self.playing = true;
    }

    /// Advances by `dt` seconds (nothing when paused) and returns the new point, starting from
    /// `point` for the dimensions that do not move.
    pub fn advance(&mut self, space: &Space, point: &[f32], dt: f32) -> Vec<f32> {
        if self.playing && self.seconds_per_traverse > 0.0 {
            self.phase = (self.phase + dt / self.seconds_per_traverse).rem_euclid(2.0);
        }
        self.point(space, point)
    }

    /// The point at the current phase.
    pub fn point(&self, space: &Space, point: &[f32]) -> Vec<f32> {
        let mut out = point.to_vec();
        for (k, axis) in space.axes.iter().enumerate() {
            let moves = match self.kind {
                PathKind::Diagonal => true,
                PathKind::Along(j) => j == k,
            };
            if moves && k < out.len() {
                let t =
                    if axis.periodic { self.phase.rem_euclid(1.0) } else { triangle(self.phase) };
                out[k] = axis.value_at(t);
            }
        }
        out
    }
}

/// 0 → 1 over the first traverse, back to 0 over the second.
fn triangle(phase: f32) -> f32 {
    let p = phase.rem_euclid(2.0);
    if p <= 1.0 {
        p
    } else {
        2.0 - p
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use pis_format::{Dimension, DimensionKind};

    fn space() -> Space {
        let dim = |name: &str, values: Vec<f32>, periodic| Dimension {
            name: name.into(),
            kind: DimensionKind::Other,
            periodic,
            unit: String::new(),
            block_size: 1,
            values,
        };
        Space::new(&[
            dim("light", vec![0.0, 0.5, 1.0], false),
            dim("view", vec![0.0, 90.0, 180.0, 270.0], true),
        ])
    }

    #[test]
    fn the_diagonal_goes_corner_to_corner_and_back() {
        let s = space();
        let mut p = Playback::new(PathKind::Diagonal);
        p.playing = true;
        p.seconds_per_traverse = 4.0;
        assert_eq!(p.advance(&s, &[0.0, 0.0], 0.0), vec![0.0, 0.0]);
        assert_eq!(p.advance(&s, &[0.0, 0.0], 2.0), vec![0.5, 135.0]);
        // Bounded light turns back at its last sample; periodic view goes round.
        assert_eq!(p.advance(&s, &[0.0, 0.0], 3.0), vec![0.75, 67.5]);
        assert!((p.phase - 1.25).abs() < 1e-6);
        assert_eq!(
            p.advance(&s, &[0.0, 0.0], 3.0),
            vec![0.0, 0.0],
            "after two traverses it is back"
        );
    }

    #[test]
    fn along_one_dimension_the_others_stay() {
        let s = space();
        let mut p = Playback::new(PathKind::Along(0));
        p.play_from(&s, &[0.5, 90.0]);
        assert!((p.phase - 0.5).abs() < 1e-6, "starts where the slider is");
        assert_eq!(p.advance(&s, &[0.5, 90.0], 0.0), vec![0.5, 90.0], "no jump on play");
        let q = p.advance(&s, &[0.5, 90.0], 2.0);
        assert_eq!(q, vec![0.75, 90.0]);
    }

    #[test]
    fn paused_playback_does_not_move() {
        let s = space();
        let mut p = Playback::new(PathKind::Diagonal);
        p.phase = 0.5;
        let a = p.advance(&s, &[0.0, 0.0], 10.0);
        assert_eq!((a, p.phase), (vec![0.5, 135.0], 0.5));
    }

    #[test]
    fn triangle_wave_is_continuous() {
        for i in 0..400 {
            let x = i as f32 * 0.01;
            assert!((triangle(x + 0.01) - triangle(x)).abs() <= 0.0100001, "jump at {x}");
        }
    }
}
