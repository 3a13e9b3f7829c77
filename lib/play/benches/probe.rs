//! Probe mode (thesis 3.4.3) on demo1: time to measure A of every object through wgpu
//! (trilinear, 512×512 texture, occluded by the rest of the scene) and its agreement with
//! the hardware model (PSNR of A_probe·x against A_model·x for a random x).
//! Run: cargo bench -p pis-play --bench probe [-- WIDTHxHEIGHT]

#[path = "../../compile/benches/common/mod.rs"]
mod common;

use common::demo1;
use std::time::Instant;

use pis_compile::{
    render_matrix, scene_depth, Address, DrawMesh, Filter, RenderMatrix, Sampler, TextureLayout,
    TextureTransform, TexturedObject, Viewport,
};
use pis_play::{probe_render_matrix, Gpu, TexturedPipeline};

fn product(a: &RenderMatrix, x: &[f32]) -> Vec<(u32, f32)> {
    let mut y = vec![0.0; a.rows()];
    a.mul(x, &mut y);
    a.pixels.iter().copied().zip(y).collect()
}

fn main() {
    let size = std::env::args()
        .skip(1)
        .find_map(|a| a.split_once('x').and_then(|(w, h)| Some((w.parse().ok()?, h.parse().ok()?))))
        .unwrap_or((320u32, 240u32));
    let gpu = match Gpu::new() {
        Ok(g) => g,
        Err(e) => {
            eprintln!("probe bench skipped: {e}");
            return;
        }
    };
    println!("adapter: {}", gpu.describe());
    let pipeline = TexturedPipeline::new(&gpu);
    let vp = Viewport { width: size.0, height: size.1 };
    let (meshes, clip_from_world) = demo1(size);
    let draws: Vec<DrawMesh> = meshes
        .iter()
        .map(|m| DrawMesh {
            positions: &m.positions,
            uvs: &m.uvs,
            indices: &m.indices,
            clip_from_object: clip_from_world * m.world_from_object,
        })
        .collect();
    let layout = TextureLayout::full(512, 512);
    let sampler = Sampler { filter: Filter::Trilinear, address: [Address::ClampToEdge; 2] };
    let mut seed = 1u32;
    let x: Vec<f32> = (0..layout.texel_count())
        .map(|_| {
            seed ^= seed << 13;
            seed ^= seed >> 17;
            seed ^= seed << 5;
            (seed >> 8) as f32 / (1u32 << 24) as f32
        })
        .collect();
    let t_all = Instant::now();
    for (k, m) in meshes.iter().enumerate() {
        let occluders: Vec<DrawMesh> =
            draws.iter().enumerate().filter(|(j, _)| *j != k).map(|(_, d)| *d).collect();
        let object = TexturedObject {
            mesh: draws[k],
            transform: TextureTransform::IDENTITY,
            layout,
            sampler,
        };
        let t = Instant::now();
        let probe = probe_render_matrix(&gpu, &pipeline, vp, &occluders, &object).expect("probe");
        let ms = t.elapsed().as_secs_f64() * 1e3;
        let depth = scene_depth(vp, &draws, Some(k)).expect("depth");
        let model = render_matrix(vp, &object, Some(&depth)).expect("model");
        let (pm, pp) = (product(&model, &x), product(&probe, &x));
        let probe_at: std::collections::HashMap<u32, f32> = pp.into_iter().collect();
        let (mut se, mut n, mut missing) = (0.0f64, 0usize, 0usize);
        for (p, v) in pm {
            match probe_at.get(&p) {
                Some(&q) => {
                    se += ((v - q) as f64).powi(2);
                    n += 1;
                }
                None => missing += 1,
            }
        }
        let psnr = -10.0 * (se / n.max(1) as f64).max(1e-30).log10();
        println!(
            "{}×{} {:<10} probe {:>8.1} ms, {:>7} rows, {:>8} non-zeros; A_model·x vs A_probe·x {psnr:.1} dB, {missing} rows only in the model, {} only in the probe",
            vp.width,
            vp.height,
            m.name,
            ms,
            probe.rows(),
            probe.cols.len(),
            probe.rows() - n
        );
    }
    println!("all objects: {:.1} s", t_all.elapsed().as_secs_f64());
}
