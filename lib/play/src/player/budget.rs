//! The memory a frame of the file needs, checked at open against the player's cache budget
//! and the adapter's largest buffer, so that a file whose textures the player cannot hold is
//! refused before anything is decoded or allocated ([`crate::memory`]).

use pis_compile::TextureLayout;
use pis_format::{Container, Mapping, StreamRef};

use super::options::PlayerOptions;
use crate::cube_atlas::CubeAtlas;
use crate::error::PlayError;
use crate::gpu::Gpu;
use crate::memory::{blocks, size, BlockBytes};

/// The bytes of the largest single upload of a block's texture: its finest level (a surface
/// texture at its allocated power-of-two size in the device's texture format; one face's
/// atlas image of a shell's cube map in the device's cube-map format).
fn upload_bytes(gpu: &Gpu, b: &BlockBytes) -> u64 {
    let texel = |format: wgpu::TextureFormat| format.block_copy_size(None).unwrap_or(16) as u64;
    match b.mapping {
        Mapping::Surface => {
            let (w, h) = (b.width.next_power_of_two() as u64, b.height.next_power_of_two());
            w * h as u64 * texel(gpu.texture_format)
        }
        Mapping::Shell => {
            let atlas = CubeAtlas::of(&TextureLayout::cube(b.width));
            atlas.face_texels() as u64 * texel(gpu.cube_format)
        }
    }
}

/// Refuses (not supported) a file one frame of which would decode more level images than
/// the cache budget holds, or upload a texture level larger than the adapter's largest
/// buffer. A frame draws every object's layers at one parameter sample at least: per layer,
/// the level images on one pyramid path of its largest block.
pub(super) fn check_frame_memory(
    gpu: &Gpu,
    c: &Container<StreamRef>,
    options: &PlayerOptions,
) -> Result<(), PlayError> {
    let budget = options.cache_budget_bytes;
    let buffer = gpu.limits.max_buffer_size;
    let mut per_layer: Vec<&BlockBytes> = Vec::new();
    let all = blocks(c);
    for b in &all {
        let upload = upload_bytes(gpu, b);
        if upload > buffer {
            return Err(PlayError::Memory(format!(
                "{}: uploading its finest level takes {} ({} bytes), more than the adapter's largest buffer, {} ({buffer} bytes)",
                b.name,
                size(upload),
                upload,
                size(buffer)
            )));
        }
        if b.path() > budget {
            return Err(PlayError::Memory(format!(
                "{}: one texture decodes from {} of level images ({} level(s) of {} each), more than the player's cache budget for decoded level images, {} (pis-play --cache-mb)",
                b.name,
                size(b.path()),
                b.levels,
                size(b.image),
                size(budget)
            )));
        }
        match per_layer.last_mut() {
            Some(last) if (last.object, last.layer) == (b.object, b.layer) => {
                if b.path() > last.path() {
                    *last = b;
                }
            }
            _ => per_layer.push(b),
        }
    }
    let frame: u64 = per_layer.iter().map(|b| b.path()).fold(0, u64::saturating_add);
    if frame > budget {
        // The first of the largest.
        let largest =
            per_layer.iter().fold(per_layer[0], |m, b| if b.path() > m.path() { b } else { m });
        return Err(PlayError::Memory(format!(
            "one frame decodes {} of level images ({} layers; the largest, {}, {}), more than the player's cache budget for decoded level images, {} (pis-play --cache-mb)",
            size(frame),
            per_layer.len(),
            largest.name,
            size(largest.path()),
            size(budget)
        )));
    }
    Ok(())
}
