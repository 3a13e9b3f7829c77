//! The wgpu device the player draws with.

use crate::error::PlayError;

/// An adapter, its device and queue, and what the player needs from them.
pub struct Gpu {
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub info: wgpu::AdapterInfo,
    pub limits: wgpu::Limits,
    /// Format of object textures: `Rgba32Float` where the adapter can filter it (feature
    /// `FLOAT32_FILTERABLE`: Mesa's lavapipe and desktop GPUs), so that the texel values the
    /// sampler filters are exactly those the model's A multiplies; else `Rgba16Float`
    /// (always filterable; texels rounded to half floats, relative error ≤ 2^-11).
    pub texture_format: wgpu::TextureFormat,
    /// Format of shells' cube maps (read with `textureLoad`, never filtered by the sampler):
    /// `Rgba32Float`, or `Rgba16Float` for a file whose textures a player holds in half
    /// floats ([`Gpu::with_half_textures`]).
    pub cube_format: wgpu::TextureFormat,
    /// The adapter the device was opened on (its texture format features).
    adapter: wgpu::Adapter,
}

/// Choices when opening the GPU.
#[derive(Clone, Copy, Debug, Default)]
pub struct GpuOptions {
    /// Use `Rgba16Float` textures even where `Rgba32Float` is filterable.
    pub half_textures: bool,
}

/// Gives the process an `XDG_RUNTIME_DIR` where none is set, before the first wgpu instance
/// is created: Mesa's Vulkan drivers print "error: XDG_RUNTIME_DIR is invalid or not set in
/// the environment." otherwise (headless machines, containers, cron), which is noise for a
/// player that never opens a window surface here.
///
/// The directory is private: `$TMPDIR/pis-runtime-UID`, mode 0700, owned by the process's
/// user (a directory of that name owned by someone else, or readable by others, is not used;
/// a fresh `pis-runtime-UID-PID` is made instead). Done once per process.
///
/// Thread safety: setting an environment variable races with threads that read the
/// environment through libc at the same time. It runs once, before the instance (and so
/// before any driver thread) exists; the callers create the `Gpu` before they start threads
/// that read the environment. The variable is only set when it is absent, so an
/// environment that provides it is untouched.
fn ensure_runtime_dir() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        if std::env::var_os("XDG_RUNTIME_DIR").is_some_and(|v| !v.is_empty()) {
            return;
        }
        if let Some(dir) = private_runtime_dir() {
            // Edition 2021: `set_var` is a safe function; see the note above on threads.
            std::env::set_var("XDG_RUNTIME_DIR", dir);
        }
    });
}

#[cfg(unix)]
fn private_runtime_dir() -> Option<std::path::PathBuf> {
    use std::os::unix::fs::{DirBuilderExt, MetadataExt, PermissionsExt};
    let uid = std::fs::metadata("/proc/self").map(|m| m.uid()).ok();
    let base = std::env::temp_dir();
    let private = |p: &std::path::Path| {
        std::fs::symlink_metadata(p).is_ok_and(|m| {
            m.is_dir()
                && Some(m.uid()) == uid.or(Some(m.uid()))
                && m.permissions().mode() & 0o077 == 0
        })
    };
    let mut candidates = Vec::new();
    if let Some(u) = uid {
        candidates.push(base.join(format!("pis-runtime-{u}")));
    }
    candidates.push(base.join(format!("pis-runtime-{}-{}", uid.unwrap_or(0), std::process::id())));
    for dir in candidates {
        let _ = std::fs::DirBuilder::new().mode(0o700).create(&dir);
        if private(&dir) {
            return Some(dir);
        }
    }
    None
}

#[cfg(not(unix))]
fn private_runtime_dir() -> Option<std::path::PathBuf> {
    None
}

impl Gpu {
    /// Opens the default adapter (high-performance preference; Mesa's lavapipe on a machine
    /// without a GPU) with default options.
    pub fn new() -> Result<Gpu, PlayError> {
        Gpu::with_options(GpuOptions::default())
    }

    /// Opens the default adapter.
    pub fn with_options(options: GpuOptions) -> Result<Gpu, PlayError> {
        let instance = Gpu::instance();
        Gpu::open(&instance, None, options).map(|(gpu, _)| gpu)
    }

