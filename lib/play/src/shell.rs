//! Environment-map shells on the GPU (`shell.wgsl`): a cube map as a six-layer 2D array
//! texture read with `textureLoad` and filtered in the shader exactly as pis-compile's
//! hardware model filters it (`pis_compile::shell`), and the pipeline that draws one object
//! with one shell — the rendering a shell's render matrix predicts. The player's frames
//! draw a reflective object's shells with the same functions (`frame/reflection.wgsl`,
//! `frame/reflection.rs`).
//!
//! Each layer holds one face's MIP levels side by side, each with a one-texel border that
//! makes its bilinear lookups seamless (cube_atlas.rs).

use bytemuck::{Pod, Zeroable};
use pis_compile::shell::{DepthCube, ShellObject, ShellShape};
use pis_compile::{DrawMesh, TextureLayout, Viewport};
use wgpu::util::DeviceExt;

use crate::cube_atlas::{sources, CubeAtlas};
use crate::error::PlayError;
use crate::gpu::Gpu;
use crate::image::FloatImage;
use crate::textured::{write_level, DEPTH_FORMAT, TARGET_FORMAT};

/// The shell functions every shell pipeline appends its entry points to: the isotropic LOD
/// (`texture_lod.wgsl`, shared with the textured pipeline and the frame), then `shell.wgsl`.
pub const SHELL_FUNCTIONS: &str =
    concat!(include_str!("texture_lod.wgsl"), include_str!("shell.wgsl"));
/// The one-shell object pipeline's entry points.
pub const SHELL_OBJECT: &str = include_str!("shell_object.wgsl");

/// The code a pipeline of shell lookups carries: `shell.wgsl`'s pipeline-overridable
/// constants. A pipeline compiled without depth shells or without sub-pixel lookups leaves
/// the depth march or the k × k loop out of its code; a draw that needs neither looks its
/// shells up with the same arithmetic either way, and takes less than half the time on a
/// CPU rasterizer (lavapipe), where the code a shader carries costs even when not run.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct ShellCode {
    /// The depth march (a depth shell, SPEC.md 8.5).
    pub depth: bool,
    /// k × k lookups per pixel with k > 1 (SPEC.md 8.2).
    pub sub_pixel: bool,
}

impl ShellCode {
    /// The code a shell of `shape` looked up `lookups` times per pixel side needs.
    pub fn of(shape: &ShellShape, lookups: u32) -> ShellCode {
        ShellCode { depth: matches!(shape, ShellShape::Depth { .. }), sub_pixel: lookups > 1 }
    }

    /// The code a shell block placed with `shape` (SPEC.md 7.3) and `lookups` needs.
    pub fn of_placement(shape: pis_format::ShellShape, lookups: u32) -> ShellCode {
        ShellCode { depth: shape == pis_format::ShellShape::Depth, sub_pixel: lookups > 1 }
    }

    /// The code both `self` and `other` need.
    pub fn union(self, other: ShellCode) -> ShellCode {
        ShellCode { depth: self.depth || other.depth, sub_pixel: self.sub_pixel || other.sub_pixel }
    }

