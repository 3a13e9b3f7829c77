//! Recording a frame: the bind groups of its draws, the object-index pass (per sample, and
//! at pixel centres where asked for), the additive pass of surface layers, reflection terms
//! and lens terms, and the display-filter resolve of multisampled frames.

use bytemuck::{Pod, Zeroable};
use wgpu::util::DeviceExt;

use super::draw::{LayerDraw, ObjectDraw, NO_OBJECT};
use super::hybrid::{lens_bind, LensDraw};
use super::pipelines::FramePipelines;
use super::reflection::{reflection_bind, ReflectionDraw};
use super::resolve::SHARED_ID_FORMAT;
use super::targets::{offscreen_format, target_texture, Targets};
use crate::gpu::Gpu;
use crate::textured::{allocated_size, cut_uniform};

/// `Uniforms` of `frame.wgsl` (144 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct Uniforms {
    clip_from_object: [f32; 16],
    affine_abcd: [f32; 4],
    affine_ef: [f32; 2],
    size: [f32; 2],
    scale: [f32; 2],
    max_level: f32,
    weight: f32,
    object: u32,
    anisotropic: u32,
    _pad: [u32; 2],
    cut: [f32; 4],
}

fn uniforms(clip_from_object: glam::Mat4, object: u32, layer: Option<&LayerDraw>) -> Uniforms {
    let mut u = Uniforms {
        clip_from_object: clip_from_object.to_cols_array(),
        affine_abcd: [1.0, 0.0, 0.0, 1.0],
        affine_ef: [0.0; 2],
        size: [1.0; 2],
        scale: [1.0; 2],
        max_level: 0.0,
        weight: 0.0,
        object,
        anisotropic: 0,
        _pad: [0; 2],
        cut: [0.0; 4],
    };
    if let Some(l) = layer {
        let [a, b, c, d, e, f] = l.transform.values;
        let layout = l.texture.layout;
        let (aw, ah) = allocated_size(&layout);
        u.affine_abcd = [a, b, c, d];
        u.affine_ef = [e, f];
        u.size = [layout.width as f32, layout.height as f32];
        u.scale = [layout.width as f32 / aw as f32, layout.height as f32 / ah as f32];
        u.max_level = l.max_level;
        u.weight = l.weight;
        u.anisotropic = l.anisotropic as u32;
        u.cut = cut_uniform(&l.transform);
    }
    u
}

/// The object-index pass: clears `ids` and `depth`, then draws every object's index and
/// depth, nearest surface winning.
fn id_pass(
    pipeline: &wgpu::RenderPipeline,
    ids: &wgpu::Texture,
    depth: &wgpu::Texture,
    objects: &[ObjectDraw],
    binds: &[wgpu::BindGroup],
    encoder: &mut wgpu::CommandEncoder,
) {
    let ids_view = ids.create_view(&Default::default());
    let depth_view = depth.create_view(&Default::default());
    let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("object ids"),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view: &ids_view,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load: wgpu::LoadOp::Clear(wgpu::Color {
                    r: NO_OBJECT as f64,
                    g: 0.0,
                    b: 0.0,
                    a: 0.0,
                }),
                store: wgpu::StoreOp::Store,
            },
        })],
        depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
            view: &depth_view,
            depth_ops: Some(wgpu::Operations {
                load: wgpu::LoadOp::Clear(1.0),
                store: wgpu::StoreOp::Store,
            }),
            stencil_ops: None,
        }),
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    });
    pass.set_pipeline(pipeline);
    for (o, bg) in objects.iter().zip(binds) {
        pass.set_bind_group(0, bg, &[]);
        pass.set_vertex_buffer(0, o.mesh.positions.slice(..));
        pass.set_vertex_buffer(1, o.mesh.uvs.slice(..));
        pass.set_index_buffer(o.mesh.indices.slice(..), wgpu::IndexFormat::Uint32);
        pass.draw_indexed(0..o.mesh.count, 0, 0..1);
    }
}

/// What a frame draws: its objects, the surface layers drawn on them, and their reflection
/// and lens terms (a term without shells, or a lens term without corners, draws nothing).
pub struct FrameDraws<'d, 'a> {
    pub objects: &'d [ObjectDraw<'a>],
    pub layers: &'d [LayerDraw<'a>],
    pub reflections: &'d [ReflectionDraw<'a>],
    pub lenses: &'d [LensDraw<'a>],
}

