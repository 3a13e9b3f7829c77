//! Relighting on the GPU against the hardware model (SPEC.md 9; Wong et al.): a relightable
//! layer's coefficient textures x_c under a set of lights (two coloured directional lights
//! and a sky, weighted by [`pis_compile::relight::Lights::weights`], the player's own
//! function; weights of either sign, as the basis gives them), against the model's
//! Σ_c w_c · A·x_c: drawn coefficient by coefficient through the frame pipeline, each times
//! its weight; and summed first by the player's `relit.wgsl`, against its Rust twin
//! `sum_coefficients`, then drawn once. Runs on Mesa's lavapipe in CI.

mod common;

use common::*;
use glam::{Mat4, Vec3};
use pis_compile::relight::{project_lat_long, sum_coefficients, DirectionalLight, Lights};
use pis_compile::{
    render_matrix, Address, DrawMesh, Filter, Sampler, TextureLayout, TextureTransform,
    TexturedObject, Viewport,
};
use pis_play::frame::{FramePipelines, MeshGpu};
use pis_play::image::FloatImage;
use pis_play::mip::MipBuilder;
use pis_play::relit::RelitSum;
use pis_play::textured::create_sampler;
use pis_play::ObjectTexture;

/// A sphere seen in perspective, nine coefficient textures of one level (bilinear: the sum's
/// coarser levels are not the random textures' own) and the lights' weights over band 2.
struct Case {
    vp: Viewport,
    clip: Mat4,
    sphere: Mesh,
    layout: TextureLayout,
    sampler: Sampler,
    coefficients: Vec<Vec<f32>>,
    weights: Vec<[f64; 3]>,
}

impl Case {
    fn new() -> Case {
        let vp = Viewport { width: 160, height: 120 };
        let (w, h) = (32, 16);
        let mut sky = vec![0.2f32; w * h * 3];
        sky[(4 * w + 9) * 3..][..3].copy_from_slice(&[6.0, 4.0, 1.0]);
        let key = Vec3::new(0.5, 0.7, 0.3).normalize();
        let fill = Vec3::new(-0.6, 0.4, -0.2).normalize();
        let lights = Lights {
            directional: vec![
                DirectionalLight { direction: key, radiance: [2.5, 1.8, 1.1] },
                DirectionalLight { direction: fill, radiance: [0.4, 0.6, 1.6] },
            ],
            sky: Some(project_lat_long(w, h, &sky, 0.5, 2)),
        };
        let weights = lights.weights([3.0; 3], 2);
        assert!(weights.iter().flatten().any(|v| *v < 0.0), "the case needs negative weights");
        let layout = TextureLayout::new(90, 45, 1);
        let coefficients =
            (0..weights.len()).map(|c| random_rgba(layout.texel_count(), 11 + c as u64)).collect();
        Case {
            vp,
            clip: camera(vp, [0.4, 0.5, 2.6], [0.0, 0.0, 0.0], 0.9),
            sphere: uv_sphere(48, 24),
            layout,
            sampler: Sampler { filter: Filter::Bilinear, address: [Address::ClampToEdge; 2] },
            coefficients,
            weights,
        }
    }

    fn size(&self) -> (u32, u32) {
        (self.vp.width, self.vp.height)
    }

    fn mesh(&self, gpu: &pis_play::Gpu) -> MeshGpu {
        let s = &self.sphere;
        MeshGpu::new(gpu, &s.positions, None, &s.uvs, &s.indices)
    }

    /// The model: Σ_c w_c · A·x_c per channel.
    fn model(&self) -> FloatImage {
        let s = &self.sphere;
        let object = TexturedObject {
            mesh: DrawMesh {
                positions: &s.positions,
                uvs: &s.uvs,
                indices: &s.indices,
                clip_from_object: self.clip,
            },
            transform: TextureTransform::IDENTITY,
            layout: self.layout,
            sampler: self.sampler,
        };
        let a = render_matrix(self.vp, &object, None).unwrap();
        let mut want = predict(&a, &self.coefficients[0]);
        want.rgba.chunks_exact_mut(4).for_each(|p| p[..3].fill(0.0));
        for (x, wc) in self.coefficients.iter().zip(&self.weights) {
            let one = predict(&a, x);
            for (p, q) in want.rgba.chunks_exact_mut(4).zip(one.rgba.chunks_exact(4)) {
                for ch in 0..3 {
                    p[ch] += (wc[ch] * q[ch] as f64) as f32;
                }
            }
        }
        want
    }

    fn weights_f32(&self) -> Vec<[f32; 3]> {
        self.weights.iter().map(|w| w.map(|v| v as f32)).collect()
    }
}

