//! The paths of light through a lens object (thesis 6.2, 7.3), walked once for the tracer
//! (pis-trace's lens terms) and the runtime model (pis-compile's vertex paths): the two differ
//! only in how they find the next interface, which they pass in as a closure, so both follow
//! a ray through the object with the same operations in the same order, bit for bit.
//!
//! Two models:
//! - **greedy** (thesis 6.2): a reflection-first and a refraction-first path, each following at
//!   every later interface the child with the larger Fresnel coefficient;
//! - **tree** (thesis 7.3's full ray tree): at every interface both children are followed while
//!   the path's weight (the largest channel of its F·G) stays at or above `min_weight` and its
//!   depth within the cap. The exit rays are grouped into terms by how often the path took the
//!   lesser branch after the first interface (the one the greedy model drops: the reflection
//!   where F < ½ and the ray can refract, else the refraction): term 0 holds the
//!   reflection-first paths that never did (the greedy reflection-first path), term 1 + k the
//!   refraction-first paths that did k times (term 1 is the greedy refraction-first path; a
//!   sphere's TT, TRT, TRRT are terms 1, 2, 3, and a total internal reflection, having no
//!   lesser branch, does not count). Within a term the heaviest path stands for it (its exit
//!   direction is the one the player looks up); the lighter ones are dropped. The greedy
//!   model is the tree cut to its first two terms, with no least weight.

use crate::optics::{fresnel_dielectric, offset_origin, reflect, refract};
use glam::Vec3;

/// The most terms a lens model has: reflection-first and three refraction-first classes.
pub const MAX_TERMS: usize = 4;

/// How the paths through a lens object are followed and grouped into terms.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LensModel {
    #[default]
    /// Thesis 6.2: two paths, each following the larger Fresnel branch.
    Greedy,
    /// The ray tree: both branches while the weight stays at or above `min_weight`; terms
    /// reflection-first and refraction-first having taken the lesser branch 0 …
    /// `internal_terms` − 1 times.
    Tree { min_weight: f32, internal_terms: u8 },
}

impl LensModel {
    /// The tree at its defaults: paths down to 1 % of the light, four terms (a sphere's R,
    /// TT, TRT and TRRT).
    pub const TREE: LensModel = LensModel::Tree { min_weight: 0.01, internal_terms: 3 };

    /// How many terms the model fills: 2 for the greedy model.
    pub fn terms(self) -> usize {
        match self {
            LensModel::Greedy => 2,
            LensModel::Tree { internal_terms, .. } => {
                1 + (internal_terms as usize).min(MAX_TERMS - 1)
            }
        }
    }

    /// The least weight a path keeps (0 for the greedy model).
    pub fn min_weight(self) -> f32 {
        match self {
            LensModel::Greedy => 0.0,
            LensModel::Tree { min_weight, .. } => min_weight,
        }
    }

    /// Whether this is the greedy model (which set.json leaves unrecorded).
    pub fn is_greedy(&self) -> bool {
        *self == LensModel::Greedy
    }
}

/// A path's topology (thesis 6.4.1): how many interfaces it met and, at each, whether it
/// reflected. Two paths with different topologies are different whatever their directions.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Topology {
    pub interfaces: u8,
    /// Bit i: the path reflected at interface i (the first is the vertex itself).
    pub reflected: u32,
}

impl Topology {
    fn then(self, reflected: bool) -> Topology {
        let mut t = self;
        if reflected && t.interfaces < 32 {
            t.reflected |= 1 << t.interfaces;
        }
        t.interfaces = t.interfaces.saturating_add(1);
        t
    }
}

/// One interface of the lens object met along a path.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LensInterface {
    pub position: Vec3,
    /// Unit shading normal on the side the ray comes from.
    pub normal: Vec3,
    pub geometric_normal: Vec3,
    /// Whether the ray meets the surface from outside (entering).
    pub front_face: bool,
    pub ior: f32,
    /// Base colour, multiplied in on entering.
    pub base: Vec3,
    /// The absorption along the segment that reached this interface (1 outside the object).
    pub absorption: Vec3,
}

/// What the next segment of a path meets: the lens object again, or something else (or
/// nothing), where the path leaves it; `H` is what the caller keeps of that exit (the tracer,
/// the hit it found; the runtime model, nothing).
pub enum Step<H> {
    Interface(LensInterface),
    Exit(H),
}

/// Where a path leaves the lens object.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LensPath<H> {
    /// The outgoing ray: its origin (offset off the last interface) and unit direction.
    pub exit_origin: Vec3,
    pub exit_direction: Vec3,
    /// F·G: the Fresnel coefficients, base colour on entering and absorption along the path.
    pub modulation: Vec3,
    pub topology: Topology,
    /// What the caller's `next` returned at the exit.
    pub exit: H,
}

/// A path not yet out of the object.
#[derive(Clone, Copy)]
struct Branch {
    position: Vec3,
    geometric_normal: Vec3,
    direction: Vec3,
    modulation: Vec3,
    topology: Topology,
    /// How often the path took the lesser branch after the first interface.
    lesser: u32,
    depth: u32,
}