    /// The values of `shell.wgsl`'s overridable constants.
    pub fn constants(self) -> [(&'static str, f64); 2] {
        let flag = |on: bool| if on { 1.0 } else { 0.0 };
        [("DEPTH_SHELLS", flag(self.depth)), ("SUB_PIXEL_LOOKUPS", flag(self.sub_pixel))]
    }
}

/// A cube map on the GPU, as its lookups read it: each face's levels with their borders in
/// one atlas image ([`CubeAtlas`]), the six faces the layers of a 2D array.
pub struct ShellTexture {
    pub layout: TextureLayout,
    pub atlas: CubeAtlas,
    pub texture: wgpu::Texture,
    pub view: wgpu::TextureView,
}

impl ShellTexture {
    /// Allocates a cube map of `layout` (six square faces) for `object` (named in errors).
    pub fn new(gpu: &Gpu, layout: TextureLayout, object: &str) -> Result<ShellTexture, PlayError> {
        let limit = gpu.limits.max_texture_dimension_2d;
        let atlas = CubeAtlas::of(&layout);
        if layout.faces != 6
            || layout.width != layout.height
            || layout.width == 0
            || atlas.largest_side() > limit
            || layout.levels == 0
            || layout.levels > TextureLayout::cube(layout.width).levels
        {
            return Err(PlayError::TextureSize {
                object: object.to_string(),
                width: layout.width,
                height: layout.height,
                limit,
            });
        }
        let texture = gpu.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("shell"),
            size: wgpu::Extent3d {
                width: atlas.width,
                height: atlas.height,
                depth_or_array_layers: 6,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: gpu.cube_format,
            // Storage: the GPU's rebuild writes it (rebuild.rs).
            usage: wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_DST
                | wgpu::TextureUsages::COPY_SRC
                | wgpu::TextureUsages::STORAGE_BINDING,
            view_formats: &[],
        });
        let view = texture.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        });
        Ok(ShellTexture { layout, atlas, texture, view })
    }

    /// Uploads RGBA texels in the layout's order (face after face, each level after level),
    /// bordered on the CPU ([`CubeAtlas::border`]); returns the bytes written.
    pub fn upload(&self, gpu: &Gpu, rgba: &[f32]) -> Result<u64, PlayError> {
        let l = self.layout;
        let want = l.texel_count() * 4;
        if rgba.len() != want {
            return Err(PlayError::TextureData {
                got: rgba.len(),
                want,
                width: l.width,
                height: l.height,
                levels: l.levels,
            });
        }
        self.upload_atlas(gpu, &self.atlas.border(&l, rgba))
    }

    /// Uploads the atlas images `texels` ([`CubeAtlas::border`]'s); returns the bytes
    /// written.
    pub fn upload_atlas(&self, gpu: &Gpu, texels: &[f32]) -> Result<u64, PlayError> {
        let face = self.atlas.face_texels() * 4;
        if texels.len() != 6 * face {
            return Err(PlayError::TextureData {
                got: texels.len(),
                want: 6 * face,
                width: self.atlas.width,
                height: self.atlas.height,
                levels: 1,
            });
        }
        let size = (self.atlas.width, self.atlas.height);
        let mut bytes = 0;
        for (f, image) in texels.chunks_exact(face).enumerate() {
            bytes += write_level(gpu, &self.texture, (0, f as u32), size, image);
        }
        Ok(bytes)
    }
}

/// Reads a cube map back (tests and diagnostics): RGBA texels in its layout's order, face
/// after face and level after level, as [`ShellTexture::upload`] takes them.
pub fn read_cube(gpu: &Gpu, cube: &ShellTexture) -> Result<Vec<f32>, PlayError> {
    Ok(cube.atlas.interior(&cube.layout, &read_atlas(gpu, cube)?))
}

/// Reads a cube map's atlas images back (tests and diagnostics): RGBA, face after face.
pub fn read_atlas(gpu: &Gpu, cube: &ShellTexture) -> Result<Vec<f32>, PlayError> {
    let a = cube.atlas;
    let mut out = Vec::with_capacity(6 * a.face_texels() * 4);
    for face in 0..6 {
        out.extend(crate::mip::read_level(gpu, &cube.texture, (0, face), (a.width, a.height))?);
    }
    Ok(out)
}

/// Texel format of depth cubes: one distance per texel, read with `textureLoad`.
pub const DEPTH_CUBE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;

/// A depth shell's depth cube on the GPU (one level, six layers), or a one-texel stand-in
/// for the shaders' `depth` argument where the shell has another shape.
pub struct DepthTexture {
    pub texture: wgpu::Texture,
    pub view: wgpu::TextureView,
}

