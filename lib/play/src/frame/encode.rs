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
use super::translucent::composite;
use crate::gpu::Gpu;
use crate::textured::{allocated_size, cut_uniform};

/// `Uniforms` of `frame.wgsl` (160 bytes).
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
    alpha_mode: u32,
    _pad: u32,
    cut: [f32; 4],
    tint: [f32; 4],
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
        alpha_mode: 0,
        _pad: 0,
        cut: [0.0; 4],
        tint: [1.0; 4],
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
        u.tint = [l.tint[0], l.tint[1], l.tint[2], 1.0];
        u.anisotropic = l.anisotropic as u32;
        u.cut = cut_uniform(&l.transform);
    }
    u
}

/// Which objects an object-index pass draws.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Drawn {
    /// The opaque objects, into cleared depth: the surfaces the additive pass draws.
    Opaque,
    /// The translucent objects, over the opaque objects' depth: the nearest translucent
    /// surface in front of them.
    Translucent,
    /// Every object, into cleared depth: the nearest surface, for the readback and the
    /// display-filter resolve of a frame with translucent objects.
    All,
}

impl Drawn {
    fn has(self, o: &ObjectDraw) -> bool {
        match self {
            Drawn::Opaque => !o.translucent,
            Drawn::Translucent => o.translucent,
            Drawn::All => true,
        }
    }
}

/// The object-index pass: clears `ids` (and `depth`, except for [`Drawn::Translucent`]),
/// then draws the index and depth of the objects `drawn` names, nearest surface winning.
fn id_pass(
    pipeline: &wgpu::RenderPipeline,
    (ids, depth): (&wgpu::Texture, &wgpu::Texture),
    (objects, binds): (&[ObjectDraw], &[wgpu::BindGroup]),
    drawn: Drawn,
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
                load: if drawn == Drawn::Translucent {
                    wgpu::LoadOp::Load
                } else {
                    wgpu::LoadOp::Clear(1.0)
                },
                store: wgpu::StoreOp::Store,
            }),
            stencil_ops: None,
        }),
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    });
    pass.set_pipeline(pipeline);
    for (o, bg) in objects.iter().zip(binds).filter(|(o, _)| drawn.has(o)) {
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
    let translucent = draws.objects.iter().any(|o| o.translucent);
    pipes.id_pipeline(gpu, samples);
    pipes.layer_pipeline(gpu, sample_format, samples);
    if translucent {
        pipes.translucent_pipelines(gpu, sample_format, samples);
        targets.translucent_targets(gpu, pipes, sample_format);
    }
    for r in &draws.reflections {
        pipes.reflection_pipeline(gpu, (sample_format, samples, r.code()));
    }
    for l in &draws.lenses {
        pipes.hybrid_pipeline(gpu, (sample_format, samples, l.code()));
    }
    let binds = Binds::new(gpu, pipes, &draws);
    let sample_colour = sample_colour(gpu, targets, sample_format, display.is_some());
    let (depth, ids_bind) =
        id_passes(pipes, targets, object_ids && !translucent, (draws.objects, &binds.ids), encoder);
    let attachments = Attachments {
        // Kept for the display-filter resolve, or for the composite to resolve.
        keep_samples: sample_colour.is_some() && (display.is_some() || translucent),
        sample_colour,
        keep_depth: translucent,
        depth,
        ids_bind,
    };
    let key = (sample_format, samples);
    additive_pass(pipes, key, &attachments, colour, &draws, &binds, encoder);
    if translucent {
        let frame = match &attachments.sample_colour {
            Some(v) if display.is_none() => (v, Some(colour), wgpu::StoreOp::Discard),
            Some(v) => (v, None, wgpu::StoreOp::Store),
            None => (colour, None, wgpu::StoreOp::Store),
        };
        translucent_passes(pipes, targets, key, &attachments, frame, &draws, &binds, encoder);
        nearest_ids(
            pipes,
            targets,
            object_ids,
            display.is_some(),
            (draws.objects, &binds.ids),
            encoder,
        );
    }
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
                let mut u = uniforms(o.clip_from_object, o.object, Some(l));
                u.alpha_mode = match (o.translucent, l.opacity) {
                    (false, _) => 0,
                    (true, true) => 1,
                    (true, false) => 2,
                };
                let b = ubuf(u);
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
        let layout = (&pipes.reflection_draw_layout, &pipes.no_depth);
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
    /// The samples are kept for the display-filter resolve or the translucent composite
    /// (else the hardware resolves them into the frame's target).
    keep_samples: bool,
    /// The depth is kept for the translucent draws.
    keep_depth: bool,
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
    drawn: (&[ObjectDraw], &[wgpu::BindGroup]),
    encoder: &mut wgpu::CommandEncoder,
) -> (&'t wgpu::Texture, &'t wgpu::BindGroup) {
    let centres = &pipes.id_pipelines[&1];
    let opaque = Drawn::Opaque;
    match &targets.multi {
        Some(m) => {
            let per_sample = &pipes.id_pipelines[&targets.samples];
            id_pass(per_sample, (&m.ids, &m.depth), drawn, opaque, encoder);
            if object_ids {
                id_pass(centres, (&targets.ids, &targets.depth), drawn, opaque, encoder);
            }
            (&m.depth, &m.ids_bind)
        }
        None => {
            id_pass(centres, (&targets.ids, &targets.depth), drawn, opaque, encoder);
            (&targets.depth, &targets.ids_bind)
        }
    }
}

