//! Shared test scenes for the GPU tests: a UV sphere, an occluder, random textures, PSNR,
//! and the adapter policy (fail in CI, skip locally).

#![allow(dead_code)]

use std::f32::consts::PI;
use std::path::PathBuf;

use glam::{DVec3, Mat4, Vec3};
use pis_compile::shell::{DepthCube, Shell, ShellShape};
use pis_compile::transform::{look_at, perspective};
use pis_compile::{RenderMatrix, Viewport};
use pis_play::{FloatImage, Gpu};

/// The GPU, or `None` with a printed reason when there is none and this is not CI. In CI
/// (`CI=true`) a missing adapter fails the test.
pub fn gpu_or_skip(test: &str) -> Option<Gpu> {
    gpu_with_or_skip(test, pis_play::GpuOptions::default())
}

/// [`gpu_or_skip`] with options.
pub fn gpu_with_or_skip(test: &str, options: pis_play::GpuOptions) -> Option<Gpu> {
    match Gpu::with_options(options) {
        Ok(g) => {
            eprintln!("{test}: adapter {}", g.describe());
            Some(g)
        }
        Err(e) if std::env::var("CI").map(|v| v == "true").unwrap_or(false) => {
            panic!("{test}: {e}")
        }
        Err(e) => {
            eprintln!("{test}: skipped: {e}");
            None
        }
    }
}

/// A UV sphere of radius 1: u = longitude / 2π, v = colatitude / π (v = 0 at +y).
pub struct Mesh {
    pub positions: Vec<[f32; 3]>,
    pub uvs: Vec<[f32; 2]>,
    pub indices: Vec<u32>,
}

pub fn uv_sphere(slices: u32, stacks: u32) -> Mesh {
    let mut m = Mesh { positions: vec![], uvs: vec![], indices: vec![] };
    for j in 0..=stacks {
        let v = j as f32 / stacks as f32;
        let th = v * PI;
        for i in 0..=slices {
            let u = i as f32 / slices as f32;
            let ph = u * 2.0 * PI;
            m.positions.push([th.sin() * ph.cos(), th.cos(), -th.sin() * ph.sin()]);
            m.uvs.push([u, v]);
        }
    }
    let row = slices + 1;
    for j in 0..stacks {
        for i in 0..slices {
            let (a, b, c, d) =
                (j * row + i, j * row + i + 1, (j + 1) * row + i + 1, (j + 1) * row + i);
            m.indices.extend([a, b, c, a, c, d]);
        }
    }
    m
}

/// A quad occluder in the plane z = `z`, x ∈ [x0, x1], y ∈ [y0, y1].
pub fn quad(x0: f32, x1: f32, y0: f32, y1: f32, z: f32) -> Mesh {
    Mesh {
        positions: vec![[x0, y0, z], [x1, y0, z], [x1, y1, z], [x0, y1, z]],
        uvs: vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]],
        indices: vec![0, 1, 2, 0, 2, 3],
    }
}

/// A camera: clip-from-world of a perspective view at `eye` looking at `target`.
pub fn camera(vp: Viewport, eye: [f32; 3], target: [f32; 3], fovy: f32) -> Mat4 {
    perspective(fovy, vp.width as f32 / vp.height as f32, 0.1, 50.0)
        * look_at(Vec3::from(eye), Vec3::from(target), Vec3::Y)
}

/// Deterministic random values in [0, 1) (xorshift).
pub fn random(n: usize, seed: u64) -> Vec<f32> {
    let mut s = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    (0..n)
        .map(|_| {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 40) as f32 / (1u64 << 24) as f32
        })
        .collect()
}

/// An RGBA texture (4 values per texel, alpha 1) with independent random R, G, B.
pub fn random_rgba(texels: usize, seed: u64) -> Vec<f32> {
    let r = random(texels * 3, seed);
    (0..texels).flat_map(|t| [r[3 * t], r[3 * t + 1], r[3 * t + 2], 1.0]).collect()
}

/// A·x per channel for an RGBA texture: the image the model predicts (alpha = coverage).
pub fn predict(a: &RenderMatrix, rgba: &[f32]) -> FloatImage {
    let mut img = FloatImage {
        width: a.width,
        height: a.height,
        rgba: vec![0.0; a.width as usize * a.height as usize * 4],
    };
    for r in 0..a.rows() {
        let (c, v) = a.row(r);
        let p = a.pixels[r] as usize;
        for ch in 0..3 {
            img.rgba[4 * p + ch] =
                c.iter().zip(v).map(|(&c, &v)| v * rgba[4 * c as usize + ch]).sum();
        }
        img.rgba[4 * p + 3] = a.coverage[r];
    }
    img
}

/// The comparison of two renderings over the pixels both cover.
#[derive(Debug)]
pub struct Comparison {
    pub psnr_db: f64,
    pub both: usize,
    /// Pixels covered in one rendering only.
    pub coverage_mismatch: usize,
}

