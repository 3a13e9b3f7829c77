//! The window's surface: a swap chain of textures the player draws into, viewed with an sRGB
//! format so that the player's linear radiance is encoded for display by the hardware.

use std::sync::Arc;

use winit::window::Window;

/// A configured surface and the format its textures are drawn through.
pub struct WindowSurface {
    pub surface: wgpu::Surface<'static>,
    pub config: wgpu::SurfaceConfiguration,
    /// The format of the views frames are drawn into: sRGB (the surface's own format, or its
    /// sRGB twin as a view format where the surface offers only a linear one).
    pub view_format: wgpu::TextureFormat,
}

/// Picks the surface format and the view format: an sRGB surface format if the surface has
/// one, else its first format viewed through the sRGB twin.
pub fn choose_formats(
    formats: &[wgpu::TextureFormat],
) -> Option<(wgpu::TextureFormat, wgpu::TextureFormat)> {
    if let Some(&f) = formats.iter().find(|f| f.is_srgb()) {
        return Some((f, f));
    }
    let f = *formats.first()?;
    Some((f, f.add_srgb_suffix()))
}

impl WindowSurface {
    /// Configures `surface` for `window` on `device`. `vsync` false asks for a present mode
    /// that does not wait for the display (to measure how fast frames are drawn).
    pub fn new(
        surface: wgpu::Surface<'static>,
        adapter_caps: wgpu::SurfaceCapabilities,
        device: &wgpu::Device,
        window: &Arc<Window>,
        vsync: bool,
    ) -> Result<WindowSurface, String> {
        let (format, view_format) = choose_formats(&adapter_caps.formats)
            .ok_or("the window surface offers no texture format")?;
        let size = window.inner_size();
        let config = wgpu::SurfaceConfiguration {
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            format,
            color_space: wgpu::SurfaceColorSpace::Auto,
            width: size.width.max(1),
            height: size.height.max(1),
            present_mode: if vsync {
                wgpu::PresentMode::AutoVsync
            } else {
                wgpu::PresentMode::AutoNoVsync
            },
            desired_maximum_frame_latency: 2,
            alpha_mode: adapter_caps
                .alpha_modes
                .first()
                .copied()
                .unwrap_or(wgpu::CompositeAlphaMode::Auto),
            view_formats: if view_format != format { vec![view_format] } else { Vec::new() },
        };
        surface.configure(device, &config);
        Ok(WindowSurface { surface, config, view_format })
    }

    /// Follows a window resize (a zero size, a minimized window, keeps the old one).
    pub fn resize(&mut self, device: &wgpu::Device, width: u32, height: u32) {
        if width > 0 && height > 0 {
            self.config.width = width;
            self.config.height = height;
            self.surface.configure(device, &self.config);
        }
    }

    /// Reconfigures after the surface was lost or became outdated.
    pub fn reconfigure(&self, device: &wgpu::Device) {
        self.surface.configure(device, &self.config);
    }

    pub fn size(&self) -> (u32, u32) {
        (self.config.width, self.config.height)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use wgpu::TextureFormat as F;

    #[test]
    fn an_srgb_format_is_preferred_and_a_linear_one_viewed_as_srgb() {
        assert_eq!(
            choose_formats(&[F::Bgra8Unorm, F::Bgra8UnormSrgb]),
            Some((F::Bgra8UnormSrgb, F::Bgra8UnormSrgb))
        );
        assert_eq!(choose_formats(&[F::Rgba8Unorm]), Some((F::Rgba8Unorm, F::Rgba8UnormSrgb)));
        assert_eq!(choose_formats(&[]), None);
    }
}