/// Where a frame is drawn: `colour`, of format `format` and size `targets.size`; with
/// `object_ids`, every pixel's object index at its centre is also left in `targets.ids`
/// (single-sample frames always do; multisampled ones draw one more index pass for it);
/// `display`: the ray-traced set's display filter multisampled frames are resolved with.
pub struct FrameTarget<'v> {
    pub colour: &'v wgpu::TextureView,
    pub format: wgpu::TextureFormat,
    pub object_ids: bool,
    pub display: Option<pis_format::DisplayFilter>,
}

/// Records a frame into `encoder`: clears `target.colour` to transparent black, then draws
/// with `targets.samples` per pixel (multisampled frames are drawn into the sample
/// attachments and resolved into the colour target: with a display filter by the
/// display-filter resolve over each pixel's 3×3 neighbourhood, the samples drawn in the
/// offscreen format; without, by the hardware's average of each pixel's own samples).
/// Single-sample frames ignore the display filter. The additive pass draws the layers, then
/// the reflection terms, then the lens terms.
pub fn encode(
    gpu: &Gpu,
    pipes: &mut FramePipelines,
    targets: &mut Targets,
    target: FrameTarget,
    frame: FrameDraws,
    encoder: &mut wgpu::CommandEncoder,
) {
    let FrameTarget { colour, format, object_ids, display } = target;
    let samples = targets.samples;
    // The display filter applies to multisampled frames; their samples are then drawn in
    // the offscreen (float) format, whatever the target's.
    let display = display.filter(|_| samples > 1);
    let sample_format = if display.is_some() { offscreen_format(gpu) } else { format };
    let draws = Draws {
        objects: frame.objects,
        layers: frame.layers,
        reflections: frame.reflections.iter().filter(|r| !r.shells.is_empty()).collect(),
        lenses: frame.lenses.iter().filter(|l| !l.shells.is_empty() && l.count > 0).collect(),
    };
    pipes.id_pipeline(gpu, samples);
    pipes.layer_pipeline(gpu, sample_format, samples);
    if !draws.reflections.is_empty() {
        pipes.reflection_pipeline(gpu, sample_format, samples);
    }
    if !draws.lenses.is_empty() {
        pipes.hybrid_pipeline(gpu, sample_format, samples);
    }
    let binds = Binds::new(gpu, pipes, &draws);
    let sample_colour = sample_colour(gpu, targets, sample_format, display.is_some());
    let (depth, ids_bind) =
        id_passes(pipes, targets, object_ids, draws.objects, &binds.ids, encoder);
    let attachments = Attachments {
        keep_samples: sample_colour.is_some() && display.is_some(),
        sample_colour,
        depth,
        ids_bind,
    };
    additive_pass(pipes, (sample_format, samples), &attachments, colour, &draws, &binds, encoder);
    if let (Some(filter), Some(m)) = (display, &mut targets.multi) {
        let size = targets.size;
        let shared = m.shared_ids.get_or_insert_with(|| {
            target_texture(
                gpu,
                "shared object ids",
                size,
                1,
                SHARED_ID_FORMAT,
                wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            )
        });
        let samples = (&m.colour[&(sample_format, true)], &m.ids, &*shared);
        pipes.resolve.encode(gpu, filter, samples, (colour, format), encoder);
    }
}

/// What a frame draws, its reflection and lens terms those that draw something.
struct Draws<'d, 'a> {
    objects: &'d [ObjectDraw<'a>],
    layers: &'d [LayerDraw<'a>],
    reflections: Vec<&'d ReflectionDraw<'a>>,
    lenses: Vec<&'d LensDraw<'a>>,
}

/// The bind groups of a frame's draws.
struct Binds {
    /// Per object, its uniforms for the object-index pass.
    ids: Vec<wgpu::BindGroup>,
    /// Per surface layer, its uniforms, texture and sampler.
    layers: Vec<wgpu::BindGroup>,
    /// Per reflection term: the bind group of its whole shell stack and, where the mesh has
    /// hull triangles and the term more than one shell, the bind group of its most distant
    /// shell alone (thesis 5.7: hull polygons never see the object itself).
    reflections: Vec<(wgpu::BindGroup, Option<wgpu::BindGroup>)>,
    /// Per lens term, its uniforms and cube maps.
    lenses: Vec<wgpu::BindGroup>,
}

