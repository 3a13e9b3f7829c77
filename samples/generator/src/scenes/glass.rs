//! glass — the seed's hybrid rendering scene (section 6.5): a glass teapot and a reflective
//! cup on a low platform, a ring of columns around them and distant walls; a view path
//! circling the teapot at 8° per sample.

use std::io;
use std::path::Path;

use glam::Vec3;

use super::common::*;
use crate::gltf_writer::MaterialDesc;
use crate::mesh::Mesh;
use crate::teapot::whole_teapot;

const TARGET: Vec3 = Vec3::new(0.0, 0.5, 0.0);

/// Writes samples/glass.
pub fn write(dir: &Path) -> io::Result<()> {
    std::fs::create_dir_all(dir)?;
    let mut w = crate::gltf_writer::GltfWriter::new();
    let (floor_mat, wall_mat) = room_materials(&mut w, dir)?;
    let glass =
        w.add_material(&MaterialDesc::glass("TeapotGlass", 1.5, 0.3, 1.0, [0.9, 0.95, 1.0]));
    let silver = w.add_material(&MaterialDesc::metal("Silver", [0.95, 0.93, 0.88], 0.03));
    let stone = w.add_material(&MaterialDesc::plain("Marble", [0.8, 0.78, 0.74], 0.5));
    let platform_mat = w.add_material(&MaterialDesc::plain("PlatformWood", [0.45, 0.3, 0.18], 0.7));

    let top = 0.3;
    let platform = crate::mesh::lathe(
        &[
            vec![glam::Vec2::new(0.0, 0.0), glam::Vec2::new(0.7, 0.0)],
            vec![glam::Vec2::new(0.7, 0.0), glam::Vec2::new(0.7, top)],
            vec![glam::Vec2::new(0.7, top), glam::Vec2::new(0.0, top)],
        ],
        48,
    );
    object(
        &mut w,
        "GlassTeapot",
        &whole_teapot(8, 0.12, Vec3::ZERO),
        glass,
        Vec3::new(-0.05, top, -0.05),
    );
    object(&mut w, "SilverCup", &cup(1.5), silver, Vec3::new(0.45, top, 0.2));
    object(&mut w, "Platform", &platform, platform_mat, Vec3::ZERO);
    let mut columns = Mesh::default();
    for k in 0..8 {
        let a = std::f32::consts::TAU * (k as f32 + 0.5) / 8.0;
        columns.append(
            &column(0.12, 2.5).scaled_translated(1.0, Vec3::new(2.2 * a.cos(), 0.0, 2.2 * a.sin())),
        );
    }
    object(&mut w, "Columns", &columns, stone, Vec3::ZERO);
    let (walls, floor) = room(8.0, 5.0);
    object(&mut w, "Walls", &walls, wall_mat, Vec3::ZERO);
    object(&mut w, "Floor", &floor, floor_mat, Vec3::ZERO);
    light_node(&mut w, "Lamp", 40.0, 0.15, Vec3::new(1.2, 3.2, 1.6), true);
    camera_node(&mut w, 35.0, TARGET, 1.8, 15.0, 0.0);
    w.write(dir, "glass")?;

    let toml = format!(
        r#"{header}
name = "glass"
gltf = "glass.gltf"
resolution = [160, 120]
spp = 4

[camera]
node = "Camera"
yfov_deg = 35

[object.GlassTeapot]
role = "refractive"

[object.SilverCup]
role = "reflective"

# The view circles the teapot at 8° per sample, as in the seed.
[[dimension]]
name = "view"
driver = "orbit"
samples = 4
target = [{tx}, {ty}, {tz}]
radius = 1.8
elevation_deg = 15
azimuth_deg = [0, 24]

[preset.paper]
resolution = [640, 480]
spp = 16
samples = {{ view = 8 }}
"#,
        header = toml_header("glass — the seed's section 6.5: glass teapot, reflective cup, ring of columns, distant walls"),
        tx = TARGET.x,
        ty = TARGET.y,
        tz = TARGET.z,
    );
    std::fs::write(dir.join("scene.toml"), toml)
}
