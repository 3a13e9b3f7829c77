//! glTF animations: keyframe samplers with STEP, LINEAR and CUBICSPLINE interpolation
//! (glTF 2.0 specification, appendix C "Animation Sampler Interpolation Modes").

use glam::{Quat, Vec3, Vec4};

/// A named glTF animation: channels that drive node translation, rotation or scale.
#[derive(Clone, Debug, PartialEq)]
pub struct Animation {
    pub name: String,
    pub channels: Vec<Channel>,
}

/// One animated property of one node.
#[derive(Clone, Debug, PartialEq)]
pub struct Channel {
    /// Index into [`crate::Rig::nodes`].
    pub node: usize,
    pub path: TargetPath,
    pub sampler: Sampler,
}

/// Which node property a channel drives.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TargetPath {
    Translation,
    /// Unit quaternion (x, y, z, w).
    Rotation,
    Scale,
}

/// glTF sampler interpolation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Interpolation {
    /// The value of the previous keyframe, held until the next.
    Step,
    /// Linear; spherical linear (slerp) for rotations.
    Linear,
    /// Cubic Hermite spline with per-keyframe in- and out-tangents.
    CubicSpline,
}

/// Keyframes: strictly increasing times and their values, stored as `Vec4` (translation and
/// scale use xyz; rotations are quaternions xyzw). For [`Interpolation::CubicSpline`],
/// `values` holds three entries per keyframe: in-tangent, value, out-tangent.
#[derive(Clone, Debug, PartialEq)]
pub struct Sampler {
    pub interpolation: Interpolation,
    pub times: Vec<f32>,
    pub values: Vec<Vec4>,
}

impl Animation {
    /// The time span covered by the animation's keyframes: (first, last) over all channels,
    /// or (0, 0) when it has none.
    pub fn time_range(&self) -> (f32, f32) {
        let mut lo = f32::INFINITY;
        let mut hi = f32::NEG_INFINITY;
        for c in &self.channels {
            if let (Some(first), Some(last)) = (c.sampler.times.first(), c.sampler.times.last()) {
                lo = lo.min(*first);
                hi = hi.max(*last);
            }
        }
        if lo.is_finite() && hi.is_finite() {
            (lo, hi)
        } else {
            (0.0, 0.0)
        }
    }
}

impl Sampler {
    /// Entry `i` of `values`; zero if a hand-built sampler has too few (the loader checks
    /// that every keyframe has its values).
    fn at(&self, i: usize) -> Vec4 {
        self.values.get(i).copied().unwrap_or(Vec4::ZERO)
    }

    /// The keyframe value `k` (the middle entry for cubic splines).
    fn value(&self, k: usize) -> Vec4 {
        match self.interpolation {
            Interpolation::CubicSpline => self.at(3 * k + 1),
            _ => self.at(k),
        }
    }

    /// Samples the sampler at time `t`, clamping outside the keyframe range. Rotations
    /// (`rotation == true`) are slerped (LINEAR) or normalised (CUBICSPLINE).
    pub fn sample(&self, t: f32, rotation: bool) -> Vec4 {
        let n = self.times.len();
        if n == 0 {
            return if rotation { Vec4::new(0.0, 0.0, 0.0, 1.0) } else { Vec4::ZERO };
        }
        if n == 1 || t <= self.times[0] {
            return self.value(0);
        }
        if t >= self.times[n - 1] {
            return self.value(n - 1);
        }
        // Last keyframe k with times[k] <= t; t < times[n-1] so k + 1 < n.
        let k = self.times.partition_point(|&x| x <= t) - 1;
        let (t0, t1) = (self.times[k], self.times[k + 1]);
        let dt = t1 - t0;
        let s = (t - t0) / dt;
        match self.interpolation {
            Interpolation::Step => self.value(k),
            Interpolation::Linear => {
                let (a, b) = (self.value(k), self.value(k + 1));
                if rotation {
                    let q = Quat::from_vec4(a).normalize().slerp(Quat::from_vec4(b).normalize(), s);
                    Vec4::from(q)
                } else {
                    a.lerp(b, s)
                }
            }
            Interpolation::CubicSpline => {
                let p0 = self.at(3 * k + 1);
                let m0 = self.at(3 * k + 2) * dt; // out-tangent of k
                let p1 = self.at(3 * (k + 1) + 1);
                let m1 = self.at(3 * (k + 1)) * dt; // in-tangent of k + 1
                let (s2, s3) = (s * s, s * s * s);
                let v = p0 * (2.0 * s3 - 3.0 * s2 + 1.0)
                    + m0 * (s3 - 2.0 * s2 + s)
                    + p1 * (-2.0 * s3 + 3.0 * s2)
                    + m1 * (s3 - s2);
                if rotation {
                    Vec4::from(Quat::from_vec4(v).normalize())
                } else {
                    v
                }
            }
        }
    }
}

/// A node's local transform as translation, rotation and scale.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Trs {
    pub translation: Vec3,
    pub rotation: Quat,
    pub scale: Vec3,
}

impl Default for Trs {
    fn default() -> Self {
        Trs { translation: Vec3::ZERO, rotation: Quat::IDENTITY, scale: Vec3::ONE }
    }
}

impl Trs {
    /// The matrix T·R·S.
    pub fn matrix(&self) -> glam::Mat4 {
        glam::Mat4::from_scale_rotation_translation(self.scale, self.rotation, self.translation)
    }
}

