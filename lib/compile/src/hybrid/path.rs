//! The paths through a lens object traced against the object alone: from a point of its
//! surface seen along `dir`, the terms of the greedy two-path model (thesis 6.2) or of the
//! ray tree (7.3). The walk is pis-trace's own ([`pis_scene::lens_tree`]), which compiles the
//! traced set's term layers and ray records; only the intersection differs (the lens
//! object's triangles here, the scene's BVH there), and a test keeps the two identical.

use glam::Vec3;
use pis_scene::lens_tree::{LensInterface, Step};
pub use pis_scene::lens_tree::{LensModel, Topology, MAX_TERMS};
pub use pis_scene::optics::{fresnel_dielectric, reflect, refract};

use super::lens::{LensObject, LensSurface};

/// The terms of a lens model: the greedy model's two (thesis 6.2), the first two of the
/// tree's, then the tree's refraction-first paths that took the branch the greedy model
/// drops once and twice (pis-trace's `refraction_1` and `refraction_2` layers).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Term {
    /// The path that starts with a reflection.
    ReflectionFirst = 0,
    /// The path that starts with a refraction.
    RefractionFirst = 1,
    /// A refraction-first path that took the lesser branch once.
    RefractionLesser1 = 2,
    /// A refraction-first path that took the lesser branch twice.
    RefractionLesser2 = 3,
}

/// The greedy model's terms.
pub const TERMS: [Term; 2] = [Term::ReflectionFirst, Term::RefractionFirst];

impl Term {
    /// Every term, in order.
    pub const ALL: [Term; MAX_TERMS] = [
        Term::ReflectionFirst,
        Term::RefractionFirst,
        Term::RefractionLesser1,
        Term::RefractionLesser2,
    ];

    /// The terms `model` fills, in order.
    pub fn of(model: LensModel) -> &'static [Term] {
        &Term::ALL[..model.terms()]
    }
}

/// The lens model a file's `lens_model` setting records (SPEC.md 6.6).
pub fn file_lens_model(terms: pis_format::lens_model::LensTerms) -> LensModel {
    match terms {
        pis_format::lens_model::LensTerms::Greedy => LensModel::Greedy,
        pis_format::lens_model::LensTerms::Tree { min_weight, terms } => {
            LensModel::Tree { min_weight, internal_terms: terms.saturating_sub(1) }
        }
    }
}

/// What a file records of `model` (SPEC.md 6.6 `lens_model`).
pub fn file_lens_terms(model: LensModel) -> pis_format::lens_model::LensTerms {
    match model {
        LensModel::Greedy => pis_format::lens_model::LensTerms::Greedy,
        LensModel::Tree { min_weight, .. } => {
            pis_format::lens_model::LensTerms::Tree { min_weight, terms: model.terms() as u8 }
        }
    }
}

/// Where a path leaves the lens object (the runtime model keeps nothing of the exit itself).
pub type LensPath = pis_scene::lens_tree::LensPath<()>;

/// The terms of `model` from `first`, the lens object's surface where a ray of direction
/// `dir` (unit) meets it: the walk pis-trace's lens terms take ([`pis_scene::lens_tree`]),
/// with the lens object's own triangles and material for the interfaces it meets.
pub fn lens_paths(
    lens: &LensObject,
    first: &LensSurface,
    dir: Vec3,
    model: LensModel,
    max_depth: u32,
) -> [Option<LensPath>; MAX_TERMS] {
    lens_paths_counted(lens, first, dir, model, max_depth).0
}

/// [`lens_paths`] and the number of rays the walk cast through the lens object.
pub fn lens_paths_counted(
    lens: &LensObject,
    first: &LensSurface,
    dir: Vec3,
    model: LensModel,
    max_depth: u32,
) -> ([Option<LensPath>; MAX_TERMS], u64) {
    let m = lens.material;
    let mut rays = 0u64;
    let interface = |s: &LensSurface, absorption: Vec3| LensInterface {
        position: s.position,
        normal: s.normal,
        geometric_normal: s.geometric_normal,
        front_face: s.front_face,
        ior: m.ior,
        base: m.base,
        absorption,
    };
    let paths = pis_scene::lens_tree::lens_paths(
        &interface(first, Vec3::ONE),
        dir,
        model,
        max_depth,
        |o, d| {
            rays += 1;
            match lens.closest(o, d, f32::INFINITY) {
                None => Step::Exit(()),
                Some(hit) => {
                    let s = lens.surface(&hit, o, d);
                    let absorption = if !s.front_face && m.sigma_a != Vec3::ZERO {
                        (-m.sigma_a * hit.t).exp()
                    } else {
                        Vec3::ONE
                    };
                    Step::Interface(interface(&s, absorption))
                }
            }
        },
    );
    (paths, rays)
}

/// One term of the greedy two-path model (thesis 6.2) from `first`: the path that starts
/// as `term` says and follows at every later interface the child with the larger Fresnel
/// coefficient, with the Fresnel factors, the base colour on entering and the absorption
/// inside multiplied along (F·G); `None` where the term does not exist (refraction-first under
/// total internal reflection) or the path is still inside after `max_depth` more interfaces.
pub fn greedy_path(
    lens: &LensObject,
    first: &LensSurface,
    dir: Vec3,
    term: Term,
    max_depth: u32,
) -> Option<LensPath> {
    lens_paths(lens, first, dir, LensModel::Greedy, max_depth)[term as usize]
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
        // A total internal reflection has no lesser branch: the tree keeps the same path as
        // its refraction-first term, and the light the short faces reflect in its others.
        let tree = lens_paths(&lens, &first, dir, LensModel::TREE, 8);
        assert_eq!(tree[1], Some(t));
        assert!(tree[2].is_some(), "a path reflected once at a short face");
    }

    #[test]
    fn paths_differ_by_topology_existence_angle_and_modulation() {
        let a = LensPath {
            exit_origin: Vec3::ZERO,
            exit_direction: Vec3::Z,
            modulation: Vec3::ONE,
            topology: Topology { interfaces: 2, reflected: 0 },
            exit: (),
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
