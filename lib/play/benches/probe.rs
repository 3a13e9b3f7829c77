//! Probe mode (thesis 3.4.3) on demo1: time to measure A of every object through wgpu
//! (trilinear, 512×512 texture, occluded by the rest of the scene) and its agreement with
//! the hardware model (PSNR of A_probe·x against A_model·x for a random x).
//! Run: cargo bench -p pis-play --bench probe [-- WIDTHxHEIGHT]

use std::path::Path;
use std::time::Instant;

use glam::{Mat4, Vec3};
use pis_compile::transform::perspective;
use pis_compile::{render_matrix, scene_depth, Address, DrawMesh, Filter, RenderMatrix, Sampler, TextureLayout, TextureTransform, TexturedObject, Viewport};
use pis_play::{probe_render_matrix, Gpu, TexturedPipeline};

struct Mesh {
    name: String,
    positions: Vec<[f32; 3]>,
    uvs: Vec<[f32; 2]>,
    indices: Vec<u32>,
    world_from_object: Mat4,
}

fn demo1(resolution: (u32, u32)) -> (Vec<Mesh>, Mat4) {
    let options = pis_scene::LoadOptions { resolution: Some(resolution), ..Default::default() };
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../samples/demo1/scene.toml");
    let scene = pis_scene::load_with(&path, &options).expect("demo1 loads");
    let frame = scene.frame_at(0).expect("point 0");
    let cam = frame.camera;
    let aspect = resolution.0 as f32 / resolution.1 as f32;
    let clip_from_world = perspective(cam.yfov, aspect, cam.znear, cam.zfar.min(100.0)) * cam.world_from_camera.inverse();
    let meshes = scene
        .objects
        .iter()
        .zip(&frame.instances)
        .map(|(o, inst)| {
            let mut m = Mesh { name: o.name.clone(), positions: vec![], uvs: vec![], indices: vec![], world_from_object: inst.world_from_object };
            for p in &o.primitives {
                let base = m.positions.len() as u32;
                m.positions.extend(p.positions.iter().map(|v: &Vec3| v.to_array()));
                m.uvs.extend(p.uvs.iter().map(|v| v.to_array()));
                m.indices.extend(p.indices.iter().map(|&i| base + i));
            }
            m
        })
        .collect();
    (meshes, clip_from_world)
}

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
        .map(|m| DrawMesh { positions: &m.positions, uvs: &m.uvs, indices: &m.indices, clip_from_object: clip_from_world * m.world_from_object })
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
        let occluders: Vec<DrawMesh> = draws.iter().enumerate().filter(|(j, _)| *j != k).map(|(_, d)| *d).collect();
        let object = TexturedObject { mesh: draws[k], transform: TextureTransform::IDENTITY, layout, sampler };
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
