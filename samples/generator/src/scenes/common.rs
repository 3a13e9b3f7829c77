//! Pieces shared by the sample scenes: the room, the table, the vase, the cup, the light.

use std::io;
use std::path::Path;

use glam::{Quat, Vec2, Vec3};

use crate::gltf_writer::{GltfWriter, MaterialDesc, NodeDesc};
use crate::mesh::{cuboid, lathe, quad, Mesh};
use crate::textures;

/// Lathe segments around the axis for the small objects.
pub const SEGMENTS: usize = 40;

/// Adds a mesh node at `translation` as a scene root; returns the node index.
pub fn object(
    w: &mut GltfWriter,
    name: &str,
    mesh: &Mesh,
    material: usize,
    translation: Vec3,
) -> usize {
    let m = w.add_mesh(name, mesh, material);
    let t = (translation != Vec3::ZERO).then_some(translation);
    w.add_node(
        NodeDesc { name: name.into(), mesh: Some(m), translation: t, ..NodeDesc::default() },
        true,
    )
}

/// Samples a Catmull-Rom spline through `points` with `per_segment` steps per segment.
pub fn smooth(points: &[Vec2], per_segment: usize) -> Vec<Vec2> {
    let n = points.len();
    let at = |k: isize| points[k.clamp(0, n as isize - 1) as usize];
    let mut out = Vec::new();
    for k in 0..n - 1 {
        let (p0, p1, p2, p3) =
            (at(k as isize - 1), at(k as isize), at(k as isize + 1), at(k as isize + 2));
        for s in 0..per_segment {
            let t = s as f32 / per_segment as f32;
            let (t2, t3) = (t * t, t * t * t);
            out.push(
                0.5 * ((2.0 * p1)
                    + (p2 - p0) * t
                    + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * t2
                    + (3.0 * p1 - p0 - 3.0 * p2 + p3) * t3),
            );
        }
    }
    out.push(points[n - 1]);
    out
}

fn v2(r: f32, y: f32) -> Vec2 {
    Vec2::new(r, y)
}

/// Walls and ceiling of a room (inward-facing), and its floor, spanning x and z in
/// [-half, half] and y in [0, height]. The floor has a 1 × 1 UV square over its whole area.
pub fn room(half: f32, height: f32) -> (Mesh, Mesh) {
    let mut walls = cuboid(Vec3::new(-half, 0.0, -half), Vec3::new(half, height, half), 3, true);
    // Drop the bottom face (the floor is its own object): it is the fourth of six faces.
    let per_face = walls.indices.len() / 6;
    walls.indices.drain(3 * per_face..4 * per_face);
    let floor = quad(
        Vec3::new(-half, 0.0, half),
        Vec3::new(2.0 * half, 0.0, 0.0),
        Vec3::new(0.0, 0.0, -2.0 * half),
        8,
        8,
        Vec2::ONE,
    );
    (walls, floor)
}

/// Writes floor.png (a checkerboard) and wallpaper.png (green stripes) into `dir` and adds
/// the floor and wall materials. Returns (floor material, wall material).
pub fn room_materials(w: &mut GltfWriter, dir: &Path) -> io::Result<(usize, usize)> {
    textures::checker(&dir.join("floor.png"), 128, 16, [205, 200, 190], [70, 60, 55])?;
    textures::wallpaper(&dir.join("wallpaper.png"), 128, 32, [96, 150, 96], [130, 180, 120])?;
    let floor_tex = w.add_png_texture("floor.png");
    let wall_tex = w.add_png_texture("wallpaper.png");
    let floor = w.add_material(&MaterialDesc::textured("Floor", floor_tex, 0.8));
    let walls = w.add_material(&MaterialDesc::textured("Wallpaper", wall_tex, 0.9));
    Ok((floor, walls))
}

/// Height of the table top's upper surface.
pub const TABLE_HEIGHT: f32 = 0.75;

