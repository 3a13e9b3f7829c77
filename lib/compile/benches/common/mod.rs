//! demo1 at parameter point 0 as meshes in world placement and a clip-from-world matrix,
//! shared by the render-matrix benchmark here and the probe benchmark in pis-play
//! (`#[path]`-included there).

use std::path::Path;

use glam::{Mat4, Vec3};
use pis_compile::transform::perspective;

pub struct Mesh {
    pub name: String,
    pub positions: Vec<[f32; 3]>,
    pub uvs: Vec<[f32; 2]>,
    pub indices: Vec<u32>,
    pub world_from_object: Mat4,
}

pub fn demo1(resolution: (u32, u32)) -> (Vec<Mesh>, Mat4) {
    let options = pis_scene::LoadOptions { resolution: Some(resolution), ..Default::default() };
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../samples/demo1/scene.toml");
    let scene = pis_scene::load_with(&path, &options).expect("demo1 loads");
    let frame = scene.frame_at(0).expect("point 0");
    let cam = frame.camera;
    let aspect = resolution.0 as f32 / resolution.1 as f32;
    let clip_from_world = perspective(cam.yfov, aspect, cam.znear, cam.zfar.min(100.0))
        * cam.world_from_camera.inverse();
    let meshes = scene
        .objects
        .iter()
        .zip(&frame.instances)
        .map(|(o, inst)| {
            let mut m = Mesh {
                name: o.name.clone(),
                positions: vec![],
                uvs: vec![],
                indices: vec![],
                world_from_object: inst.world_from_object,
            };
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
