//! The greedy two-path model (thesis 6.2) traced through a lens object alone: from a point
//! of its surface seen along `dir`, the reflection-first and the refraction-first paths,
//! each following at every later interface the child with the larger Fresnel coefficient,
//! with the Fresnel factors, the base colour on entering and the absorption inside
//! multiplied along (F·G). The same model, in the same order of operations, as pis-trace's
//! greedy terms (`Integrator::greedy_term`), which compile the traced set's `reflection` and
//! `refraction` layers and ray records; a test keeps the two identical. Both meet an interface
//! through the same functions, [`pis_scene::optics`].

use glam::Vec3;
pub use pis_scene::optics::{fresnel_dielectric, reflect, refract};

use super::lens::{offset_origin, LensObject, LensSurface};

/// The two terms (thesis 6.2).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Term {
    /// The path that starts with a reflection.
    ReflectionFirst = 0,
    /// The path that starts with a refraction.
    RefractionFirst = 1,
}

pub const TERMS: [Term; 2] = [Term::ReflectionFirst, Term::RefractionFirst];

/// A path's "topology" (thesis 6.4.1): how many interfaces it met and, at each, whether it
/// reflected. Two paths with different topologies are different whatever their directions.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Topology {
    pub interfaces: u8,
    /// Bit i: the path reflected at interface i (the first is the vertex itself).
    pub reflected: u32,
}

/// Where a greedy path leaves the lens object.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LensPath {
    /// The outgoing ray: its origin (offset off the last interface, as pis-trace's) and unit
    /// direction.
    pub exit_origin: Vec3,
    pub exit_direction: Vec3,
    /// F·G: the Fresnel coefficients, base colour and absorption along the path.
    pub modulation: Vec3,
    pub topology: Topology,
}

/// Follows `term` from `first`, the lens object's surface where a ray of direction `dir`
/// (unit) meets it, until the path leaves the object; `None` where the term does not exist
/// (refraction-first under total internal reflection) or the path is still inside after
/// `max_depth` more interfaces.
pub fn greedy_path(
    lens: &LensObject,
    first: &LensSurface,
    dir: Vec3,
    term: Term,
    max_depth: u32,
) -> Option<LensPath> {
    let m = lens.material;
    let eta = if first.front_face { 1.0 / m.ior } else { m.ior };
    let f = fresnel_dielectric(-dir.dot(first.normal), eta);
    let mut topology = Topology { interfaces: 1, reflected: 0 };
    let (mut d, mut modulation) = match term {
        Term::ReflectionFirst => {
            topology.reflected = 1;
            (reflect(dir, first.normal), Vec3::splat(f))
        }
        Term::RefractionFirst => (
            refract(dir, first.normal, eta)?,
            Vec3::splat(1.0 - f) * if first.front_face { m.base } else { Vec3::ONE },
        ),
    };
    let (mut p, mut ng) = (first.position, first.geometric_normal);
    for _ in 0..max_depth {
        let o = offset_origin(p, ng, d);
        let Some(hit) = lens.closest(o, d, f32::INFINITY) else {
            return Some(LensPath { exit_origin: o, exit_direction: d, modulation, topology });
        };
        let s = lens.surface(&hit, o, d);
        if !s.front_face && m.sigma_a != Vec3::ZERO {
            modulation *= (-m.sigma_a * hit.t).exp();
        }
        let eta2 = if s.front_face { 1.0 / m.ior } else { m.ior };
        let f2 = fresnel_dielectric(-d.dot(s.normal), eta2);
        let refracted = if f2 < 0.5 { refract(d, s.normal, eta2) } else { None };
        match refracted {
            Some(t) => {
                modulation *= (1.0 - f2) * if s.front_face { m.base } else { Vec3::ONE };
                d = t;
            }
            None => {
                modulation *= f2;
                d = reflect(d, s.normal);
                if topology.interfaces < 32 {
                    topology.reflected |= 1 << topology.interfaces;
                }
            }
        }
        topology.interfaces = topology.interfaces.saturating_add(1);
        p = s.position;
        ng = s.geometric_normal;
    }
    None
}