    /// The wgpu instance the player opens adapters from (backends from `WGPU_BACKEND`, else
    /// all that are built in), after giving the process an `XDG_RUNTIME_DIR` where none is
    /// set. A window creates its surface from this instance, then calls [`Gpu::for_surface`].
    pub fn instance() -> wgpu::Instance {
        ensure_runtime_dir();
        wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env())
    }

    /// Opens an adapter of `instance` that can present to `surface` (a window's), so that the
    /// player's frames can be drawn straight into the window's surface textures; also returns
    /// what the surface supports on that adapter (formats, present and alpha modes).
    pub fn for_surface(
        instance: &wgpu::Instance,
        surface: &wgpu::Surface<'_>,
        options: GpuOptions,
    ) -> Result<(Gpu, wgpu::SurfaceCapabilities), PlayError> {
        let (gpu, adapter) = Gpu::open(instance, Some(surface), options)?;
        let caps = surface.get_capabilities(&adapter);
        Ok((gpu, caps))
    }

    fn open(
        instance: &wgpu::Instance,
        surface: Option<&wgpu::Surface<'_>>,
        options: GpuOptions,
    ) -> Result<(Gpu, wgpu::Adapter), PlayError> {
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            force_fallback_adapter: false,
            compatible_surface: surface,
            apply_limit_buckets: false,
        }))
        .map_err(|e| PlayError::NoAdapter(e.to_string()))?;
        let info = adapter.get_info();
        let full = adapter.features().contains(wgpu::Features::FLOAT32_FILTERABLE)
            && !options.half_textures;
        let (texture_format, features) = if full {
            (wgpu::TextureFormat::Rgba32Float, wgpu::Features::FLOAT32_FILTERABLE)
        } else {
            (wgpu::TextureFormat::Rgba16Float, wgpu::Features::empty())
        };
        // Float32 blending lets the player add layers in an Rgba32Float frame (else it
        // accumulates in Rgba16Float).
        let features = features | (adapter.features() & wgpu::Features::FLOAT32_BLENDABLE);
        // The adapter's own format features (multisampled Rgba32Float and R32Uint targets,
        // which WebGPU does not guarantee) where it reports them.
        let features = features
            | (adapter.features() & wgpu::Features::TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES);
        let limits = adapter.limits();
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("pis-play"),
            required_features: features,
            required_limits: limits.clone(),
            ..Default::default()
        }))
        .map_err(|e| PlayError::Device { adapter: info.name.clone(), message: e.to_string() })?;
        let cube_format = wgpu::TextureFormat::Rgba32Float;
        let gpu = Gpu {
            device,
            queue,
            info,
            limits,
            texture_format,
            cube_format,
            adapter: adapter.clone(),
        };
        Ok((gpu, adapter))
    }

    /// The same device with surface textures and cube maps in `Rgba16Float`: half the
    /// memory and upload of 32-bit floats, texels rounded to half floats (relative error
    /// ≤ 2^-11), for a file whose frames that leaves within its coding error.
    pub fn with_half_textures(&self) -> Gpu {
        Gpu {
            device: self.device.clone(),
            queue: self.queue.clone(),
            info: self.info.clone(),
            limits: self.limits.clone(),
            texture_format: wgpu::TextureFormat::Rgba16Float,
            cube_format: wgpu::TextureFormat::Rgba16Float,
            adapter: self.adapter.clone(),
        }
    }

    /// Whether surface textures and cube maps are both `Rgba16Float`.
    pub fn half_textures(&self) -> bool {
        self.texture_format == wgpu::TextureFormat::Rgba16Float
            && self.cube_format == wgpu::TextureFormat::Rgba16Float
    }

    /// What the device can do with `format`: the adapter's features where the device was
    /// given `TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES`, else those WebGPU guarantees.
    pub fn format_features(&self, format: wgpu::TextureFormat) -> wgpu::TextureFormatFeatures {
        if self.device.features().contains(wgpu::Features::TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES)
        {
            self.adapter.get_texture_format_features(format)
        } else {
            format.guaranteed_format_features(self.device.features())
        }
    }

    /// A one-line description of the adapter: name, backend, device type, driver.
    pub fn describe(&self) -> String {
        format!(
            "{} ({:?}, {:?}, {} {}; textures {:?})",
            self.info.name,
            self.info.backend,
            self.info.device_type,
            self.info.driver,
            self.info.driver_info,
            self.texture_format
        )
    }
}

/// A render pass into `color` and `depth`, both cleared (colour to transparent black, depth
/// to 1) and both stored: the one-pass frames of the shell and lens-object renderers.
pub fn cleared_pass<'e>(
    enc: &'e mut wgpu::CommandEncoder,
    label: &str,
    color: &wgpu::TextureView,
    depth: &wgpu::TextureView,
) -> wgpu::RenderPass<'e> {
    enc.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view: color,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                store: wgpu::StoreOp::Store,
            },
        })],
        depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
            view: depth,
            depth_ops: Some(wgpu::Operations {
                load: wgpu::LoadOp::Clear(1.0),
                store: wgpu::StoreOp::Store,
            }),
            stencil_ops: None,
        }),
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    })
}
