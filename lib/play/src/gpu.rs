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

impl Gpu {
    /// Opens the default adapter (high-performance preference; Mesa's lavapipe on a machine
    /// without a GPU) with default options.
    pub fn new() -> Result<Gpu, PlayError> {
        Gpu::with_options(GpuOptions::default())
    }

    /// Opens the default adapter.
    pub fn with_options(options: GpuOptions) -> Result<Gpu, PlayError> {
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
