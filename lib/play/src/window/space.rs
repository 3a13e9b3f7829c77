//! The parameter space as the window's sliders see it: one continuous range per dimension,
//! slider positions ↔ parameter points, nearest samples.

use pis_format::Dimension;

/// The continuous range of one dimension: from its first sample value to its last, the range
/// the player blends over (it clamps values outside it).
#[derive(Clone, Debug, PartialEq)]
pub struct Axis {
    pub name: String,
    pub unit: String,
    /// The sample values, strictly increasing.
    pub samples: Vec<f32>,
    pub min: f32,
    pub max: f32,
    /// The last sample neighbours the first: playback goes round instead of back.
    pub periodic: bool,
}

impl Axis {
    pub fn new(d: &Dimension) -> Axis {
        let min = d.values.first().copied().unwrap_or(0.0);
        let max = d.values.last().copied().unwrap_or(min).max(min);
        Axis {
            name: d.name.clone(),
            unit: d.unit.clone(),
            samples: d.values.clone(),
            min,
            max,
            periodic: d.periodic && d.values.len() >= 2,
        }
    }

    /// Length of the range (0 for a dimension with one sample).
    pub fn span(&self) -> f32 {
        self.max - self.min
    }

    /// The value at slider position `t` ∈ [0, 1] (clamped).
    pub fn value_at(&self, t: f32) -> f32 {
        self.min + t.clamp(0.0, 1.0) * self.span()
    }

    /// The slider position of `value`, the inverse of [`Axis::value_at`].
    pub fn position_of(&self, value: f32) -> f32 {
        if self.span() <= 0.0 {
            return 0.0;
        }
        ((value - self.min) / self.span()).clamp(0.0, 1.0)
    }

    /// Index of the sample nearest to `value` (ties to the lower sample, as the player).
    pub fn nearest_sample(&self, value: f32) -> usize {
        let mut best = 0;
        for (i, s) in self.samples.iter().enumerate() {
            if (s - value).abs() < (self.samples[best] - value).abs() {
                best = i;
            }
        }
        best
    }
}

/// All axes of a file's parameter space.
#[derive(Clone, Debug, PartialEq)]
pub struct Space {
    pub axes: Vec<Axis>,
}

impl Space {
    pub fn new(dims: &[Dimension]) -> Space {
        Space { axes: dims.iter().map(Axis::new).collect() }
    }

    /// The point in the middle of every range, snapped to the nearest sample (a point the
    /// file was traced at, so the first frame is on the sampled manifold).
    pub fn start_point(&self) -> Vec<f32> {
        self.snap(&self.axes.iter().map(|a| a.value_at(0.5)).collect::<Vec<_>>())
    }

    /// Sample indices nearest to `point`.
    pub fn nearest_samples(&self, point: &[f32]) -> Vec<usize> {
        self.axes.iter().zip(point).map(|(a, &v)| a.nearest_sample(v)).collect()
    }

    /// `point` moved to its nearest sample values (what nearest-sample playback shows).
    pub fn snap(&self, point: &[f32]) -> Vec<f32> {
        self.axes.iter().zip(point).map(|(a, &v)| a.samples[a.nearest_sample(v)]).collect()
    }

    /// Slider positions of `point`.
    pub fn positions(&self, point: &[f32]) -> Vec<f32> {
        self.axes.iter().zip(point).map(|(a, &v)| a.position_of(v)).collect()
    }

    /// The point at slider positions `t`.
    pub fn point_at(&self, t: &[f32]) -> Vec<f32> {
        self.axes.iter().zip(t).map(|(a, &t)| a.value_at(t)).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use pis_format::DimensionKind;

    fn dim(name: &str, values: &[f32], periodic: bool) -> Dimension {
        Dimension {
            name: name.into(),
            kind: DimensionKind::View,
            periodic,
            unit: "deg".into(),
            block_size: 2,
            values: values.to_vec(),
        }
    }

    #[test]
    fn slider_positions_and_values_are_inverse() {
        let a = Axis::new(&dim("view", &[-6.0, -2.0, 2.0, 6.0], false));
        assert_eq!((a.min, a.max), (-6.0, 6.0));
        for t in [0.0, 0.125, 0.5, 0.9, 1.0] {
            assert!((a.position_of(a.value_at(t)) - t).abs() < 1e-6, "t = {t}");
        }
        assert_eq!(a.value_at(0.25), -3.0);
        assert_eq!(a.value_at(1.5), 6.0, "a bounded axis clamps");
        assert_eq!(a.value_at(-1.0), -6.0);
    }

    #[test]
    fn nearest_sample_ties_to_the_lower_one() {
        let a = Axis::new(&dim("azimuth", &[0.0, 90.0, 180.0, 270.0], true));
        assert!(a.periodic);
        assert_eq!(
            (a.nearest_sample(45.0), a.nearest_sample(45.1), a.nearest_sample(400.0)),
            (0, 1, 3)
        );
    }

    #[test]
    fn nearest_samples_and_snapping() {
        let s = Space::new(&[
            dim("light", &[0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0], false),
            dim("view", &[-6.0, 6.0], false),
        ]);
        assert_eq!(s.nearest_samples(&[0.4, 1.0]), vec![1, 1]);
        assert_eq!(s.snap(&[0.9, -5.0]), vec![1.0, -6.0]);
        let start = s.start_point();
        assert_eq!(s.snap(&start), start, "the start point is a sample");
        assert_eq!(s.point_at(&s.positions(&[0.25, 3.0])), vec![0.25, 3.0]);
    }

    #[test]
    fn a_single_sample_dimension_is_a_fixed_value() {
        let a = Axis::new(&dim("time", &[2.5], true));
        assert!(!a.periodic);
        assert_eq!((a.value_at(0.7), a.position_of(9.0), a.nearest_sample(-3.0)), (2.5, 0.0, 0));
    }
}