impl Binds {
    fn new(gpu: &Gpu, pipes: &FramePipelines, draws: &Draws) -> Binds {
        let d = &gpu.device;
        let lenses =
            draws.lenses.iter().map(|l| lens_bind(gpu, &pipes.hybrid_draw_layout, l)).collect();
        let ubuf = |u: Uniforms| {
            d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("frame uniforms"),
                contents: bytemuck::bytes_of(&u),
                usage: wgpu::BufferUsages::UNIFORM,
            })
        };
        let ids = draws
            .objects
            .iter()
            .map(|o| {
                let b = ubuf(uniforms(o.clip_from_object, o.object, None));
                d.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("object id"),
                    layout: &pipes.uniform_layout,
                    entries: &[wgpu::BindGroupEntry {
                        binding: 0,
                        resource: b.as_entire_binding(),
                    }],
                })
            })
            .collect();
        let layers = draws
            .layers
            .iter()
            .map(|l| {
                let o = &draws.objects[l.draw];
                let b = ubuf(uniforms(o.clip_from_object, o.object, Some(l)));
                d.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("layer"),
                    layout: &pipes.draw_layout,
                    entries: &[
                        wgpu::BindGroupEntry { binding: 0, resource: b.as_entire_binding() },
                        wgpu::BindGroupEntry {
                            binding: 1,
                            resource: wgpu::BindingResource::TextureView(&l.texture.view),
                        },
                        wgpu::BindGroupEntry {
                            binding: 2,
                            resource: wgpu::BindingResource::Sampler(l.sampler),
                        },
                    ],
                })
            })
            .collect();
        let layout = &pipes.reflection_draw_layout;
        let reflections = draws
            .reflections
            .iter()
            .map(|r| {
                let o = &draws.objects[r.draw];
                let hull = (o.mesh.hull > 0 && r.shells.len() > 1)
                    .then(|| reflection_bind(gpu, layout, o, r, &r.shells[r.shells.len() - 1..]));
                (reflection_bind(gpu, layout, o, r, &r.shells), hull)
            })
            .collect();
        Binds { ids, layers, reflections, lenses }
    }
}

/// The attachments the additive pass draws into: the samples' colour (multisampled frames),
/// depth, and the object indices' bind group.
struct Attachments<'t> {
    sample_colour: Option<wgpu::TextureView>,
    /// The samples are kept for the display-filter resolve (else the hardware resolves them
    /// into the frame's target).
    keep_samples: bool,
    depth: &'t wgpu::Texture,
    ids_bind: &'t wgpu::BindGroup,
}

/// The colour attachment of a multisampled frame's samples (made on first use): in
/// `sample_format`, kept for the display-filter resolve to read where `display`. `None` for a
/// single-sample frame.
fn sample_colour(
    gpu: &Gpu,
    targets: &mut Targets,
    sample_format: wgpu::TextureFormat,
    display: bool,
) -> Option<wgpu::TextureView> {
    let (size, samples) = (targets.size, targets.samples);
    let m = targets.multi.as_mut()?;
    let usage = if display {
        wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING
    } else {
        wgpu::TextureUsages::RENDER_ATTACHMENT
    };
    let c = m.colour.entry((sample_format, display)).or_insert_with(|| {
        target_texture(gpu, "frame per sample", size, samples, sample_format, usage)
    });
    Some(c.create_view(&Default::default()))
}

/// The object-index passes: per sample for multisampled frames (then, with `object_ids`, one
/// more at pixel centres into `targets.ids`), else at pixel centres. Returns the depth and
/// the object indices' bind group the additive pass tests against.
fn id_passes<'t>(
    pipes: &FramePipelines,
    targets: &'t Targets,
    object_ids: bool,
    objects: &[ObjectDraw],
    id_binds: &[wgpu::BindGroup],
    encoder: &mut wgpu::CommandEncoder,
) -> (&'t wgpu::Texture, &'t wgpu::BindGroup) {
    let centres = &pipes.id_pipelines[&1];
    match &targets.multi {
        Some(m) => {
            let per_sample = &pipes.id_pipelines[&targets.samples];
            id_pass(per_sample, &m.ids, &m.depth, objects, id_binds, encoder);
            if object_ids {
                id_pass(centres, &targets.ids, &targets.depth, objects, id_binds, encoder);
            }
            (&m.depth, &m.ids_bind)
        }
        None => {
            id_pass(centres, &targets.ids, &targets.depth, objects, id_binds, encoder);
            (&targets.depth, &targets.ids_bind)
        }
    }
}

