//! Float images read back from the GPU, and their comparison.

/// An RGBA f32 image, rows from the top.
#[derive(Clone, Debug, PartialEq)]
pub struct FloatImage {
    pub width: u32,
    pub height: u32,
    pub rgba: Vec<f32>,
}

impl FloatImage {
    /// RGBA of pixel `p = y · width + x`.
    pub fn pixel(&self, p: usize) -> [f32; 4] {
        [self.rgba[4 * p], self.rgba[4 * p + 1], self.rgba[4 * p + 2], self.rgba[4 * p + 3]]
    }
}

/// Finishes `enc` with a copy of the Rgba32Float texture `color` (`viewport`-sized), submits
/// it and reads the pixels back.
pub fn read_back(
    gpu: &crate::Gpu,
    mut enc: wgpu::CommandEncoder,
    color: &wgpu::Texture,
    viewport: pis_compile::Viewport,
) -> Result<FloatImage, crate::PlayError> {
    let (w, h) = (viewport.width, viewport.height);
    let row_bytes = (w * 16).div_ceil(256) * 256;
    let readback = gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback"),
        size: row_bytes as u64 * h as u64,
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    enc.copy_texture_to_buffer(
        wgpu::TexelCopyTextureInfo {
            texture: color,
            mip_level: 0,
            origin: wgpu::Origin3d::ZERO,
            aspect: wgpu::TextureAspect::All,
        },
        wgpu::TexelCopyBufferInfo {
            buffer: &readback,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(row_bytes),
                rows_per_image: Some(h),
            },
        },
        wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 },
    );
    gpu.queue.submit([enc.finish()]);
    map_rows(gpu, &readback, row_bytes, w, h)
}

/// Maps a readback buffer of `h` rows of `row_bytes` and returns its first `w` RGBA f32
/// pixels per row.
pub fn map_rows(
    gpu: &crate::Gpu,
    readback: &wgpu::Buffer,
    row_bytes: u32,
    w: u32,
    h: u32,
) -> Result<FloatImage, crate::PlayError> {
    use crate::PlayError;
    let (tx, rx) = std::sync::mpsc::channel();
    readback.slice(..).map_async(wgpu::MapMode::Read, move |r| {
        let _ = tx.send(r);
    });
    gpu.device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| PlayError::Readback(e.to_string()))?;
    rx.recv()
        .map_err(|e| PlayError::Readback(e.to_string()))?
        .map_err(|e| PlayError::Readback(e.to_string()))?;
    let mut rgba = Vec::with_capacity(w as usize * h as usize * 4);
    {
        let view = readback
            .slice(..)
            .get_mapped_range()
            .map_err(|e| PlayError::Readback(e.to_string()))?;
        for y in 0..h as usize {
            let row = &view[y * row_bytes as usize..y * row_bytes as usize + w as usize * 16];
            rgba.extend(row.chunks_exact(4).map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]])));
        }
    }
    readback.unmap();
    Ok(FloatImage { width: w, height: h, rgba })
}
