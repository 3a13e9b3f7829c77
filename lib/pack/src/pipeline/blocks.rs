//! The parameter space as the container stores it: the blocks' sizes and staggered
//! origins (thesis 4.7), the space, the camera table and every object's transforms.

use anyhow::{anyhow, Result};
use pis_format::*;

use super::input::LoadedSet;

fn row3x4(m: glam::Mat4) -> [f32; 12] {
    let mut out = [0.0; 12];
    for r in 0..3 {
        out[r * 4..r * 4 + 4].copy_from_slice(&m.row(r).to_array());
    }
    out
}

/// Samples per block along each dimension from `--block` (one value for all dimensions).
pub fn block_sizes(block: &[u32], dims: usize) -> Result<Vec<u32>> {
    match block.len() {
        1 => Ok(vec![block[0].max(1); dims]),
        n if n == dims => Ok(block.iter().map(|&b| b.max(1)).collect()),
        n => Err(anyhow!("--block gives {n} sizes, the parameter space has {dims} dimensions")),
    }
}

/// Block origin offsets of object `i` of `n` (thesis 4.7): `i · B / n` per dimension.
pub fn stagger(i: usize, n: usize, sizes: &[u32]) -> Vec<u32> {
    sizes.iter().map(|&b| (i as u64 * b as u64 / n.max(1) as u64) as u32).collect()
}

/// The parameter space and camera table of the container for blocks of `sizes`.
pub fn geometry(set: &LoadedSet, sizes: &[u32]) -> (ParameterSpace, CameraTable) {
    let scene = &set.scene;
    let space = ParameterSpace {
        dims: scene.space.dims.iter().zip(sizes).map(|(d, &b)| Dimension {
            name: d.name.clone(),
            kind: d.kind,
            periodic: d.periodic,
            unit: d.unit.clone(),
            block_size: b,
            values: d.values.clone(),
        }).collect(),
    };
    let view = DepMask::of(&(0..space.dims.len()).filter(|&k| space.dims[k].kind == DimensionKind::View).collect::<Vec<_>>());
    let mut cameras = vec![None; space.table_len(view) as usize];
    for (s, f) in set.samples.iter().zip(&set.frames) {
        let c = f.camera;
        cameras[space.table_index(view, s)] = Some(Camera {
            world_from_camera: row3x4(c.world_from_camera),
            yfov: c.yfov,
            znear: c.znear,
            zfar: if c.zfar.is_finite() { c.zfar } else { 1e4 },
        });
    }
    let cameras = CameraTable {
        width: set.resolution.0,
        height: set.resolution.1,
        depends_on: view,
        cameras: cameras.into_iter().map(|c| c.unwrap_or(Camera { world_from_camera: IDENTITY_3X4, yfov: 0.8, znear: 0.1, zfar: 100.0 })).collect(),
    };
    (space, cameras)
}

/// Object `o`'s transform table over the space.
pub fn transforms(set: &LoadedSet, space: &ParameterSpace, o: usize) -> TransformTable {
    let first = set.frames[0].instances[o].world_from_object;
    if set.frames.iter().all(|f| f.instances[o].world_from_object == first) {
        return TransformTable::fixed(row3x4(first));
    }
    let all = DepMask::of(&(0..space.dims.len()).collect::<Vec<_>>());
    let mut t = vec![IDENTITY_3X4; space.table_len(all) as usize];
    for (s, f) in set.samples.iter().zip(&set.frames) {
        t[space.table_index(all, s)] = row3x4(f.instances[o].world_from_object);
    }
    TransformTable { depends_on: all, transforms: t }
}

