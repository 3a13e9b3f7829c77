//! Shell geometry (thesis 5.4, SPEC.md 7.3): the simple surface an environment-map layer lies
//! on, and the cube-map lookup vector of a reflection ray — the ray from a surface point is
//! intersected with the shell, and the hit point minus the shell's origin indexes the cube
//! map (normalization is not needed for the cube parameterization).
//!
//! WGSL twin: `reflect_about`, `shell_hit`, `lookup_direction` and `fresnel` in
//! `lib/play/src/shell.wgsl`, same names and order of operations.

use std::sync::Arc;

use glam::DVec3;

use super::depth::{depth_hit, DepthCube};

/// A shell's shape and parameters, in world space (SPEC.md 7.3, shapes 1–4 and 6).
#[derive(Clone, Debug, PartialEq)]
pub enum ShellShape {
    /// Centred on the origin.
    Sphere { radius: f64 },
    /// Axis-aligned, centred on the origin.
    Ellipsoid { radii: DVec3 },
    /// Axis-aligned box between two corners (which contain the origin).
    Box { min: DVec3, max: DVec3 },
    /// Capped cylinder with its axis parallel to +Y through the origin.
    Cylinder { radius: f64, y_min: f64, y_max: f64 },
    /// Star-shaped about the origin, its radius per direction the depth cube's distance,
    /// met by marching `steps` steps ([`super::depth`]).
    Depth { cube: Arc<DepthCube>, steps: u32 },
}

impl ShellShape {
    /// The shape's name (SPEC.md 7.3).
    pub fn name(&self) -> &'static str {
        match self {
            ShellShape::Sphere { .. } => "sphere",
            ShellShape::Ellipsoid { .. } => "ellipsoid",
            ShellShape::Box { .. } => "box",
            ShellShape::Cylinder { .. } => "cylinder",
            ShellShape::Depth { .. } => "depth",
        }
    }
}

/// A closed shell: its shape and the origin lookup vectors start from.
#[derive(Clone, Debug, PartialEq)]
pub struct Shell {
    pub origin: DVec3,
    pub shape: ShellShape,
}

impl Shell {
    /// The shell's SPEC.md 7.3 shape id and its twelve placement values.
    pub fn placement_values(&self) -> (u16, [f32; 12]) {
        let mut v = [0.0f32; 12];
        v[..3].copy_from_slice(&self.origin.as_vec3().to_array());
        let id = match &self.shape {
            &ShellShape::Sphere { radius } => {
                v[3] = radius as f32;
                1
            }
            &ShellShape::Ellipsoid { radii } => {
                v[3..6].copy_from_slice(&radii.as_vec3().to_array());
                2
            }
            &ShellShape::Box { min, max } => {
                v[3..6].copy_from_slice(&min.as_vec3().to_array());
                v[6..9].copy_from_slice(&max.as_vec3().to_array());
                3
            }
            &ShellShape::Cylinder { radius, y_min, y_max } => {
                v[3] = radius as f32;
                v[4] = y_min as f32;
                v[5] = y_max as f32;
                4
            }
            ShellShape::Depth { cube, steps } => {
                v[3] = cube.size as f32;
                v[4] = *steps as f32;
                v[5] = cube.far;
                6
            }
        };
        (id, v)
    }

    /// The shell of shape id `id` and placement values `v` (the inverse of
    /// [`Self::placement_values`]); `None` for quads, depth shells (whose depth cube is cast
    /// from the scene: [`Shell::depth`]) and unknown ids.
    pub fn from_placement(id: u16, v: &[f32; 12]) -> Option<Shell> {
        let d = |k: usize| DVec3::new(v[k] as f64, v[k + 1] as f64, v[k + 2] as f64);
        let shape = match id {
            1 => ShellShape::Sphere { radius: v[3] as f64 },
            2 => ShellShape::Ellipsoid { radii: d(3) },
            3 => ShellShape::Box { min: d(3), max: d(6) },
            4 => {
                ShellShape::Cylinder { radius: v[3] as f64, y_min: v[4] as f64, y_max: v[5] as f64 }
            }
            _ => return None,
        };
        Some(Shell { origin: d(0), shape })
    }

    /// The depth shell about `origin` with depth cube `cube`, marched in `steps` steps.
    pub fn depth(origin: DVec3, cube: DepthCube, steps: u32) -> Shell {
        Shell { origin, shape: ShellShape::Depth { cube: Arc::new(cube), steps } }
    }
}

