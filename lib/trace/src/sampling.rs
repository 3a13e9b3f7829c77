//! Deterministic random numbers and the sampling routines of the tracer.
//!
//! Every random number the tracer draws comes from a [`Rng`] seeded by a hash, never from
//! global state, so a render is a pure function of its inputs. Shading is seeded from the
//! quantized surface point ([`Rng::at_surface`]), which makes the residual noise of the
//! diffuse layer a fixed function on the surface: it does not change between view samples.

use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// A small, fast, deterministic generator (PCG-XSH-RR 64/32).
#[derive(Clone, Debug)]
pub struct Rng {
    state: u64,
}

/// A 64-bit finaliser (SplitMix64), used to turn keys into seeds.
#[inline]
pub fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// Hashes a list of 64-bit keys into one seed.
#[inline]
pub fn hash_keys(keys: &[u64]) -> u64 {
    let mut h = 0x9e37_79b9_7f4a_7c15u64;
    for &k in keys {
        h = mix64(
            h ^ k.wrapping_add(0x9e37_79b9_7f4a_7c15).wrapping_add(h << 6).wrapping_add(h >> 2),
        );
    }
    h
}

impl Rng {
    /// A generator seeded with `seed`.
    pub fn new(seed: u64) -> Rng {
        let mut r = Rng { state: 0 };
        r.next_u32();
        r.state = r.state.wrapping_add(mix64(seed));
        r.next_u32();
        r
    }

    /// A generator for shading at a surface point: seeded from the object-space point
    /// quantized to cells of size `cell`, the object and the bounce `depth`.
    /// With `cell <= 0` the seed falls back to `fallback` (per pixel sample).
    pub fn at_surface(
        object_point: Vec3,
        cell: f32,
        object: u32,
        depth: u32,
        fallback: u64,
    ) -> Rng {
        if cell > 0.0 {
            let q = (object_point / cell).floor();
            let key = [
                q.x as i64 as u64,
                q.y as i64 as u64,
                q.z as i64 as u64,
                object as u64,
                depth as u64,
            ];
            Rng::new(hash_keys(&key))
        } else {
            Rng::new(hash_keys(&[fallback, object as u64, depth as u64]))
        }
    }

    /// Next uniform 32-bit integer.
    #[inline]
    pub fn next_u32(&mut self) -> u32 {
        let old = self.state;
        self.state =
            old.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
        let xorshifted = (((old >> 18) ^ old) >> 27) as u32;
        let rot = (old >> 59) as u32;
        xorshifted.rotate_right(rot)
    }

    /// Next uniform float in [0, 1).
    #[inline]
    pub fn next_f32(&mut self) -> f32 {
        (self.next_u32() >> 8) as f32 * (1.0 / 16_777_216.0)
    }

    /// Next uniform point in [0, 1)².
    #[inline]
    pub fn next_2d(&mut self) -> Vec2 {
        let x = self.next_f32();
        Vec2::new(x, self.next_f32())
    }
}

/// The `i`-th point of the R2 low-discrepancy sequence, rotated by `shift` (Cranley–Patterson).
pub fn r2_point(i: u32, shift: Vec2) -> Vec2 {
    const A1: f64 = 0.754_877_666_246_692_7;
    const A2: f64 = 0.569_840_290_998_053_2;
    let x = (0.5 + A1 * i as f64 + shift.x as f64).fract() as f32;
    let y = (0.5 + A2 * i as f64 + shift.y as f64).fract() as f32;
    Vec2::new(x.min(0.999_999_94), y.min(0.999_999_94))
}

/// An orthonormal basis around unit `n` (Duff et al. 2017).
pub fn basis(n: Vec3) -> (Vec3, Vec3) {
    let sign = 1.0f32.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (
        Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        Vec3::new(b, sign + n.y * n.y * a, -n.y),
    )
}

/// Transforms a direction from the local frame of `n` (z up) to world space.
pub fn to_world(local: Vec3, n: Vec3) -> Vec3 {
    let (t, b) = basis(n);
    t * local.x + b * local.y + n * local.z
}

/// Cosine-weighted direction on the hemisphere around `n`; pdf = cos θ / π.
pub fn cosine_hemisphere(u: Vec2, n: Vec3) -> Vec3 {
    let r = u.x.sqrt();
    let phi = 2.0 * PI * u.y;
    let local = Vec3::new(r * phi.cos(), r * phi.sin(), (1.0 - u.x).max(0.0).sqrt());
    to_world(local, n).normalize()
}

/// Uniform direction inside the cone of half-angle acos(`cos_max`) around `axis`;
/// pdf = 1 / (2π (1 − cos_max)).
pub fn uniform_cone(u: Vec2, axis: Vec3, cos_max: f32) -> Vec3 {
    let cos_t = 1.0 - u.x * (1.0 - cos_max);
    let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    to_world(Vec3::new(sin_t * phi.cos(), sin_t * phi.sin(), cos_t), axis).normalize()
}

/// A GGX (Trowbridge–Reitz) microfacet normal around `n` with roughness `alpha`,
/// sampled proportionally to D(h) (h·n).
pub fn ggx_half_vector(u: Vec2, n: Vec3, alpha: f32) -> Vec3 {
    let a2 = alpha * alpha;
    let cos2 = (1.0 - u.x) / (1.0 + (a2 - 1.0) * u.x);
    let cos_t = cos2.max(0.0).sqrt();
    let sin_t = (1.0 - cos2).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    to_world(Vec3::new(sin_t * phi.cos(), sin_t * phi.sin(), cos_t), n).normalize()
}

/// Smith G1 for GGX.
pub fn ggx_g1(n_dot: f32, alpha: f32) -> f32 {
    let c = n_dot.abs().max(1e-6);
    let a2 = alpha * alpha;
    2.0 * c / (c + (a2 + (1.0 - a2) * c * c).sqrt())
}

/// Luminance of a linear RGB colour (Rec. 709 weights).
pub fn luminance(c: Vec3) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rng_is_uniform_and_deterministic() {
        let mut a = Rng::new(7);
        let mut b = Rng::new(7);
        let mut sum = 0.0f64;
        for _ in 0..10_000 {
            let x = a.next_f32();
            assert_eq!(x.to_bits(), b.next_f32().to_bits());
            assert!((0.0..1.0).contains(&x));
            sum += x as f64;
        }
        assert!((sum / 10_000.0 - 0.5).abs() < 0.01);
    }

    #[test]
    fn surface_seed_depends_on_cell_only() {
        let p = Vec3::new(0.1234, 0.5, -0.25);
        let a = Rng::at_surface(p, 0.01, 3, 0, 1).next_u32();
        let b = Rng::at_surface(p + Vec3::splat(0.001), 0.01, 3, 0, 99).next_u32();
        let c = Rng::at_surface(p + Vec3::splat(0.02), 0.01, 3, 0, 1).next_u32();
        assert_eq!(a, b);
        assert_ne!(a, c);
    }

    #[test]
    fn cosine_samples_stay_in_hemisphere() {
        let n = Vec3::new(0.3, -0.8, 0.52).normalize();
        let mut r = Rng::new(1);
        let mut mean_cos = 0.0;
        for _ in 0..20_000 {
            let d = cosine_hemisphere(r.next_2d(), n);
            assert!(d.dot(n) >= -1e-5);
            mean_cos += d.dot(n) as f64;
        }
        // E[cos θ] under the cosine distribution is 2/3.
        assert!((mean_cos / 20_000.0 - 2.0 / 3.0).abs() < 0.01);
    }
}
