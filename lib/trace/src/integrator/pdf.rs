//! The densities of the lobes' sampled directions, which next-event estimation weighs its
//! samples against (multiple importance sampling).

use glam::Vec3;
use std::f32::consts::PI;

/// The density of the diffuse lobe's sampled direction `d` ([`super::Integrator`]'s indirect
/// bounce): cosine-weighted about the shading normal `n`, a direction below the geometric
/// surface (normal `ng`) mirrored back above it, so that both the direction and its mirror
/// image lead to `d`.
pub fn diffuse_pdf(n: Vec3, ng: Vec3, d: Vec3) -> f32 {
    let c = ng.dot(d);
    if c <= 0.0 {
        return 0.0;
    }
    let mirrored = d - ng * (2.0 * c);
    (n.dot(d).max(0.0) + n.dot(mirrored).max(0.0)) / PI
}

/// The density of the GGX lobe's reflected direction `l` for the view direction `wo` (both
/// unit, away from the surface) about the shading normal `n`: D(h) (n·h) / (4 (wo·h)), the
/// half vector h drawn proportionally to D(h) (n·h).
pub fn ggx_reflection_pdf(n: Vec3, wo: Vec3, l: Vec3, alpha: f32) -> f32 {
    let h = (wo + l).normalize_or_zero();
    let (nh, vh) = (n.dot(h), wo.dot(h));
    if nh <= 0.0 || vh <= 0.0 {
        return 0.0;
    }
    let a2 = alpha * alpha;
    let dd = nh * nh * (a2 - 1.0) + 1.0;
    a2 / (PI * dd * dd) * nh / (4.0 * vh)
}