impl DepthTexture {
    /// The depth cube of `shell` (SPEC.md 8.5), uploaded with its border
    /// ([`bordered_depth_faces`]); [`Self::none`] for a shell of another shape.
    pub fn new(gpu: &Gpu, shell: &pis_compile::shell::Shell) -> DepthTexture {
        match &shell.shape {
            pis_compile::shell::ShellShape::Depth { cube, .. } => {
                DepthTexture::upload(gpu, cube.size + 2, &bordered_depth_faces(cube))
            }
            _ => DepthTexture::none(gpu),
        }
    }

    /// The stand-in bound where a shell is not a depth shell: one zero texel per face and
    /// its border.
    pub fn none(gpu: &Gpu) -> DepthTexture {
        DepthTexture::upload(gpu, 3, &[0.0; 6 * 9])
    }

    /// `data`: `n × n` distances per face, face after face, rows from the top.
    fn upload(gpu: &Gpu, n: u32, data: &[f32]) -> DepthTexture {
        let texture = gpu.device.create_texture_with_data(
            &gpu.queue,
            &wgpu::TextureDescriptor {
                label: Some("depth cube"),
                size: wgpu::Extent3d { width: n, height: n, depth_or_array_layers: 6 },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: DEPTH_CUBE_FORMAT,
                usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
                view_formats: &[],
            },
            wgpu::util::TextureDataOrder::LayerMajor,
            bytemuck::cast_slice(data),
        );
        let view = texture.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        });
        DepthTexture { texture, view }
    }
}

/// A depth cube's faces with a one-texel border, `size + 2` texels a side, face after face,
/// rows from the top: inside, the face's distances; on the border, what a cube map's atlas
/// holds there ([`crate::cube_atlas::sources`]): beyond one edge, the neighbouring face's
/// texel that `cube_texel` names, beyond a corner, the mean of the three texels that meet
/// there. `shell.wgsl`'s `depth_distance` then filters the bordered face bilinearly with no
/// seam to handle, and gets [`DepthCube::distance`]'s seamless lookup: the same four texels
/// and weights, a corner's weight on the mean of the other three.
pub fn bordered_depth_faces(cube: &DepthCube) -> Vec<f32> {
    let n = cube.size;
    let texel = |(f, i, j): (u32, u32, u32)| cube.distances[((f * n + j) * n + i) as usize];
    let mut out = Vec::with_capacity(6 * (n as usize + 2).pow(2));
    for face in 0..6 {
        for j in -1..=n as i64 {
            for i in -1..=n as i64 {
                let s = sources(face, i, j, n);
                out.push(match s.count {
                    1 => texel(s.texels[0]),
                    _ => (texel(s.texels[0]) + texel(s.texels[1]) + texel(s.texels[2])) / 3.0,
                });
            }
        }
    }
    out
}

/// The bind group layout entry of a cube map or depth cube at `binding`: a 2D array read
/// with `textureLoad` in the fragment stage.
pub(crate) fn cube_layout_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable: false },
            view_dimension: wgpu::TextureViewDimension::D2Array,
            multisampled: false,
        },
        count: None,
    }
}

/// `ShellUniforms` of `shell_object.wgsl` (208 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct ShellUniforms {
    clip_from_object: [f32; 16],
    world_from_object: [f32; 16],
    eye: [f32; 4],
    origin_shape: [f32; 4],
    a: [f32; 4],
    b: [f32; 4],
    size: u32,
    levels: u32,
    lookups: u32,
    _pad: u32,
}

/// A shell's geometry as the shaders' `ShellGeometry` fields: origin and shape id, `a`, `b`.
pub fn shell_uniform(shell: &pis_compile::shell::Shell) -> ([f32; 4], [f32; 4], [f32; 4]) {
    let (id, v) = shell.placement_values();
    let (a, b) = match id {
        // Box: corners; others: their parameters in `a`.
        3 => ([v[3], v[4], v[5], 0.0], [v[6], v[7], v[8], 0.0]),
        _ => ([v[3], v[4], v[5], 0.0], [0.0; 4]),
    };
    ([v[0], v[1], v[2], id as f32], a, b)
}