/// The translucent draws of a frame whose opaque surfaces `at` holds: the nearest
/// translucent surface per sample in front of the opaque ones, its layers' colour and
/// opacity added into the translucent target, and that target composited over `frame` (the
/// frame's samples or pixels, the view it resolves into, and whether it is kept).
#[allow(clippy::too_many_arguments)]
fn translucent_passes(
    pipes: &FramePipelines,
    targets: &Targets,
    key: (wgpu::TextureFormat, u32),
    at: &Attachments,
    frame: (&wgpu::TextureView, Option<&wgpu::TextureView>, wgpu::StoreOp),
    draws: &Draws,
    binds: &Binds,
    encoder: &mut wgpu::CommandEncoder,
) {
    let t = targets.translucent.as_ref().expect("translucent targets made");
    let ids = &t.ids;
    let per_sample = &pipes.id_pipelines[&targets.samples];
    id_pass(per_sample, (ids, at.depth), (draws.objects, &binds.ids), Drawn::Translucent, encoder);
    let (layer, layer_bind) = &t.colour[&key.0];
    let layer_view = layer.create_view(&Default::default());
    let depth_view = at.depth.create_view(&Default::default());
    {
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("translucent layers"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &layer_view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &depth_view,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Load,
                    store: wgpu::StoreOp::Discard,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&pipes.translucent.layers[&key]);
        pass.set_bind_group(1, &t.ids_bind, &[]);
        draw_layers(&mut pass, draws, binds, true);
    }
    composite(&pipes.translucent.composites[&key], layer_bind, frame, encoder);
}

/// After translucent draws: the object indices of every object's nearest surface, per sample
/// for the display-filter resolve (`display`) and at pixel centres for the readback
/// (`object_ids`).
fn nearest_ids(
    pipes: &FramePipelines,
    targets: &Targets,
    object_ids: bool,
    display: bool,
    drawn: (&[ObjectDraw], &[wgpu::BindGroup]),
    encoder: &mut wgpu::CommandEncoder,
) {
    if let (Some(m), true) = (&targets.multi, display) {
        let per_sample = &pipes.id_pipelines[&targets.samples];
        id_pass(per_sample, (&m.ids, &m.depth), drawn, Drawn::All, encoder);
    }
    if object_ids {
        let centres = &pipes.id_pipelines[&1];
        id_pass(centres, (&targets.ids, &targets.depth), drawn, Drawn::All, encoder);
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
                store: if at.sample_colour.is_some() && !at.keep_depth {
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
    draw_layers(&mut pass, draws, binds, false);
    if !draws.reflections.is_empty() {
        pass.set_bind_group(1, at.ids_bind, &[]);
        draw_reflections(&mut pass, (pipes, key), draws, binds);
    }
    if !draws.lenses.is_empty() {
        pass.set_bind_group(1, at.ids_bind, &[]);
        for (l, bg) in draws.lenses.iter().zip(&binds.lenses) {
            pass.set_pipeline(&pipes.hybrid_pipelines[&(key.0, key.1, l.code())]);
            pass.set_bind_group(0, bg, &[]);
            pass.set_vertex_buffer(0, l.corners.slice(..));
            pass.draw(0..l.count, 0..1);
        }
    }
}

/// The surface layers of the translucent objects, or of the opaque ones, on their meshes.
fn draw_layers(pass: &mut wgpu::RenderPass, draws: &Draws, binds: &Binds, translucent: bool) {
    for (l, bg) in draws.layers.iter().zip(&binds.layers) {
        let o = &draws.objects[l.draw];
        if o.translucent != translucent {
            continue;
        }
        let m = o.mesh;
        pass.set_bind_group(0, bg, &[]);
        pass.set_vertex_buffer(0, m.positions.slice(..));
        pass.set_vertex_buffer(1, m.uvs.slice(..));
        pass.set_index_buffer(m.indices.slice(..), wgpu::IndexFormat::Uint32);
        pass.draw_indexed(0..m.count, 0, 0..1);
    }
}

/// Every reflection term on its object's mesh, with the pipeline of its shells' code: the
/// hull triangles with the most distant shell alone where the term has that bind group,
/// the rest with the whole stack.
fn draw_reflections(
    pass: &mut wgpu::RenderPass,
    (pipes, key): (&FramePipelines, (wgpu::TextureFormat, u32)),
    draws: &Draws,
    binds: &Binds,
) {
    for (r, (all, hull)) in draws.reflections.iter().zip(&binds.reflections) {
        pass.set_pipeline(&pipes.reflection_pipelines[&(key.0, key.1, r.code())]);
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
