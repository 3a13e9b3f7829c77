//! Sampling the environment light (pis-scene's [`Environment`]) for next-event estimation,
//! and the densities that multiple importance sampling weighs it by against the BSDF lobes.
//!
//! An image is sampled by its piecewise-constant distribution over the lat-long texels
//! (luminance × sin θ): a point (u, v) of density p(u, v) on the unit square is the direction
//! of density p(u, v) / (2π² sin θ) over the sphere (θ = πv). A uniform environment is
//! sampled cosine-weighted about the shading normal.

use crate::sampling::cosine_hemisphere;
use glam::{Vec2, Vec3};
use pis_scene::environment::{lat_long_direction, lat_long_uv};
use pis_scene::{Environment, EnvironmentRadiance};
use std::f32::consts::PI;

/// One direction drawn towards the environment.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EnvironmentSample {
    /// Unit world direction towards the environment.
    pub direction: Vec3,
    /// Radiance arriving from it.
    pub radiance: Vec3,
    /// Density of the direction (solid angle), > 0.
    pub pdf: f32,
}

/// The environment of a scene, ready to be sampled.
#[derive(Clone, Copy, Debug)]
pub struct EnvironmentLight<'s> {
    pub environment: &'s Environment,
}

impl<'s> EnvironmentLight<'s> {
    /// `None` when the environment is black (nothing to sample).
    pub fn new(environment: &'s Environment) -> Option<EnvironmentLight<'s>> {
        environment.emits().then_some(EnvironmentLight { environment })
    }

    /// Radiance arriving from the world direction `d` (unit).
    pub fn radiance(&self, d: Vec3) -> Vec3 {
        Vec3::from(self.environment.radiance(d))
    }

    /// A direction drawn with the uniform numbers `u` for a surface of shading normal `n`.
    pub fn sample(&self, n: Vec3, u: Vec2) -> Option<EnvironmentSample> {
        let (direction, radiance, pdf) = match &self.environment.radiance {
            EnvironmentRadiance::Uniform(c) => {
                let d = cosine_hemisphere(u, n);
                (d, Vec3::from(*c), n.dot(d).max(0.0) / PI)
            }
            EnvironmentRadiance::Image(image) => {
                let distribution = image.distribution.as_ref()?;
                // The radiance of the texel drawn, whose density this is.
                let (uv, p, (i, j)) = distribution.sample(u.to_array());
                let sin_theta = (PI * uv[1]).sin();
                let d = self.environment.to_world(lat_long_direction(uv));
                (d, Vec3::from(image.texel_at(i, j)), p / (2.0 * PI * PI * sin_theta))
            }
        };
        (pdf > 0.0 && pdf.is_finite()).then_some(EnvironmentSample { direction, radiance, pdf })
    }

    /// The density of [`Self::sample`] drawing the world direction `d` (unit) for a surface of
    /// shading normal `n`.
    pub fn pdf(&self, d: Vec3, n: Vec3) -> f32 {
        match &self.environment.radiance {
            EnvironmentRadiance::Uniform(_) => n.dot(d).max(0.0) / PI,
            EnvironmentRadiance::Image(image) => {
                let Some(distribution) = image.distribution.as_ref() else { return 0.0 };
                let local = self.environment.to_image(d);
                let sin_theta = (1.0 - local.y * local.y).max(0.0).sqrt();
                if sin_theta <= 0.0 {
                    return 0.0;
                }
                distribution.density(lat_long_uv(local)) / (2.0 * PI * PI * sin_theta)
            }
        }
    }
}

/// The balance heuristic: the weight of the strategy of density `a` against one of density
/// `b` (0 when neither can draw the direction).
pub fn balance(a: f32, b: f32) -> f32 {
    if a + b > 0.0 {
        a / (a + b)
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;
    use pis_scene::LatLongImage;
    use std::sync::Arc;

    fn image_environment(
        w: u32,
        h: u32,
        texel: impl Fn(u32, u32) -> [f32; 3],
        rotation_deg: f32,
    ) -> Environment {
        let texels =
            (0..h).flat_map(|j| (0..w).map(move |i| (i, j))).map(|(i, j)| texel(i, j)).collect();
        let image = LatLongImage::new("test.exr".into(), w, h, texels);
        Environment {
            radiance: EnvironmentRadiance::Image(Arc::new(image)),
            rotation: rotation_deg.to_radians(),
            background: false,
        }
    }

    /// Σ L cos / pdf over drawn directions estimates the irradiance: for an image bright in
    /// the +X half (u ∈ [¼, ¾)) with radiance L, a surface facing +X receives πL and one
    /// facing +Y πL/2 (the classic hemisphere-light result E = πL (1 + cos α) / 2); the
    /// estimate's standard deviation is bounded by the range of L cos/pdf over the samples.
    #[test]
    fn sampled_directions_integrate_the_image() {
        let l = 3.0;
        let env = image_environment(
            64,
            32,
            |i, _| if (16..48).contains(&i) { [l; 3] } else { [0.0; 3] },
            0.0,
        );
        let light = EnvironmentLight::new(&env).unwrap();
        let mut rng = Rng::new(5);
        let n_samples = 40_000;
        for (normal, expect) in [(Vec3::X, PI * l), (Vec3::Y, PI * l / 2.0), (Vec3::NEG_X, 0.0)] {
            let (mut sum, mut max, mut other_cell) = (0.0f64, 0.0f32, 0);
            for _ in 0..n_samples {
                let s = light.sample(normal, rng.next_2d()).unwrap();
                assert!(s.direction.x >= -1e-3, "a direction of the dark half: {}", s.direction);
                // The density looked up for the direction is the sample's, but for points
                // that float rounding puts on the edge of the next cell.
                if (light.pdf(s.direction, normal) - s.pdf).abs() > 1e-3 * s.pdf {
                    other_cell += 1;
                }
                let e = s.radiance.x * normal.dot(s.direction).max(0.0) / s.pdf;
                sum += e as f64;
                max = max.max(e);
            }
            assert!(
                other_cell <= n_samples / 1000,
                "{other_cell} densities differ from the lookup"
            );
            let mean = sum / n_samples as f64;
            // Values lie in [0, max]: σ ≤ max/2; allow 4σ of the mean.
            let tolerance = 4.0 * (max as f64 / 2.0) / (n_samples as f64).sqrt() + 1e-6;
            assert!(
                (mean - expect as f64).abs() <= tolerance,
                "normal {normal}: {mean} vs {expect} ± {tolerance}"
            );
        }
    }

    /// `rotation_deg = 90` turns the image centre (+X) to −Z.
    #[test]
    fn rotation_turns_the_image_about_up() {
        // Bright only in the centre column pair (u ≈ 0.5: +X in the image frame).
        let env = image_environment(
            64,
            32,
            |i, j| if (31..33).contains(&i) && (15..17).contains(&j) { [1.0; 3] } else { [0.0; 3] },
            90.0,
        );
        let light = EnvironmentLight::new(&env).unwrap();
        assert_eq!(light.radiance(Vec3::NEG_Z), Vec3::ONE);
        assert_eq!(light.radiance(Vec3::X), Vec3::ZERO);
        let mut rng = Rng::new(1);
        for _ in 0..100 {
            let s = light.sample(Vec3::Y, rng.next_2d()).unwrap();
            assert!(s.direction.dot(Vec3::NEG_Z) > 0.99, "{}", s.direction);
        }
    }

    #[test]
    fn a_black_environment_is_not_sampled() {
        let env = Environment {
            radiance: EnvironmentRadiance::Uniform([0.0; 3]),
            rotation: 0.0,
            background: false,
        };
        assert!(EnvironmentLight::new(&env).is_none());
        let black = image_environment(4, 2, |_, _| [0.0; 3], 0.0);
        assert!(EnvironmentLight::new(&black).is_none());
    }
}