/// The compiled one-shell pipeline and its depth-only pass for occluders.
pub struct ShellPipeline {
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::RenderPipeline,
    depth_pipeline: wgpu::RenderPipeline,
}

/// A vertex buffer of `Float32x3` at shader location `location` (0 or 1).
pub(crate) const VEC3_AT: fn(u32) -> wgpu::VertexBufferLayout<'static> =
    |location| wgpu::VertexBufferLayout {
        array_stride: 12,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes: match location {
            0 => &[wgpu::VertexAttribute {
                format: wgpu::VertexFormat::Float32x3,
                offset: 0,
                shader_location: 0,
            }],
            _ => &[wgpu::VertexAttribute {
                format: wgpu::VertexFormat::Float32x3,
                offset: 0,
                shader_location: 1,
            }],
        },
    };

/// The pipelines of one object drawn with one cube map over `shell.wgsl` and `entries`
/// (WGSL appended to it): the bind group layout (binding 0 the uniforms, 1 the cube map,
/// 2 a depth cube where `depth_cube`), the
/// colour pipeline (vertex entry `vs` with two `Float32x3` buffers, fragment `fs`) and the
/// depth-only one (`vs_depth` over positions, `fs_depth`, no colour written); depth test
/// `Less`, no culling.
pub(crate) fn object_pipelines(
    gpu: &Gpu,
    label: &str,
    entries: &str,
    (vs, fs): (&str, &str),
    (vs_depth, fs_depth): (&str, &str),
    depth_cube: bool,
) -> (wgpu::BindGroupLayout, wgpu::RenderPipeline, wgpu::RenderPipeline) {
    let device = &gpu.device;
    let source = format!("{SHELL_FUNCTIONS}\n{entries}");
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(label),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    });
    let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(label),
        entries: &[
            wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            },
            cube_layout_entry(1),
            cube_layout_entry(2),
        ][..if depth_cube { 3 } else { 2 }],
    });
    let pl = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(label),
        bind_group_layouts: &[Some(&layout)],
        immediate_size: 0,
    });
    let primitive = wgpu::PrimitiveState {
        topology: wgpu::PrimitiveTopology::TriangleList,
        cull_mode: None,
        ..Default::default()
    };
    let depth_state = wgpu::DepthStencilState {
        format: DEPTH_FORMAT,
        depth_write_enabled: Some(true),
        depth_compare: Some(wgpu::CompareFunction::Less),
        stencil: Default::default(),
        bias: Default::default(),
    };
    let make = |vs,
                buffers: &[Option<wgpu::VertexBufferLayout>],
                fragment: Option<wgpu::FragmentState>| {
        device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some(label),
            layout: Some(&pl),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some(vs),
                compilation_options: Default::default(),
                buffers,
            },
            primitive,
            depth_stencil: Some(depth_state.clone()),
            multisample: Default::default(),
            fragment,
            multiview_mask: None,
            cache: None,
        })
    };
    let targets = [Some(wgpu::ColorTargetState {
        format: TARGET_FORMAT,
        blend: None,
        write_mask: wgpu::ColorWrites::ALL,
    })];
    let fragment = wgpu::FragmentState {
        module: &module,
        entry_point: Some(fs),
        compilation_options: Default::default(),
        targets: &targets,
    };
    let pipeline = make(vs, &[Some(VEC3_AT(0)), Some(VEC3_AT(1))], Some(fragment));
    let silent = [Some(wgpu::ColorTargetState {
        format: TARGET_FORMAT,
        blend: None,
        write_mask: wgpu::ColorWrites::empty(),
    })];
    let none = wgpu::FragmentState {
        module: &module,
        entry_point: Some(fs_depth),
        compilation_options: Default::default(),
        targets: &silent,
    };
    let depth_pipeline = make(vs_depth, &[Some(VEC3_AT(0))], Some(none));
    (layout, pipeline, depth_pipeline)
}

