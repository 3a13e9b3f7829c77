//! Programmatic test scenes built from the pis-scene model types.
#![allow(dead_code, reason = "each test file uses a part of these scenes")]

use glam::{Mat4, Vec2, Vec3};
use pis_scene::*;
use std::f32::consts::PI;

/// A quad with corners c ± u ± v; its front face points along u × v.
pub fn quad(c: Vec3, u: Vec3, v: Vec3, material: usize) -> Primitive {
    let n = u.cross(v).normalize();
    Primitive {
        positions: vec![c - u - v, c + u - v, c + u + v, c - u + v],
        normals: vec![n; 4],
        uvs: vec![Vec2::new(0.0, 1.0), Vec2::new(1.0, 1.0), Vec2::new(1.0, 0.0), Vec2::ZERO],
        indices: vec![0, 1, 2, 0, 2, 3],
        material,
        ..Primitive::default()
    }
}

/// An axis-aligned box; faces point outwards (or inwards with `inward`).
pub fn cuboid(lo: Vec3, hi: Vec3, material: usize, inward: bool) -> Vec<Primitive> {
    let c = (lo + hi) * 0.5;
    let h = (hi - lo) * 0.5;
    let (x, y, z) = (Vec3::X * h.x, Vec3::Y * h.y, Vec3::Z * h.z);
    let mut faces = vec![
        quad(c + x, y, z, material),
        quad(c - x, z, y, material),
        quad(c + y, z, x, material),
        quad(c - y, x, z, material),
        quad(c + z, x, y, material),
        quad(c - z, y, x, material),
    ];
    if inward {
        for f in &mut faces {
            f.indices = vec![0, 2, 1, 0, 3, 2];
            for n in &mut f.normals {
                *n = -*n;
            }
        }
    }
    faces
}

/// A UV sphere with smooth normals (pointing outwards, or inwards with `inward`).
pub fn sphere(
    c: Vec3,
    r: f32,
    rings: u32,
    segments: u32,
    material: usize,
    inward: bool,
) -> Primitive {
    let mut p = Primitive { material, ..Primitive::default() };
    for i in 0..=rings {
        let th = PI * i as f32 / rings as f32;
        for j in 0..=segments {
            let ph = 2.0 * PI * j as f32 / segments as f32;
            let n = Vec3::new(th.sin() * ph.cos(), th.cos(), th.sin() * ph.sin());
            p.positions.push(c + n * r);
            p.normals.push(if inward { -n } else { n });
            p.uvs.push(Vec2::new(j as f32 / segments as f32, i as f32 / rings as f32));
        }
    }
    let row = segments + 1;
    for i in 0..rings {
        for j in 0..segments {
            let (a, b, c2, d) =
                (i * row + j, i * row + j + 1, (i + 1) * row + j, (i + 1) * row + j + 1);
            if inward {
                p.indices.extend([a, c2, b, b, c2, d]);
            } else {
                p.indices.extend([a, b, c2, b, d, c2]);
            }
        }
    }
    p
}

/// A Lambertian material without a specular lobe.
pub fn matte(c: [f32; 3]) -> Material {
    Material {
        base_color: [c[0], c[1], c[2], 1.0],
        metallic: 0.0,
        roughness: 1.0,
        specular: 0.0,
        ..Default::default()
    }
}

/// A pure emitter (black, no specular).
pub fn emitter(l: [f32; 3]) -> Material {
    Material { emissive: l, ..matte([0.0; 3]) }
}

/// A metal with base colour `c` and roughness `r`.
pub fn metal(c: [f32; 3], r: f32) -> Material {
    Material {
        base_color: [c[0], c[1], c[2], 1.0],
        metallic: 1.0,
        roughness: r,
        ..Default::default()
    }
}

/// Clear glass of index `ior` (absorbing with `attenuation` colour at `distance`).
pub fn glass(ior: f32, attenuation: [f32; 3], distance: f32) -> Material {
    Material {
        metallic: 0.0,
        roughness: 0.0,
        transmission: 1.0,
        ior,
        attenuation_color: attenuation,
        attenuation_distance: distance,
        ..Default::default()
    }
}

pub fn object(name: &str, role: ObjectRole, primitives: Vec<Primitive>) -> SceneObject {
    SceneObject { name: name.into(), role, reflector: None, primitives }
}

