//! Geometric fitting of the environment-map shells of a reflective object (thesis 5.4,
//! 5.7).
//!
//! A reflective object's incident specular light is stored as layered environment maps: a
//! local shell for the parts of the object seen in its own reflections and a distant shell
//! for the rest of the scene, composited "over". Each shell is a simple geometry that
//! reflection rays are intersected with; the hit point less the object's environment-map
//! origin indexes a cube map. This module fits that geometry:
//!
//! - [`origin`]: the environment-map origin, the area-weighted average of the triangle
//!   centroids (5.4);
//! - [`bounding_ellipsoid`]: the local shell, the least-volume axis-aligned ellipsoid
//!   bounding the object (5.7);
//! - [`hit_points`]: where reflected view rays meet the environment, over the cameras;
//! - [`distant_box`], [`distant_sphere`]: the distant shell at the average distance of
//!   those hits, the box's bottom on the [`support_plane`] the object rests on (5.4);
//! - [`convex_hull_triangles`]: the triangles on the object's convex hull, which can never
//!   reflect the object and use the distant shell only (5.7).
//!
//! Everything is deterministic: parallel work is collected in order, and sums run in a
//! fixed order.

pub mod distant;
pub mod ellipsoid;
pub mod hits;
pub mod hull;
pub mod mesh;
pub mod origin;
pub mod point_tree;
pub mod support;
#[cfg(test)]
mod test_meshes;

pub use distant::{distant_box, distant_sphere, BoxShell, SphereShell};
pub use ellipsoid::{bounding_ellipsoid, Ellipsoid};
pub use hits::{hit_points, surface_samples, SurfaceSample};
pub use hull::convex_hull_triangles;
pub use origin::origin;
pub use support::support_plane;
