//! The parameter space as the container stores it: the blocks' sizes and staggered
//! origins (thesis 4.7), the space, the camera table and every object's transform table
//! ([`super::transforms`]).

use anyhow::{anyhow, Result};
use glam::Vec3;
use pis_format::*;

use super::input::LoadedSet;
use super::shell_fit::mesh::bounds;
use super::transforms::{baked, row3x4, stored_transform};
use super::Stagger;

/// Samples per block along each dimension from `--block` (one value for all dimensions).
pub fn block_sizes(block: &[u32], dims: usize) -> Result<Vec<u32>> {
    match block.len() {
        1 => Ok(vec![block[0].max(1); dims]),
        n if n == dims => Ok(block.iter().map(|&b| b.max(1)).collect()),
        n => Err(anyhow!("--block gives {n} sizes, the parameter space has {dims} dimensions")),
    }
}

/// Block origin offsets of object `i` of `n` (thesis 4.7): `i · B / n` per dimension of
/// `samples` values, so that the objects' blocks end at different points of the space and
/// a player crossing a block boundary decodes one object's block, not every object's. With
/// [`Stagger::Auto`], a dimension whose samples fit in one block (`samples` ≤ B) has no
/// boundary to cross and is not staggered: there an offset would only cut the object's
/// samples into two blocks, each coding its own top level, and add a decode on the way
/// across.
pub fn stagger(i: usize, n: usize, sizes: &[u32], samples: &[usize], mode: Stagger) -> Vec<u32> {
    sizes
        .iter()
        .zip(samples)
        .map(|(&b, &k)| {
            if mode == Stagger::Auto && k <= b as usize {
                0
            } else {
                (i as u64 * b as u64 / n.max(1) as u64) as u32
            }
        })
        .collect()
}

/// The samples along each dimension of the set's parameter space ([`stagger`]'s `samples`).
pub fn samples_per_dimension(set: &LoadedSet) -> Vec<usize> {
    set.scene.space.dims.iter().map(|d| d.values.len()).collect()
}

/// The parameter space and camera table of the container for blocks of `sizes`.
pub fn geometry(set: &LoadedSet, sizes: &[u32]) -> (ParameterSpace, CameraTable) {
    let scene = &set.scene;
    let space = ParameterSpace {
        dims: scene
            .space
            .dims
            .iter()
            .zip(sizes)
            .map(|(d, &b)| Dimension {
                name: d.name.clone(),
                kind: d.kind,
                periodic: d.periodic,
                unit: d.unit.clone(),
                block_size: b,
                values: d.values.clone(),
            })
            .collect(),
    };
    let view = DepMask::of(
        &(0..space.dims.len())
            .filter(|&k| space.dims[k].kind == DimensionKind::View)
            .collect::<Vec<_>>(),
    );
    let mut cameras = vec![None; space.table_len(view) as usize];
    // Each object's bounds in object space, once: every frame places them.
    let bounds: Vec<Option<(Vec3, Vec3)>> = (set.scene.objects.iter())
        .map(|o| {
            (o.primitives.iter().filter_map(|p| bounds(&p.positions)))
                .reduce(|a, b| (a.0.min(b.0), a.1.max(b.1)))
                .filter(|(lo, hi)| lo.is_finite() && hi.is_finite())
        })
        .collect();
    for (s, f) in set.samples.iter().zip(&set.frames) {
        let c = f.camera;
        let (znear, zfar) = depth_range(&bounds, f);
        cameras[space.table_index(view, s)] = Some(Camera {
            world_from_camera: row3x4(c.world_from_camera),
            yfov: c.yfov,
            znear,
            zfar,
        });
    }
    let cameras = CameraTable {
        width: set.resolution.0,
        height: set.resolution.1,
        depends_on: view,
        cameras: cameras
            .into_iter()
            .map(|c| {
                c.unwrap_or(Camera {
                    world_from_camera: IDENTITY_3X4,
                    yfov: 0.8,
                    znear: 0.1,
                    zfar: 100.0,
                })
            })
            .collect(),
    };
    (space, cameras)
}

/// The depth range the player draws with: the camera's near plane, raised to half the
/// distance of the nearest object's bounds where that is farther (a depth buffer resolves
/// about z² / near of depth at distance z: a model in units of 10⁴ seen from 3.6 · 10⁴ with
/// glTF's usual near plane of 0.01 resolved 8000 units, and its parts fought); and its far
/// plane, or where it has none (glTF's infinite projection) 10⁴ or twice the distance of the
/// farthest object corner, whichever is larger (a model in millimetres or centimetres,
/// unscaled, lay beyond 10⁴ and drew nothing).
fn depth_range(bounds: &[Option<(Vec3, Vec3)>], frame: &pis_scene::Frame) -> (f32, f32) {
    let c = &frame.camera;
    let eye = c.world_from_camera.transform_point3(Vec3::ZERO).as_dvec3();
    let (mut near, mut far) = (f64::INFINITY, 0.0f64);
    for (&(lo, hi), instance) in
        bounds.iter().zip(&frame.instances).filter_map(|(b, i)| Some((b.as_ref()?, i)))
    {
        let m = instance.world_from_object.as_dmat4();
        let (mut wlo, mut whi) = (glam::DVec3::INFINITY, glam::DVec3::NEG_INFINITY);
        for k in 0..8 {
            let pick = glam::BVec3::new(k & 1 != 0, k & 2 != 0, k & 4 != 0);
            let world = m.transform_point3(Vec3::select(pick, hi, lo).as_dvec3());
            far = far.max(world.distance(eye));
            (wlo, whi) = (wlo.min(world), whi.max(world));
        }
        near = near.min(eye.clamp(wlo, whi).distance(eye));
    }
    let far = if c.zfar.is_finite() {
        c.zfar as f64
    } else {
        (2.0 * far).clamp(1e4, f32::MAX as f64 / 4.0)
    };
    let raised = if near.is_finite() { (0.5 * near).min(1e-3 * far) } else { 0.0 };
    (raised.max(c.znear as f64) as f32, far as f32)
}

/// Object `o`'s transform table over the space.
pub fn transforms(set: &LoadedSet, space: &ParameterSpace, o: usize) -> TransformTable {
    let bake = baked(&set.frames, o);
    let first = set.frames[0].instances[o].world_from_object;
    if set.frames.iter().all(|f| f.instances[o].world_from_object == first) {
        return TransformTable::fixed(row3x4(stored_transform(&set.frames[0], o, bake)));
    }
    let all = DepMask::of(&(0..space.dims.len()).collect::<Vec<_>>());
    let mut t = vec![IDENTITY_3X4; space.table_len(all) as usize];
    for (s, f) in set.samples.iter().zip(&set.frames) {
        t[space.table_index(all, s)] = row3x4(stored_transform(f, o, bake));
    }
    TransformTable { depends_on: all, transforms: t }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_dimensions_longer_than_a_block_are_staggered() {
        // Two dimensions of 8 and 20 samples, blocks of 8, object 3 of 6.
        assert_eq!(stagger(3, 6, &[8, 8], &[8, 20], Stagger::Auto), vec![0, 4]);
        assert_eq!(stagger(3, 6, &[8, 8], &[8, 20], Stagger::Always), vec![4, 4]);
        // Blocks of 4 over the 8 samples: two blocks to cross, so staggered.
        assert_eq!(stagger(3, 6, &[4, 8], &[8, 20], Stagger::Auto), vec![2, 4]);
        // The first object is never offset.
        assert_eq!(stagger(0, 6, &[8, 8], &[9, 20], Stagger::Always), vec![0, 0]);
    }
}
