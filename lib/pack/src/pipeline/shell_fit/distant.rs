//! The distant shell: a box or a sphere at the average distance of the reflected
//! environment (thesis 5.4).

use anyhow::{anyhow, Result};
use glam::{DVec3, Vec3};

/// An axis-aligned box shell.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoxShell {
    pub min: Vec3,
    pub max: Vec3,
}

/// A finite sphere shell.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SphereShell {
    pub centre: Vec3,
    pub radius: f32,
}

/// No side of a shell is closer to its centre than this fraction of the hits' mean
/// distance, nor than [`MIN_DISTANCE`].
pub const MIN_DISTANCE_RATIO: f64 = 1e-3;
pub const MIN_DISTANCE: f64 = 1e-6;

/// The mean distance of the finite hits from `centre`, and their count.
fn mean_distance(centre: Vec3, hits: &[Vec3]) -> (f64, usize) {
    let (sum, n) = hits
        .iter()
        .filter(|h| h.is_finite())
        .fold((0.0, 0), |(s, n), h| (s + (*h - centre).as_dvec3().length(), n + 1));
    (if n > 0 { sum / n as f64 } else { 0.0 }, n)
}

fn minimum(mean: f64) -> f64 {
    (mean * MIN_DISTANCE_RATIO).max(MIN_DISTANCE)
}

/// A box map for the distant layer (thesis 5.4: "For objects resting on flat surfaces, it
/// is effective to align the box bottom with this flat surface and extend the other sides
/// to match the average distance to environmental geometry").
///
/// `hits` are world points where reflected rays from the object met the environment. Each
/// hit votes for the side its dominant axis (the largest |component| of hit − centre, the
/// first axis on a tie) and sign point to; a side lies at the mean distance, along its
/// axis, of its hits. The bottom (−Y) lies at `support_y` when given. A side without hits
/// lies at the mean of the other sides' distances. Every distance is at least a small
/// positive minimum ([`MIN_DISTANCE_RATIO`] of the hits' mean distance), so the box strictly
/// contains `centre`. Non-finite hits are ignored; without hits or a support it is an error.
pub fn distant_box(centre: Vec3, support_y: Option<f32>, hits: &[Vec3]) -> Result<BoxShell> {
    // Sides in the order −X, +X, −Y, +Y, −Z, +Z.
    let (mut sum, mut count) = ([0.0f64; 6], [0usize; 6]);
    for h in hits.iter().filter(|h| h.is_finite()) {
        let d = (*h - centre).as_dvec3().to_array();
        let axis = (1..3).fold(0, |b, k| if d[k].abs() > d[b].abs() { k } else { b });
        let side = 2 * axis + usize::from(d[axis] > 0.0);
        sum[side] += d[axis].abs();
        count[side] += 1;
    }
    let mut distance: [Option<f64>; 6] =
        std::array::from_fn(|s| (count[s] > 0).then(|| sum[s] / count[s] as f64));
    if let Some(y) = support_y.filter(|y| y.is_finite()) {
        distance[2] = Some(f64::from(centre.y) - f64::from(y));
    }
    let (hit_mean, n) = mean_distance(centre, hits);
    let least = match (n, distance[2]) {
        (0, Some(bottom)) => minimum(bottom.abs()),
        (0, None) => return Err(anyhow!("no reflected ray met the environment and there is no support plane: the distant box has no size")),
        _ => minimum(hit_mean),
    };
    let known: Vec<f64> = distance.iter().flatten().map(|d| d.max(least)).collect();
    let fill = known.iter().sum::<f64>() / known.len() as f64;
    let side = |s: usize| distance[s].unwrap_or(fill).max(least);
    let c = centre.as_dvec3();
    Ok(BoxShell {
        min: (c - DVec3::new(side(0), side(2), side(4))).as_vec3(),
        max: (c + DVec3::new(side(1), side(3), side(5))).as_vec3(),
    })
}