/// The table top (a disc with a rounded edge, radius 0.55, 4 cm thick) in table-top
/// coordinates (upper surface at y = 0), and the stand (foot, column, collar) from the floor.
pub fn table() -> (Mesh, Mesh) {
    let r = 0.55;
    let top = lathe(
        &[
            vec![v2(0.0, -0.04), v2(r - 0.02, -0.04)],
            smooth(
                &[
                    v2(r - 0.02, -0.04),
                    v2(r, -0.03),
                    v2(r + 0.005, -0.02),
                    v2(r, -0.01),
                    v2(r - 0.02, 0.0),
                ],
                2,
            ),
            vec![v2(r - 0.02, 0.0), v2(0.0, 0.0)],
        ],
        64,
    );
    let h = TABLE_HEIGHT - 0.04;
    let stand = lathe(
        &[
            vec![v2(0.0, 0.0), v2(0.3, 0.0)],
            smooth(&[v2(0.3, 0.0), v2(0.3, 0.03), v2(0.12, 0.07), v2(0.05, 0.12)], 3),
            vec![v2(0.05, 0.12), v2(0.045, h - 0.1)],
            smooth(&[v2(0.045, h - 0.1), v2(0.08, h - 0.04), v2(0.16, h)], 3),
            vec![v2(0.16, h), v2(0.0, h)],
        ],
        SEGMENTS,
    );
    (top, stand)
}

/// A vase (closed surface: outer wall, lip, a short inner well), 0.33 m tall, base at y = 0.
pub fn vase() -> Mesh {
    let outer = smooth(
        &[
            v2(0.05, 0.0),
            v2(0.085, 0.05),
            v2(0.095, 0.11),
            v2(0.07, 0.19),
            v2(0.04, 0.25),
            v2(0.038, 0.29),
            v2(0.05, 0.33),
        ],
        4,
    );
    lathe(
        &[
            vec![v2(0.0, 0.0), v2(0.05, 0.0)],
            outer,
            vec![v2(0.05, 0.33), v2(0.042, 0.33)],
            smooth(&[v2(0.042, 0.33), v2(0.032, 0.30), v2(0.025, 0.26)], 3),
            vec![v2(0.025, 0.26), v2(0.0, 0.26)],
        ],
        SEGMENTS,
    )
}

/// A cup with walls 6 mm thick and a 12 mm base (a closed solid for refraction), 12 cm
/// tall, radius 5 cm at the rim; `scale` scales it uniformly.
pub fn cup(scale: f32) -> Mesh {
    let s = |r: f32, y: f32| v2(r * scale, y * scale);
    lathe(
        &[
            vec![s(0.0, 0.0), s(0.045, 0.0)],
            vec![s(0.045, 0.0), s(0.05, 0.12)],
            smooth(&[s(0.05, 0.12), s(0.048, 0.123), s(0.044, 0.12)], 2),
            vec![s(0.044, 0.12), s(0.04, 0.012)],
            vec![s(0.04, 0.012), s(0.0, 0.012)],
        ],
        SEGMENTS,
    )
}

/// A torus about +Y: major radius `major`, tube radius `minor`.
pub fn torus(major: f32, minor: f32, tube_steps: usize, segments: usize) -> Mesh {
    let ring: Vec<Vec2> = (0..=tube_steps)
        .map(|k| {
            // Counter-clockwise in the (r, y) plane: the outside is to the right of travel.
            let a = std::f32::consts::TAU * k as f32 / tube_steps as f32;
            v2(major + minor * a.cos(), minor * a.sin())
        })
        .collect();
    lathe(&[ring], segments)
}

/// A UV sphere of radius `r` centred at the origin.
pub fn sphere(r: f32, rings: usize, segments: usize) -> Mesh {
    let profile: Vec<Vec2> = (0..=rings)
        .map(|k| {
            let a = std::f32::consts::PI * (k as f32 / rings as f32 - 0.5);
            v2(r * a.cos(), r * a.sin())
        })
        .collect();
    lathe(&[profile], segments)
}

/// The gewgaw of demo 2: a chrome ball with a torus tilted 35° balanced on it; base at y = 0.
pub fn gewgaw() -> Mesh {
    let mut m = sphere(0.03, 12, 24).scaled_translated(1.0, Vec3::new(0.0, 0.03, 0.0));
    let mut t = torus(0.075, 0.018, 12, 40);
    let tilt = Quat::from_rotation_x(35f32.to_radians());
    for (p, n) in t.positions.iter_mut().zip(t.normals.iter_mut()) {
        *p = tilt * *p + Vec3::new(0.0, 0.115, 0.0);
        *n = tilt * *n;
    }
    m.append(&t);
    m
}