pub fn compare(want: &FloatImage, got: &FloatImage) -> Comparison {
    let (mut se, mut n, mut mismatch) = (0.0f64, 0usize, 0usize);
    for p in 0..(want.width * want.height) as usize {
        let (a, b) = (want.pixel(p), got.pixel(p));
        match (a[3] > 0.5, b[3] > 0.5) {
            (true, true) => {
                for ch in 0..3 {
                    se += ((a[ch] - b[ch]) as f64).powi(2);
                }
                n += 3;
            }
            (false, false) => {}
            _ => mismatch += 1,
        }
    }
    let mse = se / n.max(1) as f64;
    Comparison {
        psnr_db: if mse == 0.0 { f64::INFINITY } else { -10.0 * mse.log10() },
        both: n / 3,
        coverage_mismatch: mismatch,
    }
}

/// Writes `NAME-actual.png` (the GPU image) and `NAME-difference.png` (|want − got| × 64)
/// into the test output folder; returns the folder.
pub fn write_failure_images(name: &str, want: &FloatImage, got: &FloatImage) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"));
    let to8 = |v: f32| (v.clamp(0.0, 1.0) * 255.0 + 0.5) as u8;
    let (w, h) = (got.width, got.height);
    let actual = image::RgbImage::from_fn(w, h, |x, y| {
        let p = got.pixel((y * w + x) as usize);
        image::Rgb([to8(p[0]), to8(p[1]), to8(p[2])])
    });
    let diff = image::RgbImage::from_fn(w, h, |x, y| {
        let (a, b) = (want.pixel((y * w + x) as usize), got.pixel((y * w + x) as usize));
        if (a[3] > 0.5) != (b[3] > 0.5) {
            return image::Rgb([255, 0, 255]);
        }
        image::Rgb([0, 1, 2].map(|c| to8((a[c] - b[c]).abs() * 64.0)))
    });
    let _ = actual.save(dir.join(format!("{name}-actual.png")));
    let _ = diff.save(dir.join(format!("{name}-difference.png")));
    dir
}

/// A frame of `scene` (mesh, clip-from-object, texture; each its own object, drawn with the
/// identity affine and level 0) of `size` with `samples` per pixel, resolved with `display`
/// (None: the box): colour and object index per pixel, read back.
pub fn draw_scene(
    gpu: &Gpu,
    pipes: &mut pis_play::frame::FramePipelines,
    size: (u32, u32),
    samples: u32,
    display: Option<pis_format::DisplayFilter>,
    scene: &[(pis_play::frame::MeshGpu, Mat4, pis_play::ObjectTexture)],
    sampler: &wgpu::Sampler,
) -> (FloatImage, Vec<u32>) {
    draw_scene_with(gpu, pipes, (size, samples), display, scene, sampler, &[])
}

/// [`draw_scene`] with the objects `translucent` marks (missing entries: opaque) drawn as
/// translucent objects, their texture's alpha their opacity.
pub fn draw_scene_with(
    gpu: &Gpu,
    pipes: &mut pis_play::frame::FramePipelines,
    (size, samples): ((u32, u32), u32),
    display: Option<pis_format::DisplayFilter>,
    scene: &[(pis_play::frame::MeshGpu, Mat4, pis_play::ObjectTexture)],
    sampler: &wgpu::Sampler,
    translucent: &[bool],
) -> (FloatImage, Vec<u32>) {
    let is = |i: usize| translucent.get(i).copied().unwrap_or(false);
    use pis_play::frame::{
        colour_image, encode, offscreen_format, FrameDraws, FrameTarget, LayerDraw, ObjectDraw,
        Readback, Targets,
    };
    let format = offscreen_format(gpu);
    let mut targets = Targets::new(gpu, pipes, size, samples).unwrap();
    let objects: Vec<ObjectDraw> = scene
        .iter()
        .enumerate()
        .map(|(i, (mesh, clip, _))| ObjectDraw {
            object: i as u32,
            mesh,
            clip_from_object: *clip,
            translucent: is(i),
        })
        .collect();
    let layers: Vec<LayerDraw> = scene
        .iter()
        .enumerate()
        .map(|(i, (_, _, texture))| LayerDraw {
            draw: i,
            texture,
            sampler,
            transform: pis_compile::TextureTransform::IDENTITY,
            max_level: 0.0,
            weight: 1.0,
            tint: [1.0; 3],
            anisotropic: false,
            opacity: is(i),
        })
        .collect();
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    let view = targets.colour.create_view(&Default::default());
    let target = FrameTarget { colour: &view, format, object_ids: true, display };
    let frame = FrameDraws { objects: &objects, layers: &layers, reflections: &[], lenses: &[] };
    encode(gpu, pipes, &mut targets, target, frame, &mut encoder);
    let texel = if format == wgpu::TextureFormat::Rgba16Float { 8 } else { 16 };
    let (rc, ri) = (Readback::new(gpu, size, texel), Readback::new(gpu, size, 4));
    rc.copy(&targets.colour, &mut encoder);
    ri.copy(&targets.ids, &mut encoder);
    gpu.queue.submit([encoder.finish()]);
    let colour = colour_image(&rc.read(gpu).unwrap(), format, size);
    let ids = ri
        .read(gpu)
        .unwrap()
        .chunks_exact(4)
        .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect();
    (colour, ids)
}