impl ShellPipeline {
    pub fn new(gpu: &Gpu) -> ShellPipeline {
        let (layout, pipeline, depth_pipeline) = object_pipelines(
            gpu,
            "shell_object.wgsl",
            SHELL_OBJECT,
            ("vs_shell", "fs_shell"),
            ("vs_shell_depth", "fs_shell_depth"),
            true,
        );
        ShellPipeline { layout, pipeline, depth_pipeline }
    }
}

/// Draws `object` with its shell's cube map `rgba` (4 values per texel of its layout) over
/// the occluders' depth; returns RGBA per pixel (rows from the top), alpha 1 where the object
/// draws the shell, 0 elsewhere. Triangles that do not draw the shell (`object.drawn`) are
/// left out of the colour pass but still write depth.
pub fn render_shell(
    gpu: &Gpu,
    pipeline: &ShellPipeline,
    viewport: Viewport,
    occluders: &[DrawMesh],
    object: &ShellObject,
    rgba: &[f32],
) -> Result<FloatImage, PlayError> {
    check_viewport(gpu, viewport)?;
    let cube = ShellTexture::new(gpu, object.layout, "shell")?;
    cube.upload(gpu, rgba)?;
    let depth_cube = DepthTexture::new(gpu, &object.shell);
    // Occluders, then the object's hidden triangles, write depth only.
    let mut depth_draws = Vec::new();
    for m in occluders {
        pis_compile::model::check_mesh(m)?;
        depth_draws.push((m.positions.to_vec(), m.indices.to_vec(), m.clip_from_object));
    }
    let (mut shown, mut hidden) = (Vec::new(), Vec::new());
    for (t, tri) in object.indices.chunks_exact(3).enumerate() {
        let on = object.drawn.is_none_or(|dr| dr.get(t).copied().unwrap_or(false));
        if on { &mut shown } else { &mut hidden }.extend_from_slice(tri);
    }
    depth_draws.push((object.positions.to_vec(), hidden, object.clip_from_object));
    let (color, depth) = frame_targets(gpu, viewport);
    let mut enc =
        gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("shell") });
    let draws = ShellDraws::new(gpu, pipeline, (&cube, &depth_cube), object, &depth_draws, &shown);
    shell_pass(&mut enc, pipeline, (&color, &depth), &draws);
    crate::image::read_back(gpu, enc, &color, viewport)
}

/// A viewport the adapter can draw: not empty, within its largest 2D texture.
pub(crate) fn check_viewport(gpu: &Gpu, viewport: Viewport) -> Result<(), PlayError> {
    let limit = gpu.limits.max_texture_dimension_2d;
    if viewport.width == 0
        || viewport.height == 0
        || viewport.width > limit
        || viewport.height > limit
    {
        return Err(PlayError::TargetSize {
            width: viewport.width,
            height: viewport.height,
            limit,
        });
    }
    Ok(())
}

/// The colour ([`TARGET_FORMAT`], copied out) and depth targets of a viewport.
fn frame_targets(gpu: &Gpu, viewport: Viewport) -> (wgpu::Texture, wgpu::Texture) {
    let size =
        wgpu::Extent3d { width: viewport.width, height: viewport.height, depth_or_array_layers: 1 };
    let target = |label, format, usage| {
        gpu.device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size,
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage,
            view_formats: &[],
        })
    };
    let color = target(
        "frame",
        TARGET_FORMAT,
        wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
    );
    let depth = target("depth", DEPTH_FORMAT, wgpu::TextureUsages::RENDER_ATTACHMENT);
    (color, depth)
}

