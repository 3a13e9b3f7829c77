//! The wgpu device the player draws with.

use crate::error::PlayError;

/// An adapter, its device and queue, and what the player needs from them.
pub struct Gpu {
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub info: wgpu::AdapterInfo,
    pub limits: wgpu::Limits,
}

impl Gpu {
    /// Opens the default adapter (high-performance preference; Mesa's lavapipe on a machine
    /// without a GPU). Requires `FLOAT32_FILTERABLE`: textures are `Rgba32Float` so that the
    /// texel values the model multiplies are the ones the sampler filters, bit for bit.
    pub fn new() -> Result<Gpu, PlayError> {
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            force_fallback_adapter: false,
            compatible_surface: None,
            apply_limit_buckets: false,
        }))
        .map_err(|e| PlayError::NoAdapter(e.to_string()))?;
        let info = adapter.get_info();
        if !adapter.features().contains(wgpu::Features::FLOAT32_FILTERABLE) {
            return Err(PlayError::Float32Filterable(info.name.clone()));
        }
        let limits = adapter.limits();
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("pis-play"),
            required_features: wgpu::Features::FLOAT32_FILTERABLE,
            required_limits: limits.clone(),
            ..Default::default()
        }))
        .map_err(|e| PlayError::Device { adapter: info.name.clone(), message: e.to_string() })?;
        Ok(Gpu { device, queue, info, limits })
    }

    /// A one-line description of the adapter: name, backend, device type, driver.
    pub fn describe(&self) -> String {
        format!(
            "{} ({:?}, {:?}, {} {})",
            self.info.name, self.info.backend, self.info.device_type, self.info.driver, self.info.driver_info
        )
    }
}
