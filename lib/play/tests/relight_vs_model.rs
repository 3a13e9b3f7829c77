//! Relighting on the GPU against the hardware model (SPEC.md 9; Wong et al.): a relightable
//! layer's coefficient textures x_c drawn through the player's frame pipeline, each times
//! its weight w_c for a set of lights (two coloured directional lights and a sky, by
//! [`pis_compile::relight::Lights::weights`], the player's own function), added; the model
//! predicts Σ_c w_c · A·x_c. Weights of either sign, as the basis gives them. Runs on Mesa's
//! lavapipe in CI.

mod common;

use common::*;
use glam::Vec3;
use pis_compile::relight::{project_lat_long, DirectionalLight, Lights};
use pis_compile::{
    render_matrix, Address, DrawMesh, Filter, Sampler, TextureLayout,
    TextureTransform, TexturedObject, Viewport,
};
use pis_play::frame::{FramePipelines, MeshGpu};
use pis_play::textured::create_sampler;
use pis_play::ObjectTexture;

#[test]
fn relit_coefficient_layers_match_the_model() {
    let test = "relit_coefficient_layers_match_the_model";
    let Some(gpu) = gpu_or_skip(test) else { return };
    let vp = Viewport { width: 160, height: 120 };
    let clip = camera(vp, [0.4, 0.5, 2.6], [0.0, 0.0, 0.0], 0.9);
    let sphere = uv_sphere(48, 24);
    let layout = TextureLayout::full(96, 48);
    let sampler = Sampler { filter: Filter::Bilinear, address: [Address::ClampToEdge; 2] };
    // Two coloured lights and a sky with a bright patch, over the band-2 basis (9 terms).
    let (w, h) = (32, 16);
    let mut sky = vec![0.2f32; w * h * 3];
    sky[(4 * w + 9) * 3..][..3].copy_from_slice(&[6.0, 4.0, 1.0]);
    let lights = Lights {
        directional: vec![
            DirectionalLight {
                direction: Vec3::new(0.5, 0.7, 0.3).normalize(),
                radiance: [2.5, 1.8, 1.1],
            },
            DirectionalLight {
                direction: Vec3::new(-0.6, 0.4, -0.2).normalize(),
                radiance: [0.4, 0.6, 1.6],
            },
        ],
        sky: Some(project_lat_long(w, h, &sky, 0.5, 2)),
    };
    let weights = lights.weights([3.0; 3], 2);
    assert!(weights.iter().flatten().any(|v| *v < 0.0), "the test needs negative weights");
    let coefficients: Vec<Vec<f32>> =
        (0..weights.len()).map(|c| random_rgba(layout.texel_count(), 11 + c as u64)).collect();
    // The model: Σ_c w_c · A·x_c per channel.
    let object = TexturedObject {
        mesh: DrawMesh {
            positions: &sphere.positions,
            uvs: &sphere.uvs,
            indices: &sphere.indices,
            clip_from_object: clip,
        },
        transform: TextureTransform::IDENTITY,
        layout,
        sampler,
    };
    let a = render_matrix(vp, &object, None).unwrap();
    let mut want = predict(&a, &coefficients[0]);
    want.rgba.chunks_exact_mut(4).for_each(|p| p[..3].fill(0.0));
    for (x, wc) in coefficients.iter().zip(&weights) {
        let one = predict(&a, x);
        for (p, q) in want.rgba.chunks_exact_mut(4).zip(one.rgba.chunks_exact(4)) {
            for ch in 0..3 {
                p[ch] += (wc[ch] * q[ch] as f64) as f32;
            }
        }
    }
    // The GPU: each coefficient texture one additive draw, tinted by its weight.
    let textures: Vec<ObjectTexture> = coefficients
        .iter()
        .map(|x| {
            let t = ObjectTexture::new(&gpu, layout);
            t.upload(&gpu, x).unwrap();
            t
        })
        .collect();
    let layers: Vec<(&ObjectTexture, [f32; 3])> =
        textures.iter().zip(&weights).map(|(t, wc)| (t, wc.map(|v| v as f32))).collect();
    let mesh = MeshGpu::new(&gpu, &sphere.positions, None, &sphere.uvs, &sphere.indices);
    let mut pipes = FramePipelines::new(&gpu);
    let samp = create_sampler(&gpu, &sampler);
    let got = draw_tinted(&gpu, &mut pipes, (vp.width, vp.height), (&mesh, clip), &layers, &samp);
    let c = compare(&want, &got);
    eprintln!(
        "{test}: PSNR {:.2} dB over {} pixels, {} coverage mismatches",
        c.psnr_db, c.both, c.coverage_mismatch
    );
    if c.psnr_db < 60.0 || c.coverage_mismatch * 1000 > c.both {
        let dir = write_failure_images(test, &want, &got);
        panic!("{test}: {c:?} (images in {})", dir.display());
    }
}