/// A mesh drawn for depth only: positions, indices and clip transform.
type DepthMesh = (Vec<[f32; 3]>, Vec<u32>, glam::Mat4);

/// One depth-only draw: positions, indices, index count, bind group.
type DepthDraw = (wgpu::Buffer, wgpu::Buffer, u32, wgpu::BindGroup);

/// The buffers and bind groups of a shell frame: the depth-only draws, then the object's
/// shown triangles (bind group, positions, normals, indices, index count).
struct ShellDraws {
    depth: Vec<DepthDraw>,
    object: (wgpu::BindGroup, wgpu::Buffer, wgpu::Buffer, wgpu::Buffer, u32),
}

impl ShellDraws {
    /// `depth_draws`: positions, indices and clip transform of each depth-only draw;
    /// `shown`: the indices of the object's triangles that draw the shell.
    fn new(
        gpu: &Gpu,
        pipeline: &ShellPipeline,
        (cube, depth_cube): (&ShellTexture, &DepthTexture),
        object: &ShellObject,
        depth_draws: &[DepthMesh],
        shown: &[u32],
    ) -> ShellDraws {
        let d = &gpu.device;
        let init = |label: &str, contents: &[u8], usage| {
            d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage,
            })
        };
        let (origin_shape, a, b) = shell_uniform(&object.shell);
        let uniforms = |clip: glam::Mat4| ShellUniforms {
            clip_from_object: clip.to_cols_array(),
            world_from_object: object.world_from_object.to_cols_array(),
            eye: [object.eye.x, object.eye.y, object.eye.z, 1.0],
            origin_shape,
            a,
            b,
            size: object.layout.width,
            levels: object.layout.levels,
            lookups: object.lookups.max(1),
            _pad: 0,
        };
        let bind = |clip: glam::Mat4| {
            let u =
                init("uniforms", bytemuck::bytes_of(&uniforms(clip)), wgpu::BufferUsages::UNIFORM);
            d.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("shell"),
                layout: &pipeline.layout,
                entries: &[
                    wgpu::BindGroupEntry { binding: 0, resource: u.as_entire_binding() },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: wgpu::BindingResource::TextureView(&cube.view),
                    },
                    wgpu::BindGroupEntry {
                        binding: 2,
                        resource: wgpu::BindingResource::TextureView(&depth_cube.view),
                    },
                ],
            })
        };
        let pad3 = |v: &[[f32; 3]]| if v.is_empty() { vec![[0.0f32; 3]] } else { v.to_vec() };
        let pad1 = |v: &[u32]| if v.is_empty() { vec![0u32] } else { v.to_vec() };
        let depth = depth_draws
            .iter()
            .map(|(p, i, clip)| {
                let bg = bind(*clip);
                (
                    init("positions", bytemuck::cast_slice(&pad3(p)), wgpu::BufferUsages::VERTEX),
                    init("indices", bytemuck::cast_slice(&pad1(i)), wgpu::BufferUsages::INDEX),
                    i.len() as u32 / 3 * 3,
                    bg,
                )
            })
            .collect();
        let object = (
            bind(object.clip_from_object),
            init(
                "positions",
                bytemuck::cast_slice(&pad3(object.positions)),
                wgpu::BufferUsages::VERTEX,
            ),
            init(
                "normals",
                bytemuck::cast_slice(&pad3(object.normals)),
                wgpu::BufferUsages::VERTEX,
            ),
            init("indices", bytemuck::cast_slice(&pad1(shown)), wgpu::BufferUsages::INDEX),
            shown.len() as u32 / 3 * 3,
        );
        ShellDraws { depth, object }
    }
}

