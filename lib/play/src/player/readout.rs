//! Where a frame goes once recorded: read back from the offscreen target (colour and, when
//! asked for, object indices), drawn offscreen and waited for (timings), or drawn into a
//! caller's view.

use std::time::Instant;

use super::options::FrameStats;
use crate::error::PlayError;
use crate::frame::{colour_image, Readback, Targets};
use crate::gpu::Gpu;
use crate::image::FloatImage;

/// An offscreen frame read back: colour and, when asked for, object indices.
pub(super) type Readout = (FloatImage, Option<Vec<u32>>);

/// Where a frame is drawn.
#[derive(Clone, Copy)]
pub(super) enum Target<'a> {
    /// The offscreen target, read back (with every pixel's object index if `ids`).
    Offscreen { ids: bool },
    /// The offscreen target drawn with one sample per pixel, read back with every pixel's
    /// object index.
    Centres,
    /// The offscreen target, drawn and waited for but not read back: a frame's cost as
    /// playback pays it, where the frame is shown rather than copied to memory.
    Timed,
    /// A caller's view of the given format.
    View(&'a wgpu::TextureView, wgpu::TextureFormat),
}

/// The readback buffers of offscreen frames: colour and object indices.
pub(super) type Readbacks = Option<(Readback, Readback)>;

/// Reads back the offscreen frame drawn into `targets` (of `format` and `size`): colour and,
/// with `ids`, object indices, through `readback` (made on first use).
pub(super) fn read_back(
    gpu: &Gpu,
    targets: &Targets,
    readback: &mut Readbacks,
    ids: bool,
    (format, size): (wgpu::TextureFormat, (u32, u32)),
    stats: &mut FrameStats,
) -> Result<Readout, PlayError> {
    let t_read = Instant::now();
    let texel = if format == wgpu::TextureFormat::Rgba16Float { 8 } else { 16 };
    let (rc, ri) = readback
        .get_or_insert_with(|| (Readback::new(gpu, size, texel), Readback::new(gpu, size, 4)));
    let mut copy = gpu
        .device
        .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("readback") });
    rc.copy(&targets.colour, &mut copy);
    if ids {
        ri.copy(&targets.ids, &mut copy);
    }
    gpu.queue.submit([copy.finish()]);
    let colour = colour_image(&rc.read(gpu)?, format, size);
    let ids = if ids {
        Some(
            ri.read(gpu)?
                .chunks_exact(4)
                .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
                .collect(),
        )
    } else {
        None
    };
    stats.readback_ms = t_read.elapsed().as_secs_f64() * 1e3;
    Ok((colour, ids))
}

/// Blocks until the GPU has finished everything submitted.
pub(super) fn wait_for_gpu(gpu: &Gpu) -> Result<(), PlayError> {
    gpu.device
        .poll(wgpu::PollType::wait_indefinitely())
        .map(|_| ())
        .map_err(|e| PlayError::Readback(e.to_string()))
}
