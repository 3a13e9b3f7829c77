//! Reading frames back: mapping a buffer the GPU filled, per-row padded readback of a target
//! texture, and colour bytes decoded into a [`FloatImage`].

use crate::error::PlayError;
use crate::gpu::Gpu;
use crate::image::FloatImage;

/// Maps a buffer the GPU has been told to fill and returns its bytes.
pub fn map_read(gpu: &Gpu, buffer: &wgpu::Buffer) -> Result<Vec<u8>, PlayError> {
    map_read_range(gpu, buffer, buffer.size(), None)
}

/// Maps the first `size` bytes of a buffer that submission `after` fills (`None`: the
/// latest submission) and returns them; later submissions, from other threads, are not
/// waited for.
pub fn map_read_range(
    gpu: &Gpu,
    buffer: &wgpu::Buffer,
    size: u64,
    after: Option<wgpu::SubmissionIndex>,
) -> Result<Vec<u8>, PlayError> {
    let (tx, rx) = std::sync::mpsc::channel();
    let slice = buffer.slice(..size);
    slice.map_async(wgpu::MapMode::Read, move |r| {
        let _ = tx.send(r);
    });
    gpu.device
        .poll(wgpu::PollType::Wait { submission_index: after, timeout: None })
        .map_err(|e| PlayError::Readback(e.to_string()))?;
    rx.recv()
        .map_err(|e| PlayError::Readback(e.to_string()))?
        .map_err(|e| PlayError::Readback(e.to_string()))?;
    let bytes = slice.get_mapped_range().map_err(|e| PlayError::Readback(e.to_string()))?.to_vec();
    buffer.unmap();
    Ok(bytes)
}

/// Readback buffers for a target texture of `texel_bytes` per texel.
pub struct Readback {
    buffer: wgpu::Buffer,
    row: u32,
    texel_bytes: u32,
    size: (u32, u32),
}

impl Readback {
    pub fn new(gpu: &Gpu, size: (u32, u32), texel_bytes: u32) -> Readback {
        let row = (size.0 * texel_bytes).div_ceil(256) * 256;
        let buffer = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback"),
            size: row as u64 * size.1 as u64,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        Readback { buffer, row, texel_bytes, size }
    }

    pub fn copy(&self, texture: &wgpu::Texture, encoder: &mut wgpu::CommandEncoder) {
        encoder.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                texture,
                mip_level: 0,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            wgpu::TexelCopyBufferInfo {
                buffer: &self.buffer,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(self.row),
                    rows_per_image: Some(self.size.1),
                },
            },
            wgpu::Extent3d { width: self.size.0, height: self.size.1, depth_or_array_layers: 1 },
        );
    }

    /// The rows, padding removed.
    pub fn read(&self, gpu: &Gpu) -> Result<Vec<u8>, PlayError> {
        let bytes = map_read(gpu, &self.buffer)?;
        let w = (self.size.0 * self.texel_bytes) as usize;
        let mut out = Vec::with_capacity(w * self.size.1 as usize);
        for y in 0..self.size.1 as usize {
            out.extend_from_slice(&bytes[y * self.row as usize..y * self.row as usize + w]);
        }
        Ok(out)
    }
}

/// Decodes colour readback bytes (`Rgba32Float` or `Rgba16Float`) into an image.
pub fn colour_image(bytes: &[u8], format: wgpu::TextureFormat, size: (u32, u32)) -> FloatImage {
    let rgba = if format == wgpu::TextureFormat::Rgba16Float {
        bytes
            .chunks_exact(2)
            .map(|b| half::f16::from_bits(u16::from_le_bytes([b[0], b[1]])).to_f32())
            .collect()
    } else {
        bytes.chunks_exact(4).map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect()
    };
    FloatImage { width: size.0, height: size.1, rgba }
}
