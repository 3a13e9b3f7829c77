//! The GPU rebuild of textures (rebuild.wgsl) against the workers' rebuild it replaces
//! (decode.rs): surface textures against `assemble` with pis-format's decimated MIP chain,
//! every level of the padded layout, for 1 to 4 channels, one to five pyramid levels, odd
//! and power-of-two sizes, and the three gamma paths (identity, the default 2.2's
//! `pow_11_5`, a general power); shells' cube maps against `assemble_cube`, every face and
//! level, with stored MIP levels (all of them or the finest few) and decimated ones, and
//! their atlases' borders against the CPU's bit for bit (cube_atlas.rs). Each from level
//! images of 32-bit floats and of 16 bits a value (`LevelRebuild::new(gpu, true)`), against
//! the workers' rebuild of the same level images as 16 bits read back (pis-format's
//! `Level16`). Sums alone are bit-exact; with an inverse gamma the GPU's division and power
//! may round differently, held to 90 dB.

mod common;

use std::sync::Arc;

use common::*;
use pis_format::mip::{decimate, mip_size};
use pis_format::precision::Level16;
use pis_format::texture::LevelLayout;
use pis_format::{Combine, DepMask, Layer, LayerKind, Mapping, MipMode, StreamRef, Term};
use pis_play::decode::{assemble, assemble_cube, AssembleJob};
use pis_play::mip::{read_levels, MipBuilder};
use pis_play::rebuild::{LevelRebuild, LevelStack};
use pis_play::shell::{read_atlas, read_cube};
use pis_play::{Gpu, ShellTexture};

fn surface_layer(channels: u8, gamma: f32) -> Layer<StreamRef> {
    layer(Mapping::Surface, channels, MipMode::Decimated, gamma)
}

fn layer(mapping: Mapping, channels: u8, mip_mode: MipMode, gamma: f32) -> Layer<StreamRef> {
    Layer {
        kind: LayerKind::Diffuse,
        mapping,
        channels,
        mip_mode,
        term: Term::Reflection,
        order: 0,
        combine: Combine::Over,
        basis: 0,
        gamma,
        depends_on: DepMask::NONE,
        blocks: vec![],
    }
}

/// Level images of `n` values, top first: the top in [0, 1), the finer ones residuals of
/// either sign (some sums fall below zero, which the inverse gamma keeps signed).
fn level_images(n: usize, count: usize, seed: u64) -> Vec<Vec<f32>> {
    (0..count)
        .map(|k| {
            let r = random(n, seed + k as u64);
            if k == 0 {
                r
            } else {
                r.iter().map(|v| (v - 0.5) * 0.3).collect()
            }
        })
        .collect()
}

/// `images` as the GPU rebuild reads them: as they are, or held in 16 bits a value.
fn as_read(images: Vec<Vec<f32>>, level16: bool) -> Vec<Vec<f32>> {
    match level16 {
        true => images.iter().map(|img| Level16::of(img).expect("finite").values()).collect(),
        false => images,
    }
}

/// The workers' texture as the GPU holds it: the padded finest level from `assemble`, then
/// each coarser level decimated from the used region and padded the same way.
fn cpu_levels(job: &AssembleJob, padded: &[(u32, u32)]) -> Vec<Vec<f32>> {
    let finest = assemble(job);
    let (w, h) = (finest.width, finest.height);
    let used: Vec<f32> = (0..h)
        .flat_map(|j| {
            let row = (j * finest.padded_width * 4) as usize;
            finest.rgba[row..row + (w * 4) as usize].to_vec()
        })
        .collect();
    let mut level = used;
    let mut out = Vec::new();
    for (m, &(gw, gh)) in padded.iter().enumerate() {
        let m = m as u32;
        if m > 0 {
            let (sw, sh) = mip_size(w, h, m - 1);
            level = decimate(&level, sw, sh, 4);
        }
        let (uw, uh) = mip_size(w, h, m);
        let mut img = vec![0.0f32; (gw * gh * 4) as usize];
        for j in 0..gh {
            for i in 0..gw {
                let s = ((j.min(uh - 1) * uw + i.min(uw - 1)) * 4) as usize;
                let d = ((j * gw + i) * 4) as usize;
                img[d..d + 4].copy_from_slice(&level[s..s + 4]);
            }
        }
        out.push(img);
    }
    out
}

#[test]
fn the_gpu_rebuild_equals_the_workers_rebuild() {
    let Some(gpu) = gpu_or_skip("the_gpu_rebuild_equals_the_workers_rebuild") else { return };
    let mips = MipBuilder::new(&gpu);
    let exact_format = gpu.texture_format == wgpu::TextureFormat::Rgba32Float;
    for half in [false, true] {
        let rebuild = LevelRebuild::new(&gpu, half);
        surfaces_against_the_workers(&gpu, &mips, (&rebuild, half), exact_format);
    }
}