/// A column: base slab, shaft, capital; `height` tall, base at y = 0.
pub fn column(radius: f32, height: f32) -> Mesh {
    let (b, c) = (0.08 * height, 0.92 * height);
    lathe(
        &[
            vec![v2(0.0, 0.0), v2(radius * 1.5, 0.0)],
            vec![v2(radius * 1.5, 0.0), v2(radius * 1.5, b * 0.6)],
            smooth(&[v2(radius * 1.5, b * 0.6), v2(radius * 1.2, b * 0.8), v2(radius, b)], 2),
            vec![v2(radius, b), v2(radius * 0.92, c)],
            smooth(
                &[
                    v2(radius * 0.92, c),
                    v2(radius * 1.2, c + 0.3 * (height - c)),
                    v2(radius * 1.5, c + 0.6 * (height - c)),
                ],
                2,
            ),
            vec![v2(radius * 1.5, c + 0.6 * (height - c)), v2(radius * 1.5, height)],
            vec![v2(radius * 1.5, height), v2(0.0, height)],
        ],
        24,
    )
}

/// Adds a point light with a sphere radius on its own node; returns the node index.
pub fn light_node(
    w: &mut GltfWriter,
    name: &str,
    intensity: f32,
    radius: f32,
    at: Vec3,
    root: bool,
) -> usize {
    let l = w.add_point_light(name, [1.0, 0.95, 0.85], intensity, radius);
    w.add_node(
        NodeDesc {
            name: format!("{name}Node"),
            light: Some(l),
            translation: Some(at),
            ..NodeDesc::default()
        },
        root,
    )
}

/// Adds the glTF camera node "Camera" at the orbit's first sample (so that other glTF
/// viewers show the scene as scene.toml frames it) looking at `target`.
pub fn camera_node(
    w: &mut GltfWriter,
    yfov_deg: f32,
    target: Vec3,
    radius: f32,
    elevation_deg: f32,
    azimuth_deg: f32,
) -> usize {
    let (el, az) = (elevation_deg.to_radians(), azimuth_deg.to_radians());
    let eye = target + radius * Vec3::new(el.cos() * az.sin(), el.sin(), el.cos() * az.cos());
    let forward = (target - eye).normalize();
    let right = forward.cross(Vec3::Y).normalize();
    let up = right.cross(forward);
    let rotation = Quat::from_mat3(&glam::Mat3::from_cols(right, up, -forward)).normalize();
    let c = w.add_camera(yfov_deg, 4.0 / 3.0, 0.05);
    w.add_node(
        NodeDesc {
            name: "Camera".into(),
            camera: Some(c),
            translation: Some(eye),
            rotation: Some(rotation),
            ..NodeDesc::default()
        },
        true,
    )
}

/// The standard header of a generated scene.toml.
pub fn toml_header(title: &str) -> String {
    format!("# {title}\n# Generated by `cargo run -p pis-samples --release -- samples/`; edit the generator, not this file.\n# Every key is documented in docs/SCENE.md.\n")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Six times the signed volume enclosed: positive when the triangles wind outward.
    fn signed_volume6(m: &Mesh) -> f32 {
        m.indices
            .chunks_exact(3)
            .map(|t| {
                let [a, b, c] = [t[0], t[1], t[2]].map(|k| m.positions[k as usize]);
                a.dot(b.cross(c))
            })
            .sum()
    }

    #[test]
    fn closed_meshes_face_outward() {
        let (top, stand) = table();
        let teapot = crate::teapot::whole_teapot(6, 1.0, Vec3::ZERO);
        for (name, m) in [
            ("table top", top),
            ("stand", stand),
            ("vase", vase()),
            ("cup", cup(1.0)),
            ("torus", torus(0.1, 0.02, 8, 16)),
            ("sphere", sphere(0.1, 8, 16)),
            ("gewgaw", gewgaw()),
            ("column", column(0.1, 1.0)),
            ("teapot", teapot),
        ] {
            assert!(signed_volume6(&m) > 0.0, "{name} faces inward");
            // Vertex normals agree with the winding (add_triangle guarantees it per face).
            for t in m.indices.chunks_exact(3) {
                let [a, b, c] = [t[0], t[1], t[2]].map(|k| k as usize);
                let face = (m.positions[b] - m.positions[a]).cross(m.positions[c] - m.positions[a]);
                assert!(face.dot(m.normals[a] + m.normals[b] + m.normals[c]) >= 0.0, "{name}");
            }
        }
        let (walls, floor) = room(3.0, 3.0);
        assert!(signed_volume6(&walls) < 0.0, "room walls face inward");
        assert!(floor.normals.iter().all(|n| n.y > 0.99));
    }
}