/// The far intersection (largest t ≥ 0) of the ray `p + t·r` with the shell, or a negative
/// value when the ray does not meet it at t ≥ 0. `r` need not be normalized.
pub fn shell_hit(shell: &Shell, p: DVec3, r: DVec3) -> f64 {
    let q = p - shell.origin;
    match shell.shape {
        ShellShape::Depth { ref cube, steps } => depth_hit(cube, steps, shell.origin, p, r),
        ShellShape::Sphere { radius } => {
            quadratic_far(r.dot(r), q.dot(r), q.dot(q) - radius * radius)
        }
        ShellShape::Ellipsoid { radii } => {
            let (qs, rs) = (q / radii, r / radii);
            quadratic_far(rs.dot(rs), qs.dot(rs), qs.dot(qs) - 1.0)
        }
        ShellShape::Box { min, max } => {
            let (lo, hi) = (min - shell.origin, max - shell.origin);
            let mut near = f64::NEG_INFINITY;
            let mut far = f64::INFINITY;
            for k in 0..3 {
                let (a, b) = slab(q[k], r[k], lo[k], hi[k]);
                near = near.max(a);
                far = far.min(b);
            }
            if near <= far {
                far
            } else {
                -1.0
            }
        }
        ShellShape::Cylinder { radius, y_min, y_max } => {
            let a = r.x * r.x + r.z * r.z;
            let b = q.x * r.x + q.z * r.z;
            let c = q.x * q.x + q.z * q.z - radius * radius;
            let (mut near, mut far) = (f64::NEG_INFINITY, f64::INFINITY);
            if a > 0.0 {
                let disc = b * b - a * c;
                if disc < 0.0 {
                    return -1.0;
                }
                let s = disc.sqrt();
                near = (-b - s) / a;
                far = (-b + s) / a;
            } else if c > 0.0 {
                return -1.0;
            }
            let (a2, b2) = slab(q.y, r.y, y_min - shell.origin.y, y_max - shell.origin.y);
            near = near.max(a2);
            far = far.min(b2);
            if near <= far {
                far
            } else {
                -1.0
            }
        }
    }
}

/// The larger root of a·t² + 2b·t + c = 0, or −1 when there is none.
fn quadratic_far(a: f64, b: f64, c: f64) -> f64 {
    let disc = b * b - a * c;
    if a <= 0.0 || disc < 0.0 {
        return -1.0;
    }
    (-b + disc.sqrt()) / a
}

/// The interval of t where `q + t·r` lies in [lo, hi] along one axis.
fn slab(q: f64, r: f64, lo: f64, hi: f64) -> (f64, f64) {
    if r == 0.0 {
        return if q >= lo && q <= hi {
            (f64::NEG_INFINITY, f64::INFINITY)
        } else {
            (f64::INFINITY, f64::NEG_INFINITY)
        };
    }
    let (t0, t1) = ((lo - q) / r, (hi - q) / r);
    (t0.min(t1), t0.max(t1))
}

/// The mirror reflection of direction `v` about the unit normal `n`: v − 2(v·n)n.
pub fn reflect_about(v: DVec3, n: DVec3) -> DVec3 {
    v - n * (2.0 * v.dot(n))
}

/// The cube-map lookup vector of a surface point `p` with interpolated normal `normal` seen
/// from `eye` (thesis 5.4): the reflection ray `r` of the view direction off the normalized
/// normal, its far hit on the shell minus the shell's origin; where the ray does not meet
/// the shell (a surface point outside it), `r` itself, as for a shell at infinity.
pub fn lookup_direction(shell: &Shell, p: DVec3, normal: DVec3, eye: DVec3) -> DVec3 {
    let n = normal.normalize_or_zero();
    let v = (p - eye).normalize_or_zero();
    let r = reflect_about(v, n);
    let t = shell_hit(shell, p, r);
    if t >= 0.0 {
        p + r * t - shell.origin
    } else {
        r
    }
}

