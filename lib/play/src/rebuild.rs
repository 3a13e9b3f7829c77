//! Textures rebuilt from their level images on the GPU (thesis 4.7, SPEC.md 8.4): the workers
//! only decode codestreams; each decoded level image goes up once as a storage buffer of its
//! own (compact: its channels only, in 32-bit floats or, where the file allows it, in 16 bits
//! a value over the image's range, two to a word; kept while the level-image cache keeps the
//! image), and a
//! texture a frame needs is its level images stacked by buffer copies, summed, inverse gamma
//! applied and widened to RGBA by compute passes (`rebuild.wgsl`):
//! - a surface texture: one pass into the finest level of the padded layout, its MIP chain
//!   decimated by `mip.wgsl`;
//! - a shell's cube map: one pass per stored MIP level of the six faces, each level below the
//!   finest adding the finest decimated to its size (stored MIP residuals, kept in a scratch
//!   chain), then the levels beyond the stored ones decimated, into a scratch chain that
//!   one more pass writes into the cube map's atlas with borders (cube_atlas.rs).
//!
//! decode.rs's `assemble` and `assemble_cube` are the reference it is held to
//! (tests/rebuild_vs_cpu.rs) and the path where the GPU rebuild does not apply (a resolution
//! reduction, a stack beyond the device's limits).

use bytemuck::{Pod, Zeroable};
use wgpu::util::DeviceExt;

use pis_format::mip::mip_size;
use pis_format::precision::Level16;
use pis_format::reconstruct::face_len;
use pis_format::texture::LevelLayout;

use crate::cube_border::BorderPass;
use crate::gpu::Gpu;
use crate::mip::{storage_name, MipBuilder};
use crate::shell::ShellTexture;
use crate::textured::{allocated_size, ObjectTexture};

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct Params {
    used: [u32; 2],
    alloc: [u32; 2],
    channels: u32,
    levels: u32,
    plane: u32,
    mode: u32,
    gamma: f32,
    offset: u32,
    face_len: u32,
    add: u32,
}

impl Params {
    /// The parameters of a pass over `stack` writing a `used` level of `channels`.
    fn of(stack: &LevelStack, used: [u32; 2], plane: u32) -> Params {
        Params {
            used,
            alloc: used,
            channels: stack.channels,
            levels: stack.levels.len() as u32,
            plane,
            mode: gamma_mode(stack.gamma),
            gamma: stack.gamma,
            offset: 0,
            face_len: 0,
            add: 0,
        }
    }
}

/// What a texture is rebuilt from: its level images on the GPU (top first, each at least
/// `width × height × channels` values), its channels (1 to 4) and its layer's gamma.
pub struct LevelStack<'a> {
    pub levels: &'a [&'a wgpu::Buffer],
    pub channels: u32,
    pub gamma: f32,
}

/// One entry point of `rebuild.wgsl` and the bindings it reads.
struct Pass {
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::ComputePipeline,
}

/// The rebuilding pipelines: surface textures and cube maps in the GPU's formats
/// ([`Gpu::texture_format`], [`Gpu::cube_format`]), from level images of 32-bit floats or
/// of 16 bits a value ([`LevelRebuild::level_buffer`]).
pub struct LevelRebuild {
    /// Level images are held in 16 bits a value.
    level16: bool,
    surface: Pass,
    cube_level: Pass,
    cube_decimate: Pass,
    /// Bound where a cube level adds nothing.
    no_source: wgpu::TextureView,
    /// A rebuilt cube map's levels into its atlas with borders.
    border: BorderPass,
}

fn entry(binding: u32, ty: wgpu::BindingType) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry { binding, visibility: wgpu::ShaderStages::COMPUTE, ty, count: None }
}

/// The bindings of `rebuild.wgsl`, by number.
fn binding(gpu: &Gpu, n: u32) -> wgpu::BindGroupLayoutEntry {
    let ty = match n {
        0 => wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        1 => wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only: true },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        2 => wgpu::BindingType::StorageTexture {
            access: wgpu::StorageTextureAccess::WriteOnly,
            format: gpu.texture_format,
            view_dimension: wgpu::TextureViewDimension::D2,
        },
        3 => wgpu::BindingType::StorageTexture {
            access: wgpu::StorageTextureAccess::WriteOnly,
            format: gpu.cube_format,
            view_dimension: wgpu::TextureViewDimension::D2Array,
        },
        _ => wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable: false },
            view_dimension: wgpu::TextureViewDimension::D2Array,
            multisampled: false,
        },
    };
    entry(n, ty)
}

