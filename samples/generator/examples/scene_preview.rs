//! A quick look at a sample scene before any real renderer runs: casts one ray per pixel
//! (brute force, no acceleration), shades with base colour × (ambient + Lambert from each
//! light, no shadows), follows one mirror bounce for reflective objects, and writes a PNG.
//!
//! `cargo run -p pis-samples --release --example scene_preview -- samples/demo1/scene.toml out.png [POINT [WxH]]`

use glam::{Vec2, Vec3};
use pis_scene::{load_with, LoadOptions, ObjectRole, Scene};

struct Tri {
    p: [Vec3; 3],
    n: [Vec3; 3],
    uv: [Vec2; 3],
    material: usize,
    role: ObjectRole,
}

fn intersect(t: &Tri, o: Vec3, d: Vec3) -> Option<(f32, f32, f32)> {
    let (e1, e2) = (t.p[1] - t.p[0], t.p[2] - t.p[0]);
    let h = d.cross(e2);
    let a = e1.dot(h);
    if a.abs() < 1e-12 {
        return None;
    }
    let s = o - t.p[0];
    let u = s.dot(h) / a;
    let q = s.cross(e1);
    let v = d.dot(q) / a;
    let dist = e2.dot(q) / a;
    (u >= 0.0 && v >= 0.0 && u + v <= 1.0 && dist > 1e-4).then_some((dist, u, v))
}

fn trace(
    scene: &Scene,
    tris: &[Tri],
    lights: &[pis_scene::Light],
    o: Vec3,
    d: Vec3,
    depth: u32,
) -> Vec3 {
    let mut best: Option<(f32, usize, f32, f32)> = None;
    for (k, t) in tris.iter().enumerate() {
        if let Some((dist, u, v)) = intersect(t, o, d) {
            if best.is_none_or(|b| dist < b.0) {
                best = Some((dist, k, u, v));
            }
        }
    }
    let Some((dist, k, u, v)) = best else {
        return Vec3::ZERO;
    };
    let t = &tris[k];
    let w = 1.0 - u - v;
    let p = o + d * dist;
    let n = (t.n[0] * w + t.n[1] * u + t.n[2] * v).normalize();
    let uv = t.uv[0] * w + t.uv[1] * u + t.uv[2] * v;
    let m = &scene.materials[t.material];
    let mut albedo = Vec3::new(m.base_color[0], m.base_color[1], m.base_color[2]);
    if let Some((r, tex)) =
        m.base_color_texture.and_then(|r| scene.textures.get(r.texture).map(|t| (r, t)))
    {
        let uv = r.transform.apply(uv);
        let x = ((uv.x.rem_euclid(1.0)) * tex.width as f32) as usize % tex.width as usize;
        let y = ((uv.y.rem_euclid(1.0)) * tex.height as f32) as usize % tex.height as usize;
        let c = tex.texels[y * tex.width as usize + x];
        albedo *= Vec3::new(c[0], c[1], c[2]);
    }
    if depth < 2 && t.role != ObjectRole::Diffuse {
        let r = d - 2.0 * d.dot(n) * n;
        let bounce = trace(scene, tris, lights, p + n * 1e-3 * r.dot(n).signum(), r, depth + 1);
        return if t.role == ObjectRole::Refractive {
            bounce * Vec3::new(0.7, 0.8, 0.9)
        } else {
            bounce * 0.8 + albedo * 0.1
        };
    }
    let mut lit = Vec3::splat(0.15);
    for l in lights {
        let to = l.position - p;
        lit += Vec3::from(l.radiance) * n.dot(to.normalize()).max(0.0) / to.length_squared();
    }
    albedo * lit
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (toml, out) = (std::path::Path::new(&args[0]), &args[1]);
    let index: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(0);
    let resolution = args
        .get(3)
        .and_then(|s| s.split_once('x'))
        .and_then(|(w, h)| Some((w.parse().ok()?, h.parse().ok()?)));
    let scene = load_with(toml, &LoadOptions { resolution, ..LoadOptions::default() })
        .unwrap_or_else(|e| panic!("{e}"));
    let frame = scene.frame_at(index).unwrap_or_else(|e| panic!("{e}"));
    let mut tris = Vec::new();
    for (obj, inst) in scene.objects.iter().zip(&frame.instances) {
        let m = inst.world_from_object;
        for prim in &obj.primitives {
            for c in prim.indices.chunks_exact(3) {
                let i = [c[0], c[1], c[2]].map(|i| i as usize);
                tris.push(Tri {
                    p: i.map(|i| m.transform_point3(prim.positions[i])),
                    n: i.map(|i| m.transform_vector3(prim.normals[i]).normalize()),
                    uv: i.map(|i| prim.uvs[i]),
                    material: prim.material,
                    role: obj.role,
                });
            }
        }
    }
    let (w, h) = scene.resolution;
    let cam = frame.camera;
    let tan = (cam.yfov * 0.5).tan();
    let img = image::RgbImage::from_fn(w, h, |x, y| {
        let sx = (2.0 * (x as f32 + 0.5) / w as f32 - 1.0) * tan * w as f32 / h as f32;
        let sy = (1.0 - 2.0 * (y as f32 + 0.5) / h as f32) * tan;
        let d = cam.world_from_camera.transform_vector3(Vec3::new(sx, sy, -1.0)).normalize();
        let o = cam.world_from_camera.transform_point3(Vec3::ZERO);
        let c = trace(&scene, &tris, &frame.lights, o, d, 0);
        image::Rgb(c.to_array().map(|v| (v.clamp(0.0, 1.0).powf(1.0 / 2.2) * 255.0) as u8))
    });
    img.save(out).expect("write png");
    println!("{} triangles, wrote {out}", tris.len());
}
