//! Screen areas of a container's objects: the weights of equal-slope allocation (thesis 4.5).
//! Each object is drawn at every parameter point with the file's cameras and transforms
//! through the hardware model's rasterizer, depth-tested against the other objects; its area
//! is the mean number of pixels it covers, as `pis-pack` measures it on the traced images.

use glam::{Mat4, Vec4};
use pis_compile::raster::Fragments;
use pis_compile::{scene_depth, DrawMesh, TextureTransform, Viewport};
use pis_format::{Camera, Container, StreamRef};
use rayon::prelude::*;

fn mat4(m: &[f32; 12]) -> Mat4 {
    Mat4::from_cols(
        Vec4::new(m[0], m[4], m[8], 0.0),
        Vec4::new(m[1], m[5], m[9], 0.0),
        Vec4::new(m[2], m[6], m[10], 0.0),
        Vec4::new(m[3], m[7], m[11], 1.0),
    )
}

/// The glTF perspective projection with wgpu's depth range (an infinite far plane allowed).
fn projection(c: &Camera, width: u32, height: u32) -> Mat4 {
    let aspect = width.max(1) as f32 / height.max(1) as f32;
    let f = 1.0 / (c.yfov * 0.5).tan();
    let (n, far) = (c.znear, c.zfar);
    let (c2z, c3z) =
        if far.is_finite() { (far / (n - far), n * far / (n - far)) } else { (-1.0, -n) };
    Mat4::from_cols(
        Vec4::new(f / aspect, 0.0, 0.0, 0.0),
        Vec4::new(0.0, f, 0.0, 0.0),
        Vec4::new(0.0, 0.0, c2z, -1.0),
        Vec4::new(0.0, 0.0, c3z, 0.0),
    )
}

/// Mean covered pixels per parameter point of every object (at least 1, so that an object
/// hidden everywhere still gets some storage).
pub fn screen_areas(c: &Container<StreamRef>) -> Vec<f64> {
    let vp = Viewport { width: c.cameras.width, height: c.cameras.height };
    let points = c.space.point_count();
    let uvs: Vec<Vec<[f32; 2]>> = c
        .objects
        .iter()
        .map(|o| o.mesh.texcoords.clone().unwrap_or_else(|| vec![[0.0; 2]; o.mesh.positions.len()]))
        .collect();
    let totals = (0..points)
        .into_par_iter()
        .map(|p| {
            let point = c.space.point(p);
            let cam = &c.cameras.cameras[c.space.table_index(c.cameras.depends_on, &point)];
            let clip_from_world =
                projection(cam, vp.width, vp.height) * mat4(&cam.world_from_camera).inverse();
            let meshes: Vec<DrawMesh> = c
                .objects
                .iter()
                .zip(&uvs)
                .map(|(o, uv)| {
                    let t = &o.transforms;
                    DrawMesh {
                        positions: &o.mesh.positions,
                        uvs: uv,
                        indices: &o.mesh.indices,
                        clip_from_object: clip_from_world
                            * mat4(&t.transforms[c.space.table_index(t.depends_on, &point)]),
                    }
                })
                .collect();
            (0..meshes.len())
                .map(|o| match scene_depth(vp, &meshes, Some(o)) {
                    Ok(depth) => Fragments::rasterize(
                        &meshes[o],
                        &TextureTransform::IDENTITY,
                        vp,
                        Some(&depth),
                    )
                    .pixels()
                    .len() as f64,
                    Err(_) => 0.0,
                })
                .collect::<Vec<f64>>()
        })
        .reduce(
            || vec![0.0; c.objects.len()],
            |a, b| a.iter().zip(&b).map(|(x, y)| x + y).collect(),
        );
    totals.iter().map(|t| (t / points.max(1) as f64).max(1.0)).collect()
}