impl Branch {
    /// The term of the paths under this branch (`usize::MAX` for none: a reflection-first
    /// path that took a lesser branch).
    fn term(&self) -> usize {
        match (self.topology.reflected & 1 == 1, self.lesser) {
            (true, 0) => 0,
            (true, _) => usize::MAX,
            (false, k) => 1 + k as usize,
        }
    }
}

/// A child of a path at an interface: its direction, the factor it multiplies into F·G,
/// whether it reflected, and whether it is the lesser branch.
type Child = (Vec3, Vec3, bool, bool);

/// The children of a path at interface `s` met along `d`, the greater first: refraction when
/// F < ½ and the ray can refract (thesis 6.2's greedy choice), else reflection.
fn children(s: &LensInterface, d: Vec3) -> [Option<Child>; 2] {
    let eta = if s.front_face { 1.0 / s.ior } else { s.ior };
    let f = fresnel_dielectric(-d.dot(s.normal), eta);
    let tint = if s.front_face { s.base } else { Vec3::ONE };
    let r = |lesser| (reflect(d, s.normal), Vec3::splat(f), true, lesser);
    let refracted = refract(d, s.normal, eta);
    match refracted {
        Some(t) if f < 0.5 => [Some((t, (1.0 - f) * tint, false, false)), Some(r(true))],
        Some(t) => [Some(r(false)), Some((t, (1.0 - f) * tint, false, true))],
        None => [Some(r(false)), None],
    }
}

/// The terms of `model` for a ray of direction `dir` (unit) meeting the lens object at
/// `first`: `[term 0, term 1, …]`, `None` where a term has no path (refraction-first under
/// total internal reflection, a path still inside after `max_depth` more interfaces, a tree
/// term whose paths were all pruned). `next(origin, direction)` finds what the segment meets.
pub fn lens_paths<H>(
    first: &LensInterface,
    dir: Vec3,
    model: LensModel,
    max_depth: u32,
    mut next: impl FnMut(Vec3, Vec3) -> Step<H>,
) -> [Option<LensPath<H>>; MAX_TERMS] {
    let mut terms: [Option<LensPath<H>>; MAX_TERMS] = std::array::from_fn(|_| None);
    let min_weight = model.min_weight();
    let root = Branch {
        position: first.position,
        geometric_normal: first.geometric_normal,
        direction: dir,
        modulation: Vec3::ONE,
        topology: Topology::default(),
        lesser: 0,
        depth: 0,
    };
    let mut stack = Stack::default();
    // The first interface: both children, neither the lesser, whatever the model (thesis
    // 6.2's two terms).
    for (d, factor, reflected, _) in children(first, dir).into_iter().flatten() {
        stack.push(root.child((d, factor, reflected, false)));
    }
    let terms_kept = model.terms();
    let max_depth = max_depth.min(MAX_DEPTH);
    while let Some(b) = stack.pop() {
        let term = b.term();
        if term >= terms_kept || b.modulation.max_element() < min_weight || b.depth > max_depth {
            continue;
        }
        let o = offset_origin(b.position, b.geometric_normal, b.direction);
        match next(o, b.direction) {
            Step::Exit(exit) => {
                let heavier = terms[term]
                    .as_ref()
                    .is_none_or(|p| b.modulation.max_element() > p.modulation.max_element());
                if heavier {
                    terms[term] = Some(LensPath {
                        exit_origin: o,
                        exit_direction: b.direction,
                        modulation: b.modulation,
                        topology: b.topology,
                        exit,
                    });
                }
            }
            Step::Interface(s) => {
                let at = Branch {
                    position: s.position,
                    geometric_normal: s.geometric_normal,
                    modulation: b.modulation * s.absorption,
                    ..b
                };
                // The greater branch pushed last, so walked first (ties keep the first found).
                for c in children(&s, b.direction).into_iter().flatten().rev() {
                    stack.push(at.child(c));
                }
            }
        }
    }
    terms
}

/// The deepest path [`lens_paths`] follows: its depth-first stack then never holds more than
/// one waiting sibling per level.
pub const MAX_DEPTH: u32 = 62;

/// The depth-first stack of waiting branches, on the stack frame (no allocation per ray).
struct Stack {
    branches: [Branch; MAX_DEPTH as usize + 2],
    len: usize,
}

impl Default for Stack {
    fn default() -> Stack {
        let empty = Branch {
            position: Vec3::ZERO,
            geometric_normal: Vec3::ZERO,
            direction: Vec3::ZERO,
            modulation: Vec3::ZERO,
            topology: Topology::default(),
            lesser: 0,
            depth: 0,
        };
        Stack { branches: [empty; MAX_DEPTH as usize + 2], len: 0 }
    }
}

impl Stack {
    fn push(&mut self, b: Branch) {
        self.branches[self.len] = b;
        self.len += 1;
    }

    fn pop(&mut self) -> Option<Branch> {
        self.len = self.len.checked_sub(1)?;
        Some(self.branches[self.len])
    }
}

impl Branch {
    fn child(&self, (direction, factor, reflected, lesser): Child) -> Branch {
        Branch {
            direction,
            modulation: self.modulation * factor,
            topology: self.topology.then(reflected),
            lesser: self.lesser + lesser as u32,
            depth: self.depth + 1,
            ..*self
        }
    }
}

#[cfg(test)]
mod tests;