/// Schlick's Fresnel factor at a surface point seen from `eye` (SPEC.md 9):
/// F0 + (1 − F0)(1 − cos θ)⁵, cos θ = clamp(−V·N, 0, 1), V the unit view direction, N the
/// normalized normal.
pub fn fresnel(f0: DVec3, p: DVec3, normal: DVec3, eye: DVec3) -> DVec3 {
    let n = normal.normalize_or_zero();
    let v = (p - eye).normalize_or_zero();
    let c = (-v.dot(n)).clamp(0.0, 1.0);
    let k = (1.0 - c).powi(5);
    f0 + (DVec3::ONE - f0) * k
}

#[cfg(test)]
mod tests {
    use super::*;

    fn on_shell(shell: &Shell, x: DVec3) -> bool {
        let q = x - shell.origin;
        match shell.shape {
            ShellShape::Sphere { radius } => (q.length() - radius).abs() < 1e-9,
            ShellShape::Ellipsoid { radii } => ((q / radii).length() - 1.0).abs() < 1e-9,
            ShellShape::Box { min, max } => {
                let inside = (0..3).all(|k| x[k] >= min[k] - 1e-9 && x[k] <= max[k] + 1e-9);
                inside
                    && (0..3).any(|k| (x[k] - min[k]).abs() < 1e-9 || (x[k] - max[k]).abs() < 1e-9)
            }
            ShellShape::Cylinder { radius, y_min, y_max } => {
                let rho = (q.x * q.x + q.z * q.z).sqrt();
                let inside = rho <= radius + 1e-9 && x.y >= y_min - 1e-9 && x.y <= y_max + 1e-9;
                inside
                    && ((rho - radius).abs() < 1e-9
                        || (x.y - y_min).abs() < 1e-9
                        || (x.y - y_max).abs() < 1e-9)
            }
            ShellShape::Depth { .. } => false,
        }
    }

    fn shells() -> Vec<Shell> {
        let o = DVec3::new(0.2, 0.5, -0.1);
        vec![
            Shell { origin: o, shape: ShellShape::Sphere { radius: 3.0 } },
            Shell { origin: o, shape: ShellShape::Ellipsoid { radii: DVec3::new(1.0, 0.5, 2.0) } },
            Shell {
                origin: o,
                shape: ShellShape::Box {
                    min: DVec3::new(-4.0, 0.0, -3.0),
                    max: DVec3::new(5.0, 3.0, 2.0),
                },
            },
            Shell {
                origin: o,
                shape: ShellShape::Cylinder { radius: 2.0, y_min: 0.0, y_max: 2.5 },
            },
        ]
    }

    #[test]
    fn rays_from_inside_leave_through_the_shell() {
        let mut seed = 7u64;
        let mut rnd = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        for shell in shells() {
            for _ in 0..200 {
                let p = shell.origin + DVec3::new(rnd(), rnd(), rnd()) * 0.2;
                let r = DVec3::new(rnd(), rnd(), rnd());
                let t = shell_hit(&shell, p, r);
                assert!(t > 0.0, "{shell:?}");
                assert!(on_shell(&shell, p + r * t), "{shell:?} {p} {r} {t}");
            }
        }
    }

    #[test]
    fn a_ray_that_misses_looks_up_its_own_direction() {
        let shell = Shell { origin: DVec3::ZERO, shape: ShellShape::Sphere { radius: 1.0 } };
        // A point outside the sphere reflecting away from it.
        let d = lookup_direction(
            &shell,
            DVec3::new(0.0, 5.0, 0.0),
            DVec3::Y,
            DVec3::new(0.0, 10.0, 0.0),
        );
        assert!((d - DVec3::Y).length() < 1e-12);
    }

    #[test]
    fn a_large_sphere_looks_up_nearly_the_reflection_direction() {
        let shell = Shell { origin: DVec3::ZERO, shape: ShellShape::Sphere { radius: 1e6 } };
        let d = lookup_direction(
            &shell,
            DVec3::new(0.1, 0.0, 0.0),
            DVec3::Z,
            DVec3::new(0.0, 0.0, 5.0),
        );
        let r = reflect_about(
            (DVec3::new(0.1, 0.0, 0.0) - DVec3::new(0.0, 0.0, 5.0)).normalize(),
            DVec3::Z,
        );
        assert!(d.normalize().dot(r) > 1.0 - 1e-9);
    }

    #[test]
    fn placement_values_round_trip() {
        for s in shells() {
            let (id, v) = s.placement_values();
            let back = Shell::from_placement(id, &v).unwrap();
            assert_eq!(back.placement_values(), (id, v));
        }
    }
}