impl Animation {
    /// Applies the animation at time `t` to the local transforms `locals` (indexed by node).
    pub fn apply(&self, t: f32, locals: &mut [Trs]) {
        for c in &self.channels {
            let Some(local) = locals.get_mut(c.node) else {
                continue;
            };
            match c.path {
                TargetPath::Translation => {
                    local.translation = c.sampler.sample(t, false).truncate()
                }
                TargetPath::Rotation => local.rotation = Quat::from_vec4(c.sampler.sample(t, true)),
                TargetPath::Scale => local.scale = c.sampler.sample(t, false).truncate(),
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: Vec4, b: Vec4) -> bool {
        (a - b).abs().max_element() < 1e-5
    }

    fn scalar(interpolation: Interpolation, times: &[f32], values: &[f32]) -> Sampler {
        Sampler {
            interpolation,
            times: times.to_vec(),
            values: values.iter().map(|&v| Vec4::splat(v)).collect(),
        }
    }

    #[test]
    fn step_holds_previous_keyframe() {
        let s = scalar(Interpolation::Step, &[0.0, 1.0, 2.0], &[10.0, 20.0, 30.0]);
        assert_eq!(s.sample(0.99, false).x, 10.0);
        assert_eq!(s.sample(1.0, false).x, 20.0);
        assert_eq!(s.sample(1.5, false).x, 20.0);
        assert_eq!(s.sample(-3.0, false).x, 10.0);
        assert_eq!(s.sample(9.0, false).x, 30.0);
    }

    #[test]
    fn linear_interpolates_and_clamps() {
        let s = scalar(Interpolation::Linear, &[0.0, 2.0, 3.0], &[0.0, 4.0, 1.0]);
        assert!((s.sample(0.5, false).x - 1.0).abs() < 1e-6);
        assert!((s.sample(2.5, false).x - 2.5).abs() < 1e-6);
        assert_eq!(s.sample(5.0, false).x, 1.0);
    }

    #[test]
    fn linear_rotation_is_slerp() {
        // 0° → 90° about +Y; at t = 0.5 the rotation is 45° about +Y (not a normalised lerp
        // at 0.25, which would differ from slerp).
        let q0 = Quat::IDENTITY;
        let q1 = Quat::from_rotation_y(std::f32::consts::FRAC_PI_2);
        let s = Sampler {
            interpolation: Interpolation::Linear,
            times: vec![0.0, 1.0],
            values: vec![Vec4::from(q0), Vec4::from(q1)],
        };
        let q = Quat::from_vec4(s.sample(0.25, true));
        let expected = Quat::from_rotation_y(std::f32::consts::FRAC_PI_2 * 0.25);
        assert!(q.angle_between(expected) < 1e-5, "{q:?} vs {expected:?}");
        // Hand-computed: sin(π/16), cos(π/16).
        let half = std::f32::consts::PI / 16.0;
        assert!(close(Vec4::from(q), Vec4::new(0.0, half.sin(), 0.0, half.cos())));
    }

    #[test]
    fn linear_rotation_takes_the_short_way() {
        let q0 = Quat::from_rotation_z(0.1);
        let q1 = -Quat::from_rotation_z(0.3); // same rotation, opposite hemisphere
        let s = Sampler {
            interpolation: Interpolation::Linear,
            times: vec![0.0, 1.0],
            values: vec![q0.into(), q1.into()],
        };
        let q = Quat::from_vec4(s.sample(0.5, true));
        assert!(q.angle_between(Quat::from_rotation_z(0.2)) < 1e-5);
    }

    #[test]
    fn cubic_spline_matches_hermite_by_hand() {
        // Keyframes at t = 1 and t = 3 (dt = 2): p0 = 0, out-tangent b0 = 1; p1 = 2,
        // in-tangent a1 = -1. At t = 2 (s = 0.5): h00 = 0.5, h10 = 0.125, h01 = 0.5,
        // h11 = -0.125; m0 = 2·1 = 2, m1 = 2·(-1) = -2
        // → 0.5·0 + 0.125·2 + 0.5·2 + (-0.125)·(-2) = 1.5.
        let s = scalar(Interpolation::CubicSpline, &[1.0, 3.0], &[9.0, 0.0, 1.0, -1.0, 2.0, 9.0]);
        assert!((s.sample(2.0, false).x - 1.5).abs() < 1e-6);
        // At s = 0.25: h00 = 0.84375, h10 = 0.140625, h01 = 0.15625, h11 = -0.046875
        // → 0 + 0.28125 + 0.3125 + 0.09375 = 0.6875.
        assert!((s.sample(1.5, false).x - 0.6875).abs() < 1e-6);
        // Endpoints are the values, not the tangents.
        assert_eq!(s.sample(0.0, false).x, 0.0);
        assert_eq!(s.sample(3.0, false).x, 2.0);
    }

    #[test]
    fn cubic_spline_rotation_is_normalised() {
        let q0 = Quat::IDENTITY;
        let q1 = Quat::from_rotation_x(1.0);
        let z = Vec4::ZERO;
        let s = Sampler {
            interpolation: Interpolation::CubicSpline,
            times: vec![0.0, 1.0],
            values: vec![z, q0.into(), z, z, q1.into(), z],
        };
        let q = s.sample(0.5, true);
        assert!((q.length() - 1.0).abs() < 1e-5);
    }

    #[test]
    fn apply_sets_node_properties() {
        let anim = Animation {
            name: "a".into(),
            channels: vec![Channel {
                node: 1,
                path: TargetPath::Translation,
                sampler: scalar(Interpolation::Linear, &[0.0, 1.0], &[0.0, 2.0]),
            }],
        };
        let mut locals = vec![Trs::default(); 2];
        anim.apply(0.5, &mut locals);
        assert_eq!(locals[1].translation, Vec3::splat(1.0));
        assert_eq!(locals[0], Trs::default());
        assert_eq!(anim.time_range(), (0.0, 1.0));
    }
}