/// Whether two paths of one term differ (thesis 6.4.1): one exists and the other not,
/// different topologies, exit directions more than `max_angle` (as its cosine) apart, or
/// F·G differing by more than `max_modulation` in a channel (F·G is interpolated linearly
/// across a triangle, and Fresnel's factors change fast towards grazing angles, faster
/// than the directions do).
pub fn paths_differ(
    a: Option<&LensPath>,
    b: Option<&LensPath>,
    cos_max_angle: f32,
    max_modulation: f32,
) -> bool {
    match (a, b) {
        (None, None) => false,
        (Some(a), Some(b)) => {
            a.topology != b.topology
                || a.exit_direction.dot(b.exit_direction) < cos_max_angle
                || (a.modulation - b.modulation).abs().max_element() > max_modulation
        }
        _ => true,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hybrid::lens::{LensMaterial, LensObject};

    /// A slab of glass between z = 0 and z = −1 (two large quads, outward normals).
    fn slab(ior: f32, sigma: f32) -> LensObject {
        let s = 10.0;
        let positions = vec![
            Vec3::new(-s, -s, 0.0),
            Vec3::new(s, -s, 0.0),
            Vec3::new(s, s, 0.0),
            Vec3::new(-s, s, 0.0),
            Vec3::new(-s, -s, -1.0),
            Vec3::new(s, -s, -1.0),
            Vec3::new(s, s, -1.0),
            Vec3::new(-s, s, -1.0),
        ];
        let normals =
            vec![Vec3::Z, Vec3::Z, Vec3::Z, Vec3::Z, -Vec3::Z, -Vec3::Z, -Vec3::Z, -Vec3::Z];
        let indices = [0, 1, 2, 0, 2, 3, 4, 6, 5, 4, 7, 6];
        LensObject::new(
            LensMaterial { ior, base: Vec3::ONE, sigma_a: Vec3::splat(sigma) },
            positions,
            normals,
            &indices,
        )
    }

    fn entering(lens: &LensObject, dir: Vec3) -> LensSurface {
        let o = Vec3::new(0.0, 0.0, 5.0) - dir * 0.0;
        let hit = lens.closest(o, dir, f32::INFINITY).expect("hits the slab");
        lens.surface(&hit, o, dir)
    }

    #[test]
    fn a_slab_passes_a_ray_parallel_to_itself_attenuated() {
        let lens = slab(1.5, 0.5);
        let dir = Vec3::new(0.3, 0.0, -1.0).normalize();
        let first = entering(&lens, dir);
        let t = greedy_path(&lens, &first, dir, Term::RefractionFirst, 8)
            .expect("refraction-first path");
        // Out of a parallel slab the ray keeps its direction, displaced.
        assert!(t.exit_direction.dot(dir) > 1.0 - 1e-6, "{:?}", t.exit_direction);
        assert!(t.exit_origin.z < -0.999, "{:?}", t.exit_origin);
        assert_eq!(t.topology, Topology { interfaces: 2, reflected: 0 });
        // (1 − F) twice and exp(−σ·d) for the path inside.
        let eta = 1.0 / 1.5;
        let f1 = fresnel_dielectric(-dir.dot(Vec3::Z), eta);
        let inside = refract(dir, Vec3::Z, eta).unwrap();
        let f2 = fresnel_dielectric(-inside.dot(Vec3::Z), 1.5);
        let d = 1.0 / -inside.z;
        let want = (1.0 - f1) * (1.0 - f2) * (-0.5 * d).exp();
        assert!((t.modulation.x - want).abs() < 1e-3 * want, "{} against {want}", t.modulation.x);
        let r = greedy_path(&lens, &first, dir, Term::ReflectionFirst, 8)
            .expect("reflection-first path");
        assert!((r.exit_direction - reflect(dir, Vec3::Z)).length() < 1e-6);
        assert_eq!(r.topology, Topology { interfaces: 1, reflected: 1 });
        assert!((r.modulation.x - f1).abs() < 1e-7);
    }

    #[test]
    fn beyond_the_critical_angle_the_path_reflects_inside() {
        // A 45° prism's hypotenuse seen head-on: the ray enters the short face at normal
        // incidence, meets the hypotenuse at 45° (beyond glass's 41.8° critical angle),
        // reflects there, and leaves through the other short face turned by 90°.
        let positions = vec![
            Vec3::new(0.0, 0.0, 0.5),
            Vec3::new(1.0, 0.0, 0.5),
            Vec3::new(0.0, 1.0, 0.5),
            Vec3::new(0.0, 0.0, -0.5),
            Vec3::new(1.0, 0.0, -0.5),
            Vec3::new(0.0, 1.0, -0.5),
        ];
        // Faces: y = 0 (normal −y), x = 0 (normal −x), hypotenuse (normal (1,1)/√2), caps.
        let indices = [0, 3, 4, 0, 4, 1, 0, 2, 5, 0, 5, 3, 1, 4, 5, 1, 5, 2, 0, 1, 2, 3, 5, 4];
        let lens = LensObject::new(
            LensMaterial { ior: 1.5, base: Vec3::ONE, sigma_a: Vec3::ZERO },
            positions,
            vec![],
            &indices,
        );
        let dir = Vec3::Y;
        let o = Vec3::new(0.3, -2.0, 0.0);
        let hit = lens.closest(o, dir, f32::INFINITY).expect("hits the prism");
        let first = lens.surface(&hit, o, dir);
        let t = greedy_path(&lens, &first, dir, Term::RefractionFirst, 8)
            .expect("refraction-first path");
        assert_eq!(t.topology, Topology { interfaces: 3, reflected: 0b010 });
        assert!(t.exit_direction.dot(-Vec3::X) > 1.0 - 1e-5, "{:?}", t.exit_direction);
        assert!(t.exit_origin.x < 1e-3, "{:?}", t.exit_origin);
    }

    #[test]
    fn paths_differ_by_topology_existence_angle_and_modulation() {
        let a = LensPath {
            exit_origin: Vec3::ZERO,
            exit_direction: Vec3::Z,
            modulation: Vec3::ONE,
            topology: Topology { interfaces: 2, reflected: 0 },
        };
        let mut b = a;
        let cos3 = 3f32.to_radians().cos();
        fn paths_differ(a: Option<&LensPath>, b: Option<&LensPath>, c: f32) -> bool {
            super::paths_differ(a, b, c, 0.05)
        }
        assert!(!paths_differ(Some(&a), Some(&b), cos3));
        b.exit_direction = Vec3::new(0.0, 4f32.to_radians().sin(), 4f32.to_radians().cos());
        assert!(paths_differ(Some(&a), Some(&b), cos3));
        b.exit_direction = Vec3::new(0.0, 2f32.to_radians().sin(), 2f32.to_radians().cos());
        assert!(!paths_differ(Some(&a), Some(&b), cos3));
        b.topology.reflected = 2;
        assert!(paths_differ(Some(&a), Some(&b), cos3));
        assert!(paths_differ(Some(&a), None, cos3));
        assert!(!paths_differ(None, None, cos3));
        b.topology = a.topology;
        b.modulation = Vec3::splat(0.94);
        assert!(paths_differ(Some(&a), Some(&b), cos3));
        b.modulation = Vec3::splat(0.96);
        assert!(!paths_differ(Some(&a), Some(&b), cos3));
    }
}
