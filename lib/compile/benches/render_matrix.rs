//! Time to build the render matrix A of every object of demo1 with the hardware model
//! (trilinear, 512×512 texture with its MIP chain, occluded by the rest of the scene), at
//! 320×240 and 640×480, without and with antialiasing (2× supersampled, Gaussian display
//! filter σ 0.5 px, R 1.5 px). Run: cargo bench -p pis-compile --bench render_matrix

mod common;

use common::demo1;
use std::time::Instant;

use pis_compile::{
    antialias, render_matrix, scene_depth, Address, DisplayFilter, DrawMesh, Filter, Sampler,
    TextureLayout, TextureTransform, TexturedObject, Viewport,
};

fn main() {
    let layout = TextureLayout::full(512, 512);
    let sampler = Sampler { filter: Filter::Trilinear, address: [Address::ClampToEdge; 2] };
    for (w, h) in [(320, 240), (640, 480)] {
        let (meshes, clip_from_world) = demo1((w, h));
        let draws: Vec<DrawMesh> = meshes
            .iter()
            .map(|m| DrawMesh {
                positions: &m.positions,
                uvs: &m.uvs,
                indices: &m.indices,
                clip_from_object: clip_from_world * m.world_from_object,
            })
            .collect();
        for factor in [1u32, 2] {
            let vp = Viewport { width: w * factor, height: h * factor };
            let t_all = Instant::now();
            let mut rows = 0;
            let mut nnz = 0;
            for (k, m) in meshes.iter().enumerate() {
                let t = Instant::now();
                let depth = scene_depth(vp, &draws, Some(k)).expect("depth");
                let object = TexturedObject {
                    mesh: draws[k],
                    transform: TextureTransform::IDENTITY,
                    layout,
                    sampler,
                };
                let mut a = render_matrix(vp, &object, Some(&depth)).expect("A");
                if factor > 1 {
                    a = antialias(&a, factor, DisplayFilter { sigma_px: 0.5, radius_px: 1.5 })
                        .expect("antialias");
                }
                let ms = t.elapsed().as_secs_f64() * 1e3;
                rows += a.rows();
                nnz += a.cols.len();
                println!(
                    "{w}×{h} ss{factor} {:<10} {:>6} triangles {:>7} rows {:>8} non-zeros ({:.2}/row) {:>8.1} ms",
                    m.name,
                    m.indices.len() / 3,
                    a.rows(),
                    a.cols.len(),
                    a.cols.len() as f64 / a.rows().max(1) as f64,
                    ms
                );
            }
            println!(
                "{w}×{h} ss{factor} all objects: {rows} rows, {nnz} non-zeros, {:.1} ms",
                t_all.elapsed().as_secs_f64() * 1e3
            );
        }
    }
}
