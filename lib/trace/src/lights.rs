//! Lights: next-event estimation towards point, spot, directional and sphere (area) lights,
//! and ray hits on the visible light spheres.
//!
//! A light of intensity I (`Light::radiance`, W/sr-like) with sphere radius r > 0 is a sphere
//! of uniform radiance I / (π r²): seen from afar it delivers the irradiance of the point
//! light I / d², up close it casts soft shadows.

use crate::sampling::{uniform_cone, Rng};
use glam::Vec3;
use pis_scene::{Light, LightKind};
use std::f32::consts::PI;

/// One light sample seen from a surface point.
#[derive(Clone, Copy, Debug)]
pub struct LightSample {
    /// Unit direction from the point towards the light.
    pub direction: Vec3,
    /// Distance to the sampled light point (infinite for directional lights).
    pub distance: f32,
    /// Incident radiance divided by the sampling pdf (solid angle), i.e. the estimator of
    /// ∫ L cos / cos over this light; multiply by cos θ and the BRDF.
    pub weight: Vec3,
}

/// Spot cone attenuation for direction `to_point` (unit, from the light).
fn spot_factor(light: &Light, to_point: Vec3) -> f32 {
    match light.kind {
        LightKind::Spot { inner_cone, outer_cone } => {
            let c = to_point.dot(light.direction.normalize_or_zero());
            let (ci, co) = (inner_cone.cos(), outer_cone.cos());
            let t = if ci - co > 1e-6 {
                ((c - co) / (ci - co)).clamp(0.0, 1.0)
            } else if c >= co {
                1.0
            } else {
                0.0
            };
            t * t
        }
        _ => 1.0,
    }
}

/// Radiance of the surface of a sphere light.
pub fn sphere_radiance(light: &Light) -> Vec3 {
    Vec3::from(light.radiance) / (PI * light.radius * light.radius)
}

/// Samples `light` from point `p`; `None` when the light cannot contribute.
pub fn sample_light(light: &Light, p: Vec3, rng: &mut Rng) -> Option<LightSample> {
    let intensity = Vec3::from(light.radiance);
    match light.kind {
        LightKind::Directional => {
            let d = -light.direction.normalize_or_zero();
            (d != Vec3::ZERO).then_some(LightSample {
                direction: d,
                distance: f32::INFINITY,
                weight: intensity,
            })
        }
        _ => {
            let to_light = light.position - p;
            let d2 = to_light.length_squared();
            if d2.is_nan() || d2 <= 0.0 {
                return None;
            }
            let dist = d2.sqrt();
            let axis = to_light / dist;
            let spot = spot_factor(light, -axis);
            if spot <= 0.0 {
                return None;
            }
            if light.radius <= 0.0 {
                return Some(LightSample {
                    direction: axis,
                    distance: dist,
                    weight: intensity * spot / d2,
                });
            }
            let r = light.radius;
            if dist <= r * 1.0001 {
                return None;
            }
            let cos_max = (1.0 - r * r / d2).max(0.0).sqrt();
            let dir = uniform_cone(rng.next_2d(), axis, cos_max);
            // Distance to the near side of the sphere along dir.
            let b = dir.dot(to_light);
            let disc = b * b - (d2 - r * r);
            let t = b - disc.max(0.0).sqrt();
            let solid_angle = 2.0 * PI * (1.0 - cos_max);
            Some(LightSample {
                direction: dir,
                distance: t.max(0.0),
                weight: sphere_radiance(light) * spot * solid_angle,
            })
        }
    }
}

/// The nearest visible light sphere along a ray within `tmax`: (t, emitted radiance).
pub fn hit_light_sphere(
    lights: &[Light],
    origin: Vec3,
    dir: Vec3,
    tmax: f32,
) -> Option<(f32, Vec3)> {
    hit_sphere_among(lights.iter(), origin, dir, tmax)
}

/// [`hit_light_sphere`] for a camera ray: the spheres with `visible_camera`.
pub fn camera_hit_light_sphere(
    lights: &[Light],
    origin: Vec3,
    dir: Vec3,
    tmax: f32,
) -> Option<(f32, Vec3)> {
    hit_sphere_among(lights.iter().filter(|l| l.visible_camera), origin, dir, tmax)
}

fn hit_sphere_among<'a>(
    lights: impl Iterator<Item = &'a Light>,
    origin: Vec3,
    dir: Vec3,
    tmax: f32,
) -> Option<(f32, Vec3)> {
    let mut best: Option<(f32, Vec3)> = None;
    for light in lights {
        if light.radius <= 0.0 || light.kind == LightKind::Directional {
            continue;
        }
        let oc = light.position - origin;
        let b = dir.dot(oc);
        let disc = b * b - (oc.length_squared() - light.radius * light.radius);
        if disc < 0.0 {
            continue;
        }
        let s = disc.sqrt();
        let t = if b - s > 0.0 { b - s } else { b + s };
        if t <= 0.0 || t >= tmax || best.is_some_and(|(bt, _)| bt <= t) {
            continue;
        }
        let spot = spot_factor(light, (origin - light.position).normalize_or_zero());
        best = Some((t, sphere_radiance(light) * spot));
    }
    best
}