/// A scene without parameter space (one point) at `res` and `spp`.
pub fn scene(
    objects: Vec<SceneObject>,
    materials: Vec<Material>,
    res: (u32, u32),
    spp: u32,
) -> Scene {
    Scene {
        name: "test".into(),
        resolution: res,
        spp,
        objects,
        materials,
        textures: vec![],
        space: ParameterSpace::default(),
        ..Default::default()
    }
}

/// A camera at `eye` looking at `target` with vertical field of view `fov_deg`.
pub fn camera(eye: Vec3, target: Vec3, fov_deg: f32) -> Camera {
    Camera {
        world_from_camera: look_at(eye, target),
        yfov: fov_deg.to_radians(),
        znear: 0.01,
        zfar: f32::INFINITY,
    }
}

/// Rigid camera-to-world transform of a camera at `eye` looking at `target`, +Y up.
pub fn look_at(eye: Vec3, target: Vec3) -> Mat4 {
    let f = (target - eye).normalize();
    let r = f.cross(Vec3::Y).normalize();
    let u = r.cross(f);
    Mat4::from_cols(r.extend(0.0), u.extend(0.0), (-f).extend(0.0), eye.extend(1.0))
}

/// A frame with identity instances.
pub fn frame(scene: &Scene, camera: Camera, lights: Vec<Light>) -> Frame {
    Frame {
        camera,
        lights,
        instances: vec![Instance { world_from_object: Mat4::IDENTITY }; scene.objects.len()],
    }
}

/// A sphere light of intensity `i` (W/sr-like) and radius `r`.
pub fn sphere_light(name: &str, pos: Vec3, i: [f32; 3], r: f32) -> Light {
    Light {
        name: name.into(),
        kind: LightKind::Point,
        radiance: i,
        radius: r,
        visible_camera: true,
        position: pos,
        direction: Vec3::NEG_Y,
    }
}

/// A matte floor and back wall, a mirror ball and a glass ball, lit by a small sphere.
pub fn room(res: (u32, u32), spp: u32) -> (Scene, Frame) {
    let s = scene(
        vec![
            object(
                "floor",
                ObjectRole::Diffuse,
                vec![quad(Vec3::new(-2.0, 0.0, -2.0), Vec3::Z * 4.0, Vec3::X * 4.0, 0)],
            ),
            object(
                "wall",
                ObjectRole::Diffuse,
                vec![quad(Vec3::new(-2.0, 0.0, -1.5), Vec3::X * 4.0, Vec3::Y * 3.0, 1)],
            ),
            object(
                "ball",
                ObjectRole::Reflective,
                vec![sphere(Vec3::new(-0.5, 0.5, 0.0), 0.5, 12, 24, 2, false)],
            ),
        ],
        vec![matte([0.7, 0.6, 0.5]), matte([0.3, 0.5, 0.7]), metal([0.9, 0.8, 0.6], 0.0)],
        res,
        spp,
    );
    let f = frame(
        &s,
        camera(Vec3::new(0.3, 1.3, 3.2), Vec3::new(0.0, 0.5, 0.0), 45.0),
        vec![sphere_light("key", Vec3::new(1.0, 2.5, 1.5), [12.0; 3], 0.2)],
    );
    (s, f)
}

/// Mean squared display error of `layer` × coverage between two points' images, over the
/// pixels `reference` covers.
pub fn layer_error(
    image: &pis_trace::layers::PointImages,
    reference: &pis_trace::layers::PointImages,
    object: &str,
    kind: pis_trace::layers::LayerKind,
) -> f64 {
    let cov = |i: &pis_trace::layers::PointImages| {
        i.object_layer(object, pis_trace::layers::LayerKind::Coverage).map(|l| l.planes[0].clone())
    };
    let (Some(ca), Some(cb)) = (cov(image), cov(reference)) else { return 0.0 };
    let (a, b) =
        (image.object_layer(object, kind).unwrap(), reference.object_layer(object, kind).unwrap());
    let (mut sum, mut n) = (0.0, 0usize);
    for i in (0..cb.len()).filter(|&i| cb[i] > 0.0) {
        for c in 0..3 {
            let d =
                (a.planes[c][i] * ca[i]).clamp(0.0, 1.0) - (b.planes[c][i] * cb[i]).clamp(0.0, 1.0);
            sum += (d * d) as f64;
        }
        n += 1;
    }
    sum / n.max(1) as f64
}
