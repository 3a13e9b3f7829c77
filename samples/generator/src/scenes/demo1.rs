//! demo1 — the seed's demo 1 (section 4.8.1): a reflective vase, a glass cup, a reflective
//! table top, the table stand, walls and floor; the parameter space is a swinging spherical
//! light (a pendulum, glTF animation `swing`, kind light) × a view orbit around the table.

use std::io;
use std::path::Path;

use glam::{Quat, Vec3};

use super::common::*;
use crate::gltf_writer::{ChannelDesc, GltfWriter, Interp, MaterialDesc, NodeDesc};

/// Where the orbit looks and how it circles (shared with demo2).
pub const TARGET: Vec3 = Vec3::new(0.0, 0.85, 0.0);
pub const RADIUS: f32 = 1.7;
pub const ELEVATION_DEG: f32 = 22.0;

/// The table and its contents (vase, glass cup), the room, and the camera node; returns the
/// writer for the caller to add lights and extra objects.
pub fn furnished_room(dir: &Path, first_azimuth: f32) -> io::Result<GltfWriter> {
    let mut w = GltfWriter::new();
    let (floor_mat, wall_mat) = room_materials(&mut w, dir)?;
    let vase_mat = w.add_material(&MaterialDesc::plain("GlazedCeramic", [0.08, 0.18, 0.55], 0.05));
    let glass_mat =
        w.add_material(&MaterialDesc::glass("Glass", 1.5, 0.006, 0.5, [0.85, 0.95, 0.9]));
    let top_mat = w.add_material(&MaterialDesc::plain("PolishedWood", [0.30, 0.11, 0.05], 0.04));
    let stand_mat = w.add_material(&MaterialDesc::plain("StandPaint", [0.55, 0.52, 0.48], 0.6));

    let (walls, floor) = room(3.0, 3.0);
    let (top, stand) = table();
    object(&mut w, "Vase", &vase(), vase_mat, Vec3::new(-0.2, TABLE_HEIGHT, -0.08));
    object(&mut w, "GlassCup", &cup(1.0), glass_mat, Vec3::new(0.2, TABLE_HEIGHT, 0.14));
    object(&mut w, "TableTop", &top, top_mat, Vec3::new(0.0, TABLE_HEIGHT, 0.0));
    object(&mut w, "TableStand", &stand, stand_mat, Vec3::ZERO);
    object(&mut w, "Walls", &walls, wall_mat, Vec3::ZERO);
    object(&mut w, "Floor", &floor, floor_mat, Vec3::ZERO);
    camera_node(&mut w, 40.0, TARGET, RADIUS, ELEVATION_DEG, first_azimuth);
    Ok(w)
}

/// Writes samples/demo1.
pub fn write(dir: &Path) -> io::Result<()> {
    std::fs::create_dir_all(dir)?;
    let mut w = furnished_room(dir, -6.3)?;

    // The pendulum: a pivot node above the table swinging about +Z; the light hangs 0.5 m below.
    let lamp = light_node(&mut w, "Lamp", 8.0, 0.08, Vec3::new(0.0, -0.5, 0.0), false);
    let pivot = w.add_node(
        NodeDesc {
            name: "Pendulum".into(),
            translation: Some(Vec3::new(0.0, 2.2, 0.0)),
            children: vec![lamp],
            ..NodeDesc::default()
        },
        true,
    );
    let angles = [60f32, 0.0, -60.0];
    let values: Vec<f32> =
        angles.iter().flat_map(|a| Quat::from_rotation_z(a.to_radians()).to_array()).collect();
    w.add_animation(
        "swing",
        &[ChannelDesc {
            node: pivot,
            path: "rotation",
            interpolation: Interp::Linear,
            times: vec![0.0, 0.5, 1.0],
            values,
        }],
    );
    w.write(dir, "demo1")?;

    let toml = format!(
        r#"{header}
name = "demo1"
gltf = "demo1.gltf"
resolution = [160, 120]
spp = 4

[camera]
node = "Camera"
yfov_deg = 40

# Roles as inferred from the materials, spelled out: the vase and the table top are
# glossy dielectrics (diffuse + reflective layers), the cup is glass.
[object.Vase]
role = "reflective"

[object.GlassCup]
role = "refractive"

[object.TableTop]
role = "reflective"

# The swinging light: the pendulum swings from +60° (t = 0) to -60° (t = 1).
[[dimension]]
name = "light"
driver = "animation"
animation = "swing"
kind = "light"
samples = 4
time = [0, 1]

# The view circles the table; the paper preset samples it at 1.8° per sample.
[[dimension]]
name = "view"
driver = "orbit"
samples = 4
target = [{tx}, {ty}, {tz}]
radius = {radius}
elevation_deg = {elevation}
azimuth_deg = [-6.3, 6.3]

# One full 8 × 8 block of the light × view space at the seed's image size. 64 samples per
# pixel: at 16 the gold standard's own noise (40 dB against a 256-spp trace; the glass cup
# 23 dB) would sit within 3 dB of the PSNR it is to measure.
[preset.paper]
resolution = [640, 480]
spp = 64
samples = {{ light = 8, view = 8 }}
"#,
        header = toml_header("demo1 — the seed's demo 1 (section 4.8.1): light × view"),
        tx = TARGET.x,
        ty = TARGET.y,
        tz = TARGET.z,
        radius = RADIUS,
        elevation = ELEVATION_DEG,
    );
    std::fs::write(dir.join("scene.toml"), toml)
}
