//! One term of a lens object drawn through the frame's own path on its own, for the tests
//! that hold it against pis-compile's model of the player's lens term.

use pis_compile::hybrid::{Term, Tessellation};
use pis_compile::shell::Shell;

use super::draw::{MeshGpu, ObjectDraw};
use super::encode::{encode, FrameDraws, FrameTarget};
use super::hybrid::{corner_buffer, term_corners, LensDraw, MAX_LENS_SHELLS};
use super::pipelines::FramePipelines;
use super::readback::{colour_image, Readback};
use super::targets::{offscreen_format, Targets};
use crate::error::PlayError;
use crate::gpu::Gpu;
use crate::image::FloatImage;
use crate::shell::ShellTexture;

/// One term of the tessellated lens object `tess` drawn through the frame's own path
/// ([`encode`], one sample per pixel): the id pass of the tessellation, then
/// the term with `shells` (each its geometry, cube layout and RGBA texels: premultiplied
/// colour, then alpha), each looked up `lookups` × `lookups` times per pixel, at weight 1. Returns RGBA per pixel (rows from the top; alpha 1 where
/// the term is drawn). pis-compile's [`pis_compile::hybrid::term_radiance`] is its twin.
pub fn render_lens_term(
    gpu: &Gpu,
    viewport: pis_compile::Viewport,
    tess: &Tessellation,
    clip_from_world: glam::Mat4,
    term: Term,
    shells: &[(Shell, pis_compile::TextureLayout, &[f32])],
    lookups: u32,
) -> Result<FloatImage, PlayError> {
    if shells.is_empty() || shells.len() > MAX_LENS_SHELLS {
        return Err(PlayError::Request(format!(
            "{} shells: a lens term draws 1 to {MAX_LENS_SHELLS}",
            shells.len()
        )));
    }
    let size = (viewport.width, viewport.height);
    let mut pipes = FramePipelines::new(gpu);
    let mut targets = Targets::new(gpu, &pipes, size, 1)?;
    let mut cubes = Vec::with_capacity(shells.len());
    for (_, layout, rgba) in shells {
        let cube = ShellTexture::new(gpu, *layout, "lens object")?;
        cube.upload(gpu, rgba)?;
        cubes.push(cube);
    }
    let geometry: Vec<Shell> = shells.iter().map(|s| s.0.clone()).collect();
    let corners = term_corners(tess, term, &geometry);
    let buffer = corner_buffer(gpu, &corners);
    let positions: Vec<[f32; 3]> = tess.vertices.iter().map(|v| v.position.to_array()).collect();
    let indices: Vec<u32> = tess.triangles.iter().flatten().copied().collect();
    let mesh = MeshGpu::new(gpu, &positions, None, &vec![[0.0; 2]; positions.len()], &indices);
    let objects = [ObjectDraw {
        object: 0,
        mesh: &mesh,
        clip_from_object: clip_from_world,
        translucent: false,
    }];
    let lenses = [LensDraw {
        object: 0,
        clip_from_world,
        weight: 1.0,
        corners: &buffer,
        count: corners.len() as u32,
        shells: cubes.iter().map(|c| (c, lookups)).collect(),
    }];
    let format = offscreen_format(gpu);
    let view = targets.colour.create_view(&Default::default());
    let mut encoder = gpu
        .device
        .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("lens term") });
    let target = FrameTarget { colour: &view, format, object_ids: false, display: None };
    let frame = FrameDraws { objects: &objects, layers: &[], reflections: &[], lenses: &lenses };
    encode(gpu, &mut pipes, &mut targets, target, frame, &mut encoder);
    let texel = if format == wgpu::TextureFormat::Rgba16Float { 8 } else { 16 };
    let readback = Readback::new(gpu, size, texel);
    readback.copy(&targets.colour, &mut encoder);
    gpu.queue.submit([encoder.finish()]);
    Ok(colour_image(&readback.read(gpu)?, format, size))
}
