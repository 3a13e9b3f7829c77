//! The draws of a frame from its plan and its textures on the GPU: the objects placed, the
//! surface layers with their samplers and largest LOD, and the reflection terms with their
//! cube maps.

use std::collections::HashMap;

use pis_compile::{Address, Filter, Sampler};
use pis_format::PisReader;

use super::objects::{content, ObjectGpu};
use super::plan::{Plan, Wanted};
use super::relit::{RelitTextures, SurfaceItem};
use super::resident::{GpuTexture, Textures};
use crate::error::PlayError;
use crate::frame::{LayerDraw, ObjectDraw, ReflectionDraw, TermShell};
use crate::gpu::Gpu;
use crate::textured::create_sampler;

/// The player's samplers, one per filter and repeat mode (s, t).
pub(super) type Samplers = HashMap<(Filter, [bool; 2]), wgpu::Sampler>;

/// The filter of object `o` (`filters`: per object; trilinear past the end).
fn filter_of(filters: &[Filter], o: u32) -> Filter {
    filters.get(o as usize).copied().unwrap_or(Filter::Trilinear)
}

/// Every object at its clip transform (`clips`, one per object).
pub(super) fn object_draws<'a>(
    objects: &'a [ObjectGpu],
    clips: &[glam::Mat4],
) -> Vec<ObjectDraw<'a>> {
    objects
        .iter()
        .zip(clips)
        .enumerate()
        .map(|(i, (o, &clip))| ObjectDraw {
            object: i as u32,
            mesh: &o.mesh,
            clip_from_object: clip,
            translucent: o.translucent,
        })
        .collect()
}

/// The addressing of a texture repeated (or not) along s and t.
fn address(repeat: [bool; 2]) -> [Address; 2] {
    repeat.map(|r| if r { Address::Repeat } else { Address::ClampToEdge })
}

/// Makes the samplers `surfaces` need that `samplers` lacks: each surface's object's filter
/// (`filters`, per object) and repeat mode.
pub(super) fn make_samplers(
    gpu: &Gpu,
    samplers: &mut Samplers,
    filters: &[Filter],
    surfaces: &[Wanted],
) {
    for w in surfaces {
        let filter = filter_of(filters, w.key.object);
        samplers.entry((filter, w.repeat)).or_insert_with(|| {
            create_sampler(gpu, &Sampler { filter, address: address(w.repeat) })
        });
    }
}

/// The surface layers `items` of `surfaces` with their textures on the GPU (`textures`, or
/// a relightable layer's sum in `relit`) and their samplers (`samplers`, made by
/// [`make_samplers`]), each filtered with its object's filter (`filters`). A repeated axis
/// must be a power of two.
pub(super) fn layer_draws<'a>(
    reader: &PisReader,
    (textures, relit): (&'a Textures, &'a RelitTextures),
    samplers: &'a Samplers,
    filters: &[Filter],
    (surfaces, items): (&[Wanted], &[SurfaceItem]),
) -> Result<Vec<LayerDraw<'a>>, PlayError> {
    let mut layers = Vec::with_capacity(items.len());
    for item in items {
        let w = &surfaces[item.surface];
        let (texture, tint) = match &item.sum {
            Some(key) => (relit.get(key), [1.0; 3]),
            None => match textures.get(&w.key) {
                GpuTexture::Surface(texture) => (texture, w.tint),
                GpuTexture::Shell(_) => {
                    return Err(content(
                        reader,
                        format!("{:?}: a shell's texture drawn as a surface layer", w.key),
                    ))
                }
            },
        };
        let filter = filter_of(filters, w.key.object);
        let sampler = Sampler { filter, address: address(w.repeat) };
        for (axis, k, s) in [('s', 0, texture.layout.width), ('t', 1, texture.layout.height)] {
            if w.repeat[k] && !s.is_power_of_two() {
                return Err(PlayError::RepeatSize { axis, size: s });
            }
        }
        layers.push(LayerDraw {
            draw: w.draw,
            texture,
            sampler: &samplers[&(filter, w.repeat)],
            transform: w.transform,
            max_level: pis_compile::filter::max_level(&texture.layout, &sampler) as f32,
            weight: w.weight,
            tint,
            anisotropic: matches!(filter, Filter::Anisotropic(_)),
            opacity: reader
                .container()
                .objects
                .get(w.key.object as usize)
                .and_then(|o| o.layers.get(w.key.layer as usize))
                .is_some_and(|l| l.channels == 4),
        });
    }
    Ok(layers)
}

/// The reflection terms of a plan, with their cube maps on the GPU (`textures`).
pub(super) fn reflection_draws<'a>(
    reader: &PisReader,
    (textures, objects): (&'a Textures, &'a [ObjectGpu]),
    plan: &Plan,
) -> Result<Vec<ReflectionDraw<'a>>, PlayError> {
    let c = reader.container();
    let mut out = Vec::with_capacity(plan.reflections.len());
    for r in &plan.reflections {
        let mut shells = Vec::with_capacity(r.shells.len());
        for (key, shell, lookups) in &r.shells {
            let GpuTexture::Shell(cube) = textures.get(key) else {
                return Err(content(
                    reader,
                    format!("{key:?}: a surface texture drawn as a shell"),
                ));
            };
            let depth = objects[r.draw].depth.get(&(key.layer as usize, key.block)).map(|d| &d.1);
            shells.push(TermShell { shell: shell.clone(), lookups: *lookups, cube, depth });
        }
        out.push(ReflectionDraw {
            draw: r.draw,
            world_from_object: plan.worlds[r.draw],
            eye: plan.eye,
            f0: c.objects[r.draw].shading.f0,
            weight: r.weight,
            shells,
        });
    }
    Ok(out)
}