impl Pass {
    fn new(
        gpu: &Gpu,
        (module, constants): (&wgpu::ShaderModule, &[(&str, f64)]),
        name: &str,
        bindings: &[u32],
    ) -> Pass {
        let d = &gpu.device;
        let entries: Vec<_> = bindings.iter().map(|&n| binding(gpu, n)).collect();
        let layout = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some(name),
            entries: &entries,
        });
        let pl = d.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(name),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = d.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(name),
            layout: Some(&pl),
            module,
            entry_point: Some(name),
            compilation_options: wgpu::PipelineCompilationOptions {
                constants,
                ..Default::default()
            },
            cache: None,
        });
        Pass { layout, pipeline }
    }

    /// Records one dispatch of `groups` over `params` and `resources` (by binding number).
    fn dispatch(
        &self,
        gpu: &Gpu,
        params: &Params,
        resources: &[(u32, wgpu::BindingResource)],
        groups: [u32; 3],
        encoder: &mut wgpu::CommandEncoder,
    ) {
        let ubuf = gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("rebuild params"),
            contents: bytemuck::bytes_of(params),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let mut entries =
            vec![wgpu::BindGroupEntry { binding: 0, resource: ubuf.as_entire_binding() }];
        entries.extend(
            resources
                .iter()
                .map(|(n, r)| wgpu::BindGroupEntry { binding: *n, resource: r.clone() }),
        );
        let bg = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("rebuild"),
            layout: &self.layout,
            entries: &entries,
        });
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("rebuild"),
            timestamp_writes: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &bg, &[]);
        pass.dispatch_workgroups(groups[0], groups[1], groups[2]);
    }
}

/// The level images of `stack`, `plane` values each, as one buffer: the one image where it
/// lies, else the images copied one after another into a new buffer (recorded).
fn stacked(
    gpu: &Gpu,
    stack: &LevelStack,
    plane_bytes: u64,
    encoder: &mut wgpu::CommandEncoder,
) -> wgpu::Buffer {
    if let [one] = stack.levels {
        return (*one).clone();
    }
    let out = gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("level stack"),
        size: plane_bytes * stack.levels.len() as u64,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    for (k, level) in stack.levels.iter().enumerate() {
        encoder.copy_buffer_to_buffer(level, 0, &out, k as u64 * plane_bytes, plane_bytes);
    }
    out
}

/// `buffer` bound whole as the level stack.
fn stack_binding(buffer: &wgpu::Buffer) -> (u32, wgpu::BindingResource<'_>) {
    (1, buffer.as_entire_binding())
}

/// One MIP level of a texture, as a view of `dimension`.
fn level_view(
    texture: &wgpu::Texture,
    m: u32,
    dimension: wgpu::TextureViewDimension,
) -> wgpu::TextureView {
    texture.create_view(&wgpu::TextureViewDescriptor {
        dimension: Some(dimension),
        base_mip_level: m,
        mip_level_count: Some(1),
        ..Default::default()
    })
}

/// The shader's gamma mode: the identity, pis-codec's `pow_11_5` for the default gamma, or
/// the general power.
fn gamma_mode(gamma: f32) -> u32 {
    if gamma == 1.0 {
        0
    } else if gamma == pis_codec::gamma::DEFAULT_GAMMA {
        1
    } else {
        2
    }
}

/// A level image in 16 bits a value (`pis_format::precision::Level16`) as the rebuild reads
/// it, in 32-bit words: lo and step (their bits), then the values two to a word, the first in
/// the low half, the last word's high half 0 where the count is odd. `None` where a value is
/// not finite.
pub fn level16_words(values: &[f32]) -> Option<Vec<u32>> {
    let l = Level16::of(values)?;
    let pairs = l.q.chunks(2).map(|p| p[0] as u32 | (p.get(1).copied().unwrap_or(0) as u32) << 16);
    Some([l.lo.to_bits(), l.step.to_bits()].into_iter().chain(pairs).collect())
}

/// Words before a 16-bit level image's values: its lo and step.
const LEVEL16_HEADER: u32 = 2;

/// Whether a texture summed from `levels` level images of `values` values each fits the
/// device's storage buffers (else it is rebuilt on the workers), counted as 32-bit floats.
pub fn fits(gpu: &Gpu, values: u64, levels: usize) -> bool {
    let bytes = values.saturating_mul(4).saturating_mul(levels as u64);
    levels > 0
        && bytes <= gpu.limits.max_storage_buffer_binding_size
        && bytes <= gpu.limits.max_buffer_size
}