/// Compares and reports; on failure writes the images and panics.
fn check(test: &str, want: &FloatImage, got: &FloatImage) {
    let c = compare(want, got);
    eprintln!(
        "{test}: PSNR {:.2} dB over {} pixels, {} coverage mismatches",
        c.psnr_db, c.both, c.coverage_mismatch
    );
    if c.psnr_db < 60.0 || c.coverage_mismatch * 1000 > c.both {
        let dir = write_failure_images(test, want, got);
        panic!("{test}: {c:?} (images in {})", dir.display());
    }
}

#[test]
fn relit_coefficient_layers_match_the_model() {
    let test = "relit_coefficient_layers_match_the_model";
    let Some(gpu) = gpu_or_skip(test) else { return };
    let case = Case::new();
    let textures: Vec<ObjectTexture> = case
        .coefficients
        .iter()
        .map(|x| {
            let t = ObjectTexture::new(&gpu, case.layout);
            t.upload(&gpu, x).unwrap();
            t
        })
        .collect();
    let weights = case.weights_f32();
    let layers: Vec<(&ObjectTexture, [f32; 3])> = textures.iter().zip(weights).collect();
    let mesh = case.mesh(&gpu);
    let mut pipes = FramePipelines::new(&gpu);
    let samp = create_sampler(&gpu, &case.sampler);
    let got = draw_tinted(&gpu, &mut pipes, case.size(), (&mesh, case.clip), &layers, &samp);
    check(test, &case.model(), &got);
}

#[test]
fn summed_coefficients_match_the_model() {
    let test = "summed_coefficients_match_the_model";
    let Some(gpu) = gpu_or_skip(test) else { return };
    let case = Case::new();
    let mips = MipBuilder::new(&gpu);
    let textures: Vec<ObjectTexture> = case
        .coefficients
        .iter()
        .map(|x| {
            let t = mips.texture(&gpu, case.layout);
            t.upload(&gpu, x).unwrap();
            t
        })
        .collect();
    let refs: Vec<&ObjectTexture> = textures.iter().collect();
    let weights = case.weights_f32();
    let summing = RelitSum::new(&gpu);
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    let array = summing.gather(&gpu, &refs, &mut encoder);
    // Summed into the texture of an earlier sum (as when a light moves), which every texel
    // of the new one overwrites.
    let earlier: Vec<[f32; 3]> = weights.iter().map(|w| w.map(|v| 1.0 - 2.0 * v)).collect();
    let first = summing.sum(&gpu, (&array, &earlier), (&mips, None), &mut encoder);
    let earlier_texture = first.texture.clone();
    let sum = summing.sum(&gpu, (&array, &weights), (&mips, Some(first)), &mut encoder);
    assert!(sum.texture == earlier_texture, "the sum did not reuse the earlier sum's texture");
    gpu.queue.submit([encoder.finish()]);
    // The finest level, texel by texel, against the Rust twin: the used region, and the
    // padding repeating its last column and row (a clamped lookup past the edge reads it).
    let (w, h) = (case.layout.width as usize, case.layout.height as usize);
    let xs: Vec<&[f32]> = case.coefficients.iter().map(|x| x.as_slice()).collect();
    let want = sum_coefficients(&xs, &weights);
    let (aw, ah, got) = &pis_play::mip::read_levels(&gpu, &sum).unwrap()[0];
    let (aw, ah) = (*aw as usize, *ah as usize);
    assert!(aw > w && ah > h, "the case needs padding");
    let (mut se, mut peak) = (0.0f64, 0.0f64);
    for y in 0..ah {
        for x in 0..aw {
            for ch in 0..3 {
                let at = (y.min(h - 1) * w + x.min(w - 1)) * 4 + ch;
                let (a, b) = (want[at], got[(y * aw + x) * 4 + ch]);
                se += ((a - b) as f64).powi(2);
                peak = peak.max(a.abs() as f64);
            }
        }
    }
    let texel_db = 10.0 * (peak * peak / (se / (aw * ah * 3) as f64).max(1e-30)).log10();
    eprintln!("{test}: the sum's texels {texel_db:.2} dB against the twin (peak {peak:.2})");
    assert!(texel_db >= 60.0, "{test}: the sum's texels at {texel_db:.2} dB");
    // The sum drawn once, against the model.
    let mesh = case.mesh(&gpu);
    let mut pipes = FramePipelines::new(&gpu);
    let samp = create_sampler(&gpu, &case.sampler);
    let layers = [(&sum, [1.0; 3])];
    let got = draw_tinted(&gpu, &mut pipes, case.size(), (&mesh, case.clip), &layers, &samp);
    check(test, &case.model(), &got);
}
