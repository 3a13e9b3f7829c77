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
            m.is_dir() && Some(m.uid()) == uid.or(Some(m.uid())) && m.permissions().mode() & 0o077 == 0
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
        ensure_runtime_dir();
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            force_fallback_adapter: false,
            compatible_surface: None,
            apply_limit_buckets: false,
        }))
        .map_err(|e| PlayError::NoAdapter(e.to_string()))?;
        let info = adapter.get_info();
        let full = adapter.features().contains(wgpu::Features::FLOAT32_FILTERABLE) && !options.half_textures;
        let (texture_format, features) = if full {
            (wgpu::TextureFormat::Rgba32Float, wgpu::Features::FLOAT32_FILTERABLE)
        } else {
            (wgpu::TextureFormat::Rgba16Float, wgpu::Features::empty())
        };
        // Float32 blending lets the player add layers in an Rgba32Float frame (else it
        // accumulates in Rgba16Float).
        let features = features | (adapter.features() & wgpu::Features::FLOAT32_BLENDABLE);
        let limits = adapter.limits();
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("pis-play"),
            required_features: features,
            required_limits: limits.clone(),
            ..Default::default()
        }))
        .map_err(|e| PlayError::Device { adapter: info.name.clone(), message: e.to_string() })?;
        Ok(Gpu { device, queue, info, limits, texture_format })
    }

    /// A one-line description of the adapter: name, backend, device type, driver.
    pub fn describe(&self) -> String {
        format!(
            "{} ({:?}, {:?}, {} {}; textures {:?})",
            self.info.name, self.info.backend, self.info.device_type, self.info.driver, self.info.driver_info, self.texture_format
        )
    }
}