impl LevelRebuild {
    /// The pipelines for level images of 16 bits a value where `level16`, else of 32-bit
    /// floats.
    pub fn new(gpu: &Gpu, level16: bool) -> LevelRebuild {
        let source = include_str!("rebuild.wgsl")
            .replace("SURFACE_FORMAT", storage_name(gpu.texture_format))
            .replace("CUBE_FORMAT", storage_name(gpu.cube_format));
        let module = gpu.device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("rebuild.wgsl"),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
        let none = gpu.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("rebuild: no source"),
            size: wgpu::Extent3d { width: 1, height: 1, depth_or_array_layers: 6 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: gpu.cube_format,
            usage: wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        });
        let constants = [("LEVEL16", level16 as u32 as f64)];
        LevelRebuild {
            level16,
            surface: Pass::new(gpu, (&module, &constants), "rebuild", &[0, 1, 2]),
            cube_level: Pass::new(gpu, (&module, &constants), "cube_level", &[0, 1, 3, 4]),
            cube_decimate: Pass::new(gpu, (&module, &constants), "cube_decimate", &[0, 3, 4]),
            no_source: level_view(&none, 0, wgpu::TextureViewDimension::D2Array),
            border: BorderPass::new(gpu),
        }
    }

    /// Uploads a decoded level image as a storage buffer the rebuild reads: its values as they
    /// are, or in 16 bits a value ([`level16_words`]) where the pipelines read those (the
    /// player's decoder has refused values that are not finite).
    pub fn level_buffer(&self, gpu: &Gpu, values: &[f32]) -> wgpu::Buffer {
        let words;
        let contents: &[u8] = if self.level16 {
            words = level16_words(values).unwrap_or_default();
            bytemuck::cast_slice(&words)
        } else {
            bytemuck::cast_slice(values)
        };
        gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("level image"),
            contents,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        })
    }

    /// The bytes of a level image of `values` values on the GPU.
    pub fn level_bytes(&self, values: usize) -> u64 {
        match self.level16 {
            true => (LEVEL16_HEADER as u64 + values.div_ceil(2) as u64) * 4,
            false => values as u64 * 4,
        }
    }

    /// The 32-bit words from one level image to the next in a stack of `plane`-value images.
    fn stride(&self, plane: u32) -> u32 {
        (self.level_bytes(plane as usize) / 4) as u32
    }

    /// Records the rebuild of `texture` (made by [`MipBuilder::texture`] at full resolution)
    /// from `stack`: the level images stacked, the pass that writes the finest level, and
    /// the decimated MIP chain.
    pub fn record(
        &self,
        gpu: &Gpu,
        (texture, stack): (&ObjectTexture, &LevelStack),
        mips: &MipBuilder,
        encoder: &mut wgpu::CommandEncoder,
    ) {
        let layout = texture.layout;
        let (aw, ah) = allocated_size(&layout);
        let plane = layout.width * layout.height * stack.channels;
        let source = stacked(gpu, stack, self.level_bytes(plane as usize), encoder);
        let used = [layout.width, layout.height];
        let params = Params { alloc: [aw, ah], ..Params::of(stack, used, self.stride(plane)) };
        let finest = level_view(&texture.texture, 0, wgpu::TextureViewDimension::D2);
        let resources = [stack_binding(&source), (2, wgpu::BindingResource::TextureView(&finest))];
        let groups = [aw.div_ceil(8), ah.div_ceil(8), 1];
        self.surface.dispatch(gpu, &params, &resources, groups, encoder);
        mips.decimate(gpu, texture, encoder);
    }

    /// Records the rebuild of the cube map `texture` (every level of `TextureLayout::cube`
    /// of `level_layout.width`, made with [`ShellTexture::new`]) from `stack`, whose level
    /// images hold `level_layout`'s planes (six faces, each `level_layout.mips` stored
    /// levels).
    pub fn record_cube(
        &self,
        gpu: &Gpu,
        (texture, stack): (&ShellTexture, &LevelStack),
        level_layout: &LevelLayout,
        encoder: &mut wgpu::CommandEncoder,
    ) {
        let n = level_layout.width;
        let face_len = face_len(level_layout) as u32;
        let source = stacked(gpu, stack, self.level_bytes(face_len as usize * 6), encoder);
        let stored = level_layout.mips.clamp(1, texture.layout.levels);
        let scratch = (stored > 1).then(|| scratch_chain(gpu, n, stored));
        let levels = scratch_chain(gpu, n, texture.layout.levels);
        let array = wgpu::TextureViewDimension::D2Array;
        let mut offset = 0;
        for m in 0..texture.layout.levels {
            let (w, _) = mip_size(n, n, m);
            let dst = level_view(&levels, m, array);
            let groups = [w.div_ceil(8), w.div_ceil(8), 6];
            if m < stored {
                let added = match (&scratch, m) {
                    (Some(chain), 1..) => {
                        // The finest level decimated to this size: the scratch chain's next.
                        let (above, here) =
                            (level_view(chain, m - 1, array), level_view(chain, m, array));
                        self.decimate_level(
                            gpu,
                            (&above, &here),
                            (mip_size(n, n, m - 1).0, w),
                            encoder,
                        );
                        Some(here)
                    }
                    _ => None,
                };
                let params = Params {
                    offset,
                    face_len,
                    add: added.is_some() as u32,
                    ..Params::of(stack, [w, w], self.stride(face_len * 6))
                };
                let src = added.as_ref().unwrap_or(&self.no_source);
                let resources = [
                    stack_binding(&source),
                    (3, wgpu::BindingResource::TextureView(&dst)),
                    (4, wgpu::BindingResource::TextureView(src)),
                ];
                self.cube_level.dispatch(gpu, &params, &resources, groups, encoder);
                if let (Some(chain), 0) = (&scratch, m) {
                    copy_finest(encoder, &levels, chain, n);
                }
                offset += w * w * stack.channels;
            } else {
                let above = level_view(&levels, m - 1, array);
                self.decimate_level(gpu, (&above, &dst), (mip_size(n, n, m - 1).0, w), encoder);
            }
        }
        self.border.record(gpu, (&levels, &texture.atlas), &texture.view, encoder);
    }

    /// Records the decimation of a level of six faces (`src`, `size.0` square) into the
    /// next (`dst`, `size.1`).
    fn decimate_level(
        &self,
        gpu: &Gpu,
        (src, dst): (&wgpu::TextureView, &wgpu::TextureView),
        (from, to): (u32, u32),
        encoder: &mut wgpu::CommandEncoder,
    ) {
        let params = Params {
            used: [to, to],
            alloc: [from, from],
            channels: 4,
            levels: 0,
            plane: 0,
            mode: 0,
            gamma: 1.0,
            offset: 0,
            face_len: 0,
            add: 0,
        };
        let resources = [
            (3, wgpu::BindingResource::TextureView(dst)),
            (4, wgpu::BindingResource::TextureView(src)),
        ];
        let groups = [to.div_ceil(8), to.div_ceil(8), 6];
        self.cube_decimate.dispatch(gpu, &params, &resources, groups, encoder);
    }
}