fn surfaces_against_the_workers(
    gpu: &Gpu,
    mips: &MipBuilder,
    (rebuild, half): (&LevelRebuild, bool),
    exact_format: bool,
) {
    let cases: [(u32, u32, u8, usize, f32); 7] = [
        (13, 7, 3, 3, 2.2),
        (16, 16, 3, 1, 2.2),
        (37, 20, 4, 5, 2.2),
        (1, 5, 1, 2, 2.2),
        (9, 9, 2, 4, 1.0),
        (64, 32, 3, 4, 1.0),
        (21, 11, 3, 3, 1.8),
    ];
    for (seed, (w, h, c, count, gamma)) in cases.into_iter().enumerate() {
        let what = format!("{w}x{h}, {c} channels, {count} levels, gamma {gamma}, 16-bit {half}");
        let layer = surface_layer(c, gamma);
        let layout = LevelLayout { width: w, height: h, channels: c as u32, faces: 1, mips: 1 };
        let images = level_images((w * h * c as u32) as usize, count, 17 * seed as u64);
        let texture = mips.texture(gpu, pis_compile::TextureLayout::full(w, h));
        let buffers: Vec<wgpu::Buffer> =
            images.iter().map(|v| rebuild.level_buffer(gpu, v)).collect();
        let refs: Vec<&wgpu::Buffer> = buffers.iter().collect();
        let stack = LevelStack { levels: &refs, channels: c as u32, gamma };
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        rebuild.record(gpu, (&texture, &stack), mips, &mut enc);
        gpu.queue.submit([enc.finish()]);
        let got = read_levels(gpu, &texture).unwrap();
        let job = AssembleJob {
            layer: &layer,
            layout,
            levels: as_read(images, half).into_iter().map(Arc::new).collect(),
            drop_levels: 0,
        };
        let sizes: Vec<(u32, u32)> = got.iter().map(|(gw, gh, _)| (*gw, *gh)).collect();
        let want = cpu_levels(&job, &sizes);
        assert_eq!(got.len(), want.len(), "{what}: level count");
        for (m, ((_, _, g), wl)) in got.iter().zip(&want).enumerate() {
            if exact_format && gamma == 1.0 {
                assert_eq!(g, wl, "{what}, level {m}: the sums differ");
            } else {
                let p = psnr(g, wl);
                eprintln!("{what}, level {m}: {p:.1} dB");
                assert!(p >= 90.0, "{what}, level {m}: {p:.1} dB from the workers' rebuild");
            }
        }
    }
}

#[test]
fn the_gpu_rebuild_of_cube_maps_equals_the_workers_rebuild() {
    let name = "the_gpu_rebuild_of_cube_maps_equals_the_workers_rebuild";
    let Some(gpu) = gpu_or_skip(name) else { return };
    for half in [false, true] {
        cubes_against_the_workers(&gpu, &LevelRebuild::new(&gpu, half), half);
    }
}

fn cubes_against_the_workers(gpu: &Gpu, rebuild: &LevelRebuild, half: bool) {
    // (face size, channels, stored MIP levels (0: every level), decimated, pyramid levels, gamma)
    let cases: [(u32, u8, u32, bool, usize, f32); 6] = [
        (5, 4, 0, false, 3, 2.2),
        (8, 3, 0, false, 2, 2.2),
        (6, 3, 2, false, 4, 2.2),
        (7, 4, 1, true, 3, 2.2),
        (16, 4, 0, false, 3, 1.0),
        (9, 3, 0, false, 2, 1.8),
    ];
    for (seed, (n, c, mips, decimated, count, gamma)) in cases.into_iter().enumerate() {
        let mips = match (decimated, mips) {
            (true, _) => 1,
            (false, 0) => pis_format::mip::mip_count(n, n),
            (false, m) => m,
        };
        let mode = if decimated { MipMode::Decimated } else { MipMode::Stored };
        let what = format!(
            "{n}² × 6, {c} channels, {mips} stored levels, {mode:?}, {count} levels, gamma {gamma}, 16-bit {half}"
        );
        let layer = layer(Mapping::Shell, c, mode, gamma);
        let layout = LevelLayout { width: n, height: n, channels: c as u32, faces: 6, mips };
        let values: usize =
            layout.planes().iter().map(|p| (p.width * p.height * p.channels) as usize).sum();
        let images = level_images(values, count, 31 * seed as u64 + 5);
        let buffers: Vec<wgpu::Buffer> =
            images.iter().map(|v| rebuild.level_buffer(gpu, v)).collect();
        let refs: Vec<&wgpu::Buffer> = buffers.iter().collect();
        let stack = LevelStack { levels: &refs, channels: c as u32, gamma };
        let job = AssembleJob {
            layer: &layer,
            layout: layout.clone(),
            levels: as_read(images, half).into_iter().map(Arc::new).collect(),
            drop_levels: 0,
        };
        let want = assemble_cube(&job);
        let cube = ShellTexture::new(gpu, want.layout, "test").unwrap();
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        rebuild.record_cube(gpu, (&cube, &stack), &layout, &mut enc);
        gpu.queue.submit([enc.finish()]);
        let got = read_cube(gpu, &cube).unwrap();
        let want_rgba = want.rgba();
        assert_eq!(got.len(), want_rgba.len(), "{what}: texel count");
        // The border pass writes the borders the CPU writes for uploaded cube maps.
        let bordered = cube.atlas.border(&cube.layout, &got);
        assert_eq!(read_atlas(gpu, &cube).unwrap(), bordered, "{what}: the borders differ");
        if gamma == 1.0 {
            assert_eq!(got, want_rgba, "{what}: the sums differ");
        } else {
            let p = psnr(&got, &want_rgba);
            eprintln!("{what}: {p:.1} dB");
            assert!(p >= 90.0, "{what}: {p:.1} dB from the workers' rebuild");
        }
    }
}