/// One shell of each shape (SPEC.md 7.3) about a point near the origin, sized for the unit
/// test objects.
pub fn shells() -> Vec<(&'static str, Shell)> {
    let o = DVec3::new(0.05, -0.1, 0.02);
    vec![
        ("sphere", Shell { origin: o, shape: ShellShape::Sphere { radius: 3.0 } }),
        (
            "ellipsoid",
            Shell { origin: o, shape: ShellShape::Ellipsoid { radii: DVec3::new(1.6, 1.3, 1.5) } },
        ),
        (
            "box",
            Shell {
                origin: o,
                shape: ShellShape::Box {
                    min: DVec3::new(-3.0, -1.3, -4.0),
                    max: DVec3::new(4.0, 3.0, 3.5),
                },
            },
        ),
        (
            "cylinder",
            Shell {
                origin: o,
                shape: ShellShape::Cylinder { radius: 2.5, y_min: -1.3, y_max: 2.0 },
            },
        ),
        ("depth", Shell::depth(o, DepthCube::cast(o.as_vec3(), 24, 12.0, &depth_scene()), 24)),
    ]
}

/// The 12 triangles of the axis-aligned box between `lo` and `hi`.
pub fn box_triangles(lo: Vec3, hi: Vec3) -> Vec<[Vec3; 3]> {
    let c = |k: u32| {
        Vec3::new(
            if k & 1 == 0 { lo.x } else { hi.x },
            if k & 2 == 0 { lo.y } else { hi.y },
            if k & 4 == 0 { lo.z } else { hi.z },
        )
    };
    let quads =
        [[0, 2, 6, 4], [1, 5, 7, 3], [0, 4, 5, 1], [2, 3, 7, 6], [0, 1, 3, 2], [4, 6, 7, 5]];
    quads.iter().flat_map(|q| [[c(q[0]), c(q[1]), c(q[2])], [c(q[0]), c(q[2]), c(q[3])]]).collect()
}

/// What the depth shell of [`shells`] is cast from: a room with a crate on its floor beside
/// the object and a column behind it, so reflection rays stop at several depths.
pub fn depth_scene() -> Vec<[Vec3; 3]> {
    let mut scene = box_triangles(Vec3::new(-3.0, -1.3, -4.0), Vec3::new(4.0, 3.0, 3.5));
    scene.extend(box_triangles(Vec3::new(1.3, -1.3, -0.6), Vec3::new(2.1, -0.5, 0.4)));
    scene.extend(box_triangles(Vec3::new(-1.2, -1.3, -2.6), Vec3::new(-0.7, 3.0, -2.1)));
    scene
}

/// A frame of one object (`mesh` at `clip`, one sample per pixel, the box resolve) drawn
/// with `layers` added, each a texture times its per-channel tint (a relightable layer's
/// coefficient weights, SPEC.md 9), with the identity affine and level 0.
pub fn draw_tinted(
    gpu: &Gpu,
    pipes: &mut pis_play::frame::FramePipelines,
    size: (u32, u32),
    (mesh, clip): (&pis_play::frame::MeshGpu, Mat4),
    layers: &[(&pis_play::ObjectTexture, [f32; 3])],
    sampler: &wgpu::Sampler,
) -> FloatImage {
    use pis_play::frame::{
        colour_image, encode, offscreen_format, FrameDraws, FrameTarget, LayerDraw, ObjectDraw,
        Readback, Targets,
    };
    let format = offscreen_format(gpu);
    let mut targets = Targets::new(gpu, pipes, size, 1).unwrap();
    let objects = [ObjectDraw { object: 0, mesh, clip_from_object: clip, translucent: false }];
    let layers: Vec<LayerDraw> = layers
        .iter()
        .map(|&(texture, tint)| LayerDraw {
            draw: 0,
            texture,
            sampler,
            transform: pis_compile::TextureTransform::IDENTITY,
            max_level: 0.0,
            weight: 1.0,
            tint,
            anisotropic: false,
            opacity: false,
        })
        .collect();
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    let view = targets.colour.create_view(&Default::default());
    let target = FrameTarget { colour: &view, format, object_ids: true, display: None };
    let frame = FrameDraws { objects: &objects, layers: &layers, reflections: &[], lenses: &[] };
    encode(gpu, pipes, &mut targets, target, frame, &mut encoder);
    let texel = if format == wgpu::TextureFormat::Rgba16Float { 8 } else { 16 };
    let rc = Readback::new(gpu, size, texel);
    rc.copy(&targets.colour, &mut encoder);
    gpu.queue.submit([encoder.finish()]);
    colour_image(&rc.read(gpu).unwrap(), format, size)
}

/// PSNR of `a` against `b` (peak 1; infinite where they are equal).
pub fn psnr(a: &[f32], b: &[f32]) -> f64 {
    let mse = a.iter().zip(b).map(|(x, y)| (*x as f64 - *y as f64).powi(2)).sum::<f64>()
        / a.len().max(1) as f64;
    if mse == 0.0 {
        f64::INFINITY
    } else {
        -10.0 * mse.log10()
    }
}
