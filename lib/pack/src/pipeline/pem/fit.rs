//! An object's shells (thesis 5.4, 5.7): the environment-map origin, the local shell — the
//! least-volume axis-aligned ellipsoid about the origin that bounds the object — and the
//! candidates for the distant shell: a box with its bottom on the surface the object rests
//! on and its sides at the mean distance of the reflected environment, a sphere at that
//! mean distance, and a depth shell whose radius in every direction is the distance to the
//! scene's diffuse objects (SPEC.md 8.5). Fitted where the object stands at the set's first
//! point.

use anyhow::{anyhow, Result};
use glam::{DVec3, Vec3};
use pis_compile::shell::{DepthCube, Shell, ShellShape};
use pis_trace::bvh::SceneGeometry;

use super::super::input::LoadedSet;
use super::super::mesh::Mesh;
use super::super::shell_fit::{
    bounding_ellipsoid, distant_box, distant_sphere, hit_points, origin, support_plane,
};

/// Cameras whose reflections size the distant shell: at most this many, evenly spread over
/// the set's points.
pub const MAX_EYES: usize = 16;

/// Face size of a depth shell's depth cube.
pub const DEPTH_CUBE_SIZE: u32 = 64;

/// March steps of a depth shell's lookups.
pub const DEPTH_STEPS: u32 = 32;

/// A depth shell's far sphere is at most this many times the mean distance of the
/// reflected environment (a scene's ground plane would otherwise spread the steps thin).
pub const DEPTH_FAR_SPREAD: f32 = 8.0;

/// The fitted shells of one object.
#[derive(Clone, Debug)]
pub struct FittedShells {
    /// The local shell: an ellipsoid about the origin.
    pub local: Shell,
    /// The distant shell candidates: a box and a sphere about the origin.
    pub distant_box: Shell,
    pub distant_sphere: Shell,
    /// The depth shell, where one was asked for and the scene has other objects to cast its
    /// depth cube from.
    pub distant_depth: Option<Shell>,
    /// Whether the box's bottom lies on a supporting surface.
    pub supported: bool,
}

/// The world-space vertices of object `o` at point `p`.
fn world_positions(set: &LoadedSet, p: usize, o: usize, mesh: &Mesh) -> Vec<Vec3> {
    let m = set.frames[p].instances[o].world_from_object;
    mesh.positions.iter().map(|&q| m.transform_point3(Vec3::from(q))).collect()
}

/// Fits the shells of object `o` (mesh `meshes[o]`) where it stands at the set's first point,
/// the depth shell only `with_depth`.
pub fn fit_shells(
    set: &LoadedSet,
    o: usize,
    meshes: &[Mesh],
    with_depth: bool,
) -> Result<FittedShells> {
    let name = &set.scene.objects[o].name;
    let mesh = &meshes[o];
    let world = world_positions(set, 0, o, mesh);
    let centre = origin(&world, &mesh.indices)?;
    let ellipsoid = bounding_ellipsoid(&world, centre);
    let geometry = SceneGeometry::build(&set.scene, &set.frames[0]);
    let cast = |from: Vec3, dir: Vec3| {
        geometry.closest(from, dir, f32::INFINITY, Some(o as u32)).map(|h| h.t)
    };
    let support = support_plane(&world, cast);
    let step = set.frames.len().div_ceil(MAX_EYES).max(1);
    let eyes: Vec<Vec3> = set
        .frames
        .iter()
        .step_by(step)
        .map(|f| f.camera.world_from_camera.w_axis.truncate())
        .collect();
    let hits = hit_points(&world, &mesh.indices, &eyes, cast)?;
    if hits.is_empty() && support.is_none() {
        return Err(anyhow!(
            "object {name}: no reflection ray meets the scene, so no distant shell can be placed"
        ));
    }
    let b = distant_box(centre, support, &hits)?;
    let s = if hits.is_empty() { None } else { Some(distant_sphere(centre, &hits)?) };
    let o3 = centre.as_dvec3();
    let box_shell = Shell {
        origin: o3,
        shape: ShellShape::Box { min: b.min.as_dvec3(), max: b.max.as_dvec3() },
    };
    let radius = s.map_or_else(|| (b.max - b.min).length() as f64 * 0.5, |s| s.radius as f64);
    Ok(FittedShells {
        local: Shell {
            origin: o3,
            shape: ShellShape::Ellipsoid { radii: ellipsoid.radii.as_dvec3() },
        },
        distant_box: box_shell,
        distant_sphere: Shell { origin: o3, shape: ShellShape::Sphere { radius } },
        distant_depth: with_depth
            .then(|| depth_shell(set, meshes, o, centre, radius as f32))
            .flatten(),
        supported: support.is_some(),
    })
}

/// The depth shell about `centre`: its depth cube cast from the other objects' triangles
/// at the set's first point, as a reader casts it from the file (SPEC.md 8.5); the far
/// sphere just beyond the farthest of their vertices, at most [`DEPTH_FAR_SPREAD`] times
/// `mean` (the mean distance of the reflected or refracted environment). `None` without
/// other objects.
pub fn depth_shell(
    set: &LoadedSet,
    meshes: &[Mesh],
    o: usize,
    centre: Vec3,
    mean: f32,
) -> Option<Shell> {
    let mut triangles = Vec::new();
    for (k, mesh) in meshes.iter().enumerate() {
        if k == o {
            continue;
        }
        let world = world_positions(set, 0, k, mesh);
        triangles.extend(mesh.indices.chunks_exact(3).filter_map(|t| {
            let v = |i: u32| world.get(i as usize).copied();
            Some([v(t[0])?, v(t[1])?, v(t[2])?])
        }));
    }
    let farthest = triangles.iter().flatten().map(|v| v.distance(centre)).fold(0.0f32, f32::max);
    let far = (farthest * 1.01).min(DEPTH_FAR_SPREAD * mean);
    if triangles.is_empty() || !(far > 0.0 && far.is_finite()) {
        return None;
    }
    let cube = DepthCube::cast(centre, DEPTH_CUBE_SIZE, far, &triangles);
    Some(Shell::depth(centre.as_dvec3(), cube, DEPTH_STEPS))
}

/// Whether `shell` is a depth shell (SPEC.md 8.5).
pub fn is_depth(shell: &Shell) -> bool {
    matches!(shell.shape, ShellShape::Depth { .. })
}

/// A sphere so large that looking it up is looking up the reflection direction: the one
/// "sphere at infinity" shell of a static or single-shell environment map (thesis 5.10).
pub fn sphere_at_infinity(origin: DVec3) -> Shell {
    Shell { origin, shape: ShellShape::Sphere { radius: 1.0e6 } }
}