/// The shell frame's one pass into `(color, depth)`, both cleared: the depth-only draws,
/// then the object's shown triangles with the shell.
fn shell_pass(
    enc: &mut wgpu::CommandEncoder,
    pipeline: &ShellPipeline,
    (color, depth): (&wgpu::Texture, &wgpu::Texture),
    draws: &ShellDraws,
) {
    let (color_view, depth_view) =
        (color.create_view(&Default::default()), depth.create_view(&Default::default()));
    let mut pass = crate::gpu::cleared_pass(enc, "shell", &color_view, &depth_view);
    pass.set_pipeline(&pipeline.depth_pipeline);
    for (p, i, n, bg) in &draws.depth {
        pass.set_bind_group(0, bg, &[]);
        pass.set_vertex_buffer(0, p.slice(..));
        pass.set_index_buffer(i.slice(..), wgpu::IndexFormat::Uint32);
        pass.draw_indexed(0..*n, 0, 0..1);
    }
    let (bg, positions, normals, indices, count) = &draws.object;
    pass.set_pipeline(&pipeline.pipeline);
    pass.set_bind_group(0, bg, &[]);
    pass.set_vertex_buffer(0, positions.slice(..));
    pass.set_vertex_buffer(1, normals.slice(..));
    pass.set_index_buffer(indices.slice(..), wgpu::IndexFormat::Uint32);
    pass.draw_indexed(0..*count, 0, 0..1);
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use glam::DVec3;
    use pis_compile::filter::Taps;
    use pis_compile::shell::cube::{cube_face, face_st};

    use super::*;

    #[test]
    fn shell_code_sets_the_constants_shell_wgsl_declares() {
        for (name, _) in ShellCode::default().constants() {
            let declared = format!("override {name}: bool = true;");
            assert!(SHELL_FUNCTIONS.contains(&declared), "shell.wgsl lacks `{declared}`");
        }
        let sphere = ShellShape::Sphere { radius: 1.0 };
        let cube = DepthCube { size: 1, far: 2.0, distances: vec![2.0; 6] };
        let depth = ShellShape::Depth { cube: Arc::new(cube), steps: 8 };
        assert_eq!(ShellCode::of(&sphere, 1), ShellCode::default());
        let code = ShellCode::of(&sphere, 2).union(ShellCode::of(&depth, 1));
        assert_eq!(code, ShellCode { depth: true, sub_pixel: true });
        assert_eq!(code.constants(), [("DEPTH_SHELLS", 1.0), ("SUB_PIXEL_LOOKUPS", 1.0)]);
    }

    /// `depth_distance` of shell.wgsl on the bordered faces, in f64.
    fn bordered_bilinear(bordered: &[f32], n: u32, q: DVec3) -> f64 {
        let face = cube_face(q);
        let [s, t] = face_st(face, q);
        let (u, v) = (s * n as f64 - 0.5, t * n as f64 - 0.5);
        let (a, b) = (u - u.floor(), v - v.floor());
        let (i, j) = ((u.floor() + 1.0) as usize, (v.floor() + 1.0) as usize);
        let p = n as usize + 2;
        let at = |i: usize, j: usize| bordered[(face as usize * p + j) * p + i] as f64;
        (1.0 - a) * (1.0 - b) * at(i, j)
            + a * (1.0 - b) * at(i + 1, j)
            + (1.0 - a) * b * at(i, j + 1)
            + a * b * at(i + 1, j + 1)
    }

    #[test]
    fn a_bordered_depth_cube_filters_as_the_seamless_lookup() {
        let n = 5;
        let distances: Vec<f32> = (0..6 * n * n).map(|k| 1.0 + ((k * 37) % 101) as f32).collect();
        let cube = DepthCube { size: n, far: 200.0, distances };
        let bordered = bordered_depth_faces(&cube);
        assert_eq!(bordered.len(), 6 * (n as usize + 2).pow(2));
        let mut taps = Taps::default();
        for q in crate::cube_atlas::tests::direction_lattice() {
            let want = cube.distance(q, &mut taps);
            let got = bordered_bilinear(&bordered, n, q);
            assert!((want - got).abs() <= 1e-6 * want, "{q}: {want} against {got}");
        }
    }
}