/// A finite sphere map for the distant layer (thesis 5.4): centred at `centre`, with
/// radius the mean distance of the hits from it, at least [`MIN_DISTANCE`]. Non-finite
/// hits are ignored; without hits it is an error.
pub fn distant_sphere(centre: Vec3, hits: &[Vec3]) -> Result<SphereShell> {
    let (mean, n) = mean_distance(centre, hits);
    if n == 0 {
        return Err(anyhow!(
            "no reflected ray met the environment: the distant sphere has no size"
        ));
    }
    Ok(SphereShell { centre, radius: mean.max(minimum(mean)) as f32 })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: Vec3, b: Vec3) -> bool {
        a.distance(b) < 1e-4
    }

    #[test]
    fn sides_at_the_mean_distance_of_their_hits() {
        let c = Vec3::new(1.0, 1.0, 1.0);
        let hits = [
            c + Vec3::new(4.0, 1.0, -2.0),
            c + Vec3::new(6.0, -3.0, 0.0), // +X: 4, 6
            c + Vec3::new(-3.0, 0.5, 0.5), // −X: 3
            c + Vec3::new(0.0, 2.0, 1.0),  // +Y: 2
            c + Vec3::new(1.0, -1.0, 0.0), // tie: the first axis, −X is not it: +X
            c + Vec3::new(0.0, -1.5, 0.0), // −Y: 1.5
            c + Vec3::new(0.0, 0.0, 7.0),
            c + Vec3::new(1.0, 0.0, -5.0), // +Z: 7, −Z: 5
        ];
        let b = distant_box(c, None, &hits).unwrap();
        assert!(close(b.min, c - Vec3::new(3.0, 1.5, 5.0)), "{b:?}");
        assert!(close(b.max, c + Vec3::new(11.0 / 3.0, 2.0, 7.0)), "{b:?}");
    }

    #[test]
    fn bottom_on_the_support_and_empty_sides_filled() {
        let c = Vec3::new(0.0, 1.0, 0.0);
        let hits = [c + Vec3::X * 4.0, c - Vec3::X * 2.0, c + Vec3::Y * 3.0, c - Vec3::Y * 9.0];
        let b = distant_box(c, Some(0.0), &hits).unwrap();
        // Known: 2, 4, bottom 1 (the −Y hit is overruled), 3; ±Z get their mean, 2.5.
        assert!(close(b.min, Vec3::new(-2.0, 0.0, -2.5)), "{b:?}");
        assert!(close(b.max, Vec3::new(4.0, 4.0, 2.5)), "{b:?}");
        // A support alone sizes the box.
        let b = distant_box(c, Some(0.0), &[]).unwrap();
        assert!(
            close(b.min, Vec3::new(-1.0, 0.0, -1.0)) && close(b.max, Vec3::new(1.0, 2.0, 1.0)),
            "{b:?}"
        );
        assert!(distant_box(c, None, &[]).is_err());
    }

    #[test]
    fn always_contains_the_centre() {
        let c = Vec3::new(0.0, 1.0, 0.0);
        // A support above the centre, hits on the centre.
        let b = distant_box(c, Some(2.0), &[c, c + Vec3::X * 5.0]).unwrap();
        assert!(b.min.cmplt(c).all() && b.max.cmpgt(c).all(), "{b:?}");
    }

    #[test]
    fn sphere_radius_is_the_mean_distance() {
        let s = distant_sphere(
            Vec3::ONE,
            &[Vec3::ONE + Vec3::X * 2.0, Vec3::ONE - Vec3::Z * 4.0, Vec3::NAN],
        )
        .unwrap();
        assert_eq!(s, SphereShell { centre: Vec3::ONE, radius: 3.0 });
        assert!(distant_sphere(Vec3::ONE, &[Vec3::ONE]).unwrap().radius > 0.0);
        assert!(distant_sphere(Vec3::ONE, &[]).is_err());
    }
}