/// A scratch chain of six `n × n` faces and `levels` levels: the cube map's levels before
/// their borders, and the finest level decimated down the stored levels.
fn scratch_chain(gpu: &Gpu, n: u32, levels: u32) -> wgpu::Texture {
    let side = n.next_power_of_two();
    gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("rebuild: cube levels"),
        size: wgpu::Extent3d { width: side, height: side, depth_or_array_layers: 6 },
        mip_level_count: levels,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: gpu.cube_format,
        usage: wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::STORAGE_BINDING
            | wgpu::TextureUsages::COPY_SRC
            | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    })
}

/// Records the copy of the finest level's six `n × n` faces of `from` into `to`.
fn copy_finest(
    encoder: &mut wgpu::CommandEncoder,
    from: &wgpu::Texture,
    to: &wgpu::Texture,
    n: u32,
) {
    encoder.copy_texture_to_texture(
        from.as_image_copy(),
        to.as_image_copy(),
        wgpu::Extent3d { width: n, height: n, depth_or_array_layers: 6 },
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sixteen_bit_words_hold_lo_step_then_two_values_low_half_first() {
        let words = level16_words(&[1.0, -2.0, 0.5]).unwrap();
        let step = 3.0f32 / 65535.0;
        assert_eq!(&words[..2], &[(-2.0f32).to_bits(), step.to_bits()]);
        assert_eq!(words[2], 65535, "1.0 (q 65535) in the low half, -2.0 (q 0) in the high");
        assert_eq!(words[3], (2.5 / step).round() as u32, "the odd count's last word");
        assert_eq!(level16_words(&[f32::INFINITY]), None);
    }

    #[test]
    fn the_gamma_mode_names_the_fast_path_for_the_default_gamma() {
        assert_eq!(gamma_mode(1.0), 0);
        assert_eq!(gamma_mode(pis_codec::gamma::DEFAULT_GAMMA), 1);
        assert_eq!(gamma_mode(1.8), 2);
    }
}