/// The additive pass into `colour` (through the sample attachments of a multisampled frame):
/// cleared, then the surface layers, the reflection terms and the lens terms added, each
/// with the pipeline of `key` (the samples' format, samples per pixel).
fn additive_pass(
    pipes: &FramePipelines,
    key: (wgpu::TextureFormat, u32),
    at: &Attachments,
    colour: &wgpu::TextureView,
    draws: &Draws,
    binds: &Binds,
    encoder: &mut wgpu::CommandEncoder,
) {
    let depth_view = at.depth.create_view(&Default::default());
    // Multisampled: the samples are resolved into `colour` by the hardware and then not
    // kept, or kept for the display-filter resolve.
    let (view, resolve_target, store) = match (&at.sample_colour, at.keep_samples) {
        (Some(v), false) => (v, Some(colour), wgpu::StoreOp::Discard),
        (Some(v), true) => (v, None, wgpu::StoreOp::Store),
        (None, _) => (colour, None, wgpu::StoreOp::Store),
    };
    let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("layers"),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view,
            depth_slice: None,
            resolve_target,
            ops: wgpu::Operations { load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT), store },
        })],
        depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
            view: &depth_view,
            depth_ops: Some(wgpu::Operations {
                load: wgpu::LoadOp::Load,
                store: if at.sample_colour.is_some() {
                    wgpu::StoreOp::Discard
                } else {
                    wgpu::StoreOp::Store
                },
            }),
            stencil_ops: None,
        }),
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    });
    pass.set_pipeline(&pipes.layer_pipelines[&key]);
    pass.set_bind_group(1, at.ids_bind, &[]);
    draw_layers(&mut pass, draws, binds);
    if !draws.reflections.is_empty() {
        pass.set_pipeline(&pipes.reflection_pipelines[&key]);
        pass.set_bind_group(1, at.ids_bind, &[]);
        draw_reflections(&mut pass, draws, binds);
    }
    if !draws.lenses.is_empty() {
        pass.set_pipeline(&pipes.hybrid_pipelines[&key]);
        pass.set_bind_group(1, at.ids_bind, &[]);
        for (l, bg) in draws.lenses.iter().zip(&binds.lenses) {
            pass.set_bind_group(0, bg, &[]);
            pass.set_vertex_buffer(0, l.corners.slice(..));
            pass.draw(0..l.count, 0..1);
        }
    }
}

/// Every surface layer on its object's mesh.
fn draw_layers(pass: &mut wgpu::RenderPass, draws: &Draws, binds: &Binds) {
    for (l, bg) in draws.layers.iter().zip(&binds.layers) {
        let m = draws.objects[l.draw].mesh;
        pass.set_bind_group(0, bg, &[]);
        pass.set_vertex_buffer(0, m.positions.slice(..));
        pass.set_vertex_buffer(1, m.uvs.slice(..));
        pass.set_index_buffer(m.indices.slice(..), wgpu::IndexFormat::Uint32);
        pass.draw_indexed(0..m.count, 0, 0..1);
    }
}

/// Every reflection term on its object's mesh: the hull triangles with the most distant
/// shell alone where the term has that bind group, the rest with the whole stack.
fn draw_reflections(pass: &mut wgpu::RenderPass, draws: &Draws, binds: &Binds) {
    for (r, (all, hull)) in draws.reflections.iter().zip(&binds.reflections) {
        let m = draws.objects[r.draw].mesh;
        pass.set_vertex_buffer(0, m.positions.slice(..));
        pass.set_vertex_buffer(1, m.normals.slice(..));
        pass.set_index_buffer(m.indices.slice(..), wgpu::IndexFormat::Uint32);
        let rest = match hull {
            Some(bg) => {
                pass.set_bind_group(0, bg, &[]);
                pass.draw_indexed(0..m.hull, 0, 0..1);
                m.hull
            }
            None => 0,
        };
        pass.set_bind_group(0, all, &[]);
        pass.draw_indexed(rest..m.count, 0, 0..1);
    }
}
