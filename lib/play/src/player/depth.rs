//! Depth shells' depth cubes (SPEC.md 8.5): cast once per shell block when a file is
//! opened, from the file's meshes, and kept on the GPU beside the object.

use std::collections::HashMap;

use glam::Vec3;
use pis_compile::shell::depth::{MAX_SIZE, MAX_STEPS};
use pis_compile::shell::{DepthCube, Shell};
use pis_format::{Container, Placement, ShellShape};

use crate::camera::mat4_from_rows;
use crate::gpu::Gpu;
use crate::shell::DepthTexture;

/// An object's depth shells by (layer, block): the shell, its depth cube within, and the
/// cube on the GPU.
pub(super) type DepthShells = HashMap<(usize, u32), (Shell, DepthTexture)>;

/// The triangles object `own`'s depth cubes are cast from (SPEC.md 8.5): every other
/// object's, in world space, each placed by the first entry of its transform table.
pub fn scene_triangles<S>(c: &Container<S>, own: usize) -> Vec<[Vec3; 3]> {
    let mut out = Vec::new();
    for (oi, o) in c.objects.iter().enumerate() {
        let Some(t) = o.transforms.transforms.first() else { continue };
        if oi == own {
            continue;
        }
        let m = mat4_from_rows(t);
        let world: Vec<Vec3> =
            o.mesh.positions.iter().map(|&p| m.transform_point3(Vec3::from(p))).collect();
        out.extend(o.mesh.indices.chunks_exact(3).filter_map(|tri| {
            let v = |i: u32| world.get(i as usize).copied();
            Some([v(tri[0])?, v(tri[1])?, v(tri[2])?])
        }));
    }
    out
}

/// Checks a step count that replaces the files' ([`super::PlayerOptions::depth_steps`]).
pub fn check_steps(steps: Option<u32>) -> Result<(), String> {
    match steps {
        Some(s) if !(1..=MAX_STEPS).contains(&s) => {
            Err(format!("depth shells' march steps {s}: expected 1 to {MAX_STEPS}"))
        }
        _ => Ok(()),
    }
}

/// The depth shell of a shell block's placement, its depth cube cast from `triangles`,
/// marched in `steps` steps or the placement's; `None` for another shape or parameters out
/// of SPEC.md 7.3's ranges (rule 6007: the file's validation names them).
pub fn depth_shell(
    placement: &Placement,
    triangles: &[[Vec3; 3]],
    steps: Option<u32>,
) -> Option<Shell> {
    let Placement::Shell { shape: ShellShape::Depth, origin, params, .. } = placement else {
        return None;
    };
    let whole = |v: f32, max: u32| v.fract() == 0.0 && v >= 1.0 && v <= max as f32;
    let (n, file_steps, far) = (params[0], params[1], params[2]);
    if !(whole(n, MAX_SIZE) && whole(file_steps, MAX_STEPS) && far > 0.0 && far.is_finite()) {
        return None;
    }
    let origin = Vec3::from(*origin);
    if !origin.is_finite() {
        return None;
    }
    let cube = DepthCube::cast(origin, n as u32, far, triangles);
    Some(Shell::depth(origin.as_dvec3(), cube, steps.unwrap_or(file_steps as u32)))
}

/// Object `oi`'s depth shells, cast and uploaded, marched in `steps` steps or their files'.
pub(super) fn object_depth_shells<S>(
    gpu: &Gpu,
    c: &Container<S>,
    oi: usize,
    steps: Option<u32>,
) -> DepthShells {
    let mut out = DepthShells::new();
    let mut triangles = None;
    for (li, layer) in c.objects[oi].layers.iter().enumerate() {
        for (b, block) in layer.blocks.iter().enumerate() {
            if !matches!(block.placement, Placement::Shell { shape: ShellShape::Depth, .. }) {
                continue;
            }
            let tris = triangles.get_or_insert_with(|| scene_triangles(c, oi));
            if let Some(shell) = depth_shell(&block.placement, tris, steps) {
                let texture = DepthTexture::new(gpu, &shell);
                out.insert((li, b as u32), (shell, texture));
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_step_count_out_of_the_specs_range_is_refused() {
        assert!(check_steps(None).is_ok() && check_steps(Some(1)).is_ok());
        assert!(check_steps(Some(MAX_STEPS)).is_ok());
        for bad in [0, MAX_STEPS + 1] {
            let e = check_steps(Some(bad)).unwrap_err();
            assert!(e.contains(&format!("steps {bad}: expected 1 to {MAX_STEPS}")), "{e}");
        }
    }
}
