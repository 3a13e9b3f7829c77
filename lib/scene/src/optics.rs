//! The optics of a surface, shared by the tracer (pis-trace's materials and greedy terms) and
//! the compiler (pis-compile's lens paths), so both follow a ray through an interface with the
//! same operations in the same order, bit for bit.
//!
//! Conventions: directions are unit vectors; `d` travels towards the surface; `n` is the
//! surface's unit normal on the side `d` comes from (`d · n ≤ 0`); `eta` = η_i / η_t, the
//! index of refraction of the incident side over that of the transmitted side.

use glam::Vec3;

/// Schlick's approximation of the Fresnel reflectance, per channel, for reflectance `f0` at
/// normal incidence: F = F0 + (1 − F0)(1 − cos θ)⁵, with cos θ clamped to [0, 1].
pub fn schlick(f0: Vec3, cos_theta: f32) -> Vec3 {
    let m = (1.0 - cos_theta.clamp(0.0, 1.0)).powi(5);
    f0 + (Vec3::ONE - f0) * m
}

/// Exact unpolarised Fresnel reflectance of a dielectric interface: with cos θ_i = `cos_i`
/// (between the reversed incident direction and the normal on the incident side, clamped to
/// [0, 1]), sin² θ_t = η² (1 − cos² θ_i) (Snell) and cos θ_t = √(1 − sin² θ_t),
///
/// r_s = (η cos θ_i − cos θ_t) / (η cos θ_i + cos θ_t),
/// r_p = (cos θ_i − η cos θ_t) / (cos θ_i + η cos θ_t),
/// F = (r_s² + r_p²) / 2;
///
/// 1 under total internal reflection (sin² θ_t ≥ 1).
pub fn fresnel_dielectric(cos_i: f32, eta: f32) -> f32 {
    let cos_i = cos_i.clamp(0.0, 1.0);
    let sin2_t = eta * eta * (1.0 - cos_i * cos_i);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let rs = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let rp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    0.5 * (rs * rs + rp * rp)
}

/// Mirror reflection of direction `d` about normal `n`: r = d − 2 (d · n) n.
pub fn reflect(d: Vec3, n: Vec3) -> Vec3 {
    d - n * (2.0 * d.dot(n))
}

/// Refraction of unit direction `d` through the interface with unit normal `n` (facing
/// against `d`) and relative index `eta` = η_i / η_t: with cos θ_i = −d · n and
/// cos θ_t = √(1 − η² (1 − cos² θ_i)), t = η d + (η cos θ_i − cos θ_t) n, normalized. `None`
/// under total internal reflection (η² (1 − cos² θ_i) ≥ 1).
pub fn refract(d: Vec3, n: Vec3, eta: f32) -> Option<Vec3> {
    let cos_i = -d.dot(n);
    let sin2_t = eta * eta * (1.0 - cos_i * cos_i);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some((d * eta + n * (eta * cos_i - cos_t)).normalize())
}

/// The origin of a ray leaving surface point `p` (geometric normal `ng`) towards `dir`: `p`
/// moved off the surface, to the side `dir` leaves by, by 10⁻⁴ · (1 + the largest |coordinate|
/// of `p`), so that the ray does not hit the surface it starts on.
pub fn offset_origin(p: Vec3, ng: Vec3, dir: Vec3) -> Vec3 {
    let eps = 1e-4 * (1.0 + p.abs().max_element());
    if dir.dot(ng) >= 0.0 {
        p + ng * eps
    } else {
        p - ng * eps
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fresnel_at_normal_incidence_and_tir() {
        for n in [1.33f32, 1.5, 2.4] {
            let r0 = ((n - 1.0) / (n + 1.0)).powi(2);
            assert!((fresnel_dielectric(1.0, 1.0 / n) - r0).abs() < 1e-6);
            assert!((fresnel_dielectric(1.0, n) - r0).abs() < 1e-6);
        }
        // Beyond the critical angle inside glass (41.8°): at 45° and at cos θ = 0.3.
        assert_eq!(fresnel_dielectric(45f32.to_radians().cos(), 1.5), 1.0);
        assert_eq!(fresnel_dielectric(0.3, 1.5), 1.0);
        assert!(refract(Vec3::new(0.95, -0.3122499, 0.0).normalize(), Vec3::Y, 1.5).is_none());
    }

    #[test]
    fn refraction_obeys_snell() {
        let d = Vec3::new(0.5, -0.8660254, 0.0);
        let t = refract(d, Vec3::Y, 1.0 / 1.5).unwrap();
        let sin_i = 0.5f32;
        let sin_t = t.x;
        assert!((sin_i - 1.5 * sin_t).abs() < 1e-5);
    }

    #[test]
    fn reflection_mirrors_the_normal_component() {
        let d = Vec3::new(0.6, -0.8, 0.0);
        assert_eq!(reflect(d, Vec3::Y), Vec3::new(0.6, 0.8, 0.0));
    }

    #[test]
    fn schlick_runs_from_f0_at_normal_incidence_to_one_at_grazing() {
        let f0 = Vec3::new(0.04, 0.5, 1.0);
        assert_eq!(schlick(f0, 1.0), f0);
        assert_eq!(schlick(f0, 0.0), Vec3::ONE);
        assert_eq!(schlick(f0, -0.5), Vec3::ONE);
    }
}
