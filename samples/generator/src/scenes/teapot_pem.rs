//! teapot-pem — the seed's parameterized environment map scene (section 5.10): a mirror
//! teapot in a room, on a pedestal, with a few objects near the walls for its reflections;
//! a 1D view path partially circling the teapot. As in the seed, the teapot is two objects:
//! the lid, and the body with spout and handle. [`write_variant`] builds the same scene with
//! another teapot material (teapot-glossy).

use std::io;
use std::path::Path;

use glam::Vec3;

use super::common::*;
use crate::gltf_writer::MaterialDesc;
use crate::mesh::cuboid;
use crate::teapot::{teapot, BODY, BOTTOM, HANDLE, LID, RIM, SPOUT};

const TARGET: Vec3 = Vec3::new(0.0, 0.65, 0.0);

/// The teapot's base colour (linear RGB), shared by every variant.
pub const TEAPOT_COLOR: [f32; 3] = [0.95, 0.95, 0.95];

/// What sets a variant of the scene apart: its name (the directory, the glTF's file stem
/// and scene.toml's `name`), the title in scene.toml's header, and the material of the
/// teapot's body and lid.
pub struct Variant {
    pub name: &'static str,
    pub title: &'static str,
    pub teapot: MaterialDesc,
}

/// Writes samples/teapot-pem: a mirror teapot.
pub fn write(dir: &Path) -> io::Result<()> {
    write_variant(
        dir,
        &Variant {
            name: "teapot-pem",
            title: "teapot-pem — the seed's section 5.10: a mirror teapot in a room, 1D view path",
            teapot: MaterialDesc::metal("Mirror", TEAPOT_COLOR, 0.02),
        },
    )
}

/// Writes the scene with `variant`'s teapot material, name and title into `dir`; the room,
/// the other objects, the light, the camera path and the presets are the same for every
/// variant.
pub fn write_variant(dir: &Path, variant: &Variant) -> io::Result<()> {
    std::fs::create_dir_all(dir)?;
    let mut w = crate::gltf_writer::GltfWriter::new();
    let (floor_mat, wall_mat) = room_materials(&mut w, dir)?;
    let teapot_mat = w.add_material(&variant.teapot);
    let pedestal_mat =
        w.add_material(&MaterialDesc::plain("PedestalStone", [0.7, 0.68, 0.62], 0.7));
    let red = w.add_material(&MaterialDesc::plain("RedPaint", [0.7, 0.1, 0.08], 0.6));
    let blue = w.add_material(&MaterialDesc::plain("BluePaint", [0.1, 0.2, 0.6], 0.6));

    let pedestal_top = 0.5;
    let (scale, base) = (0.1, Vec3::new(0.0, pedestal_top, 0.0));
    let body_patches = RIM.chain(BODY).chain(HANDLE).chain(SPOUT).chain(BOTTOM);
    object(&mut w, "TeapotBody", &teapot(body_patches, 8, scale, Vec3::ZERO), teapot_mat, base);
    object(&mut w, "TeapotLid", &teapot(LID, 8, scale, Vec3::ZERO), teapot_mat, base);
    object(
        &mut w,
        "Pedestal",
        &cuboid(Vec3::new(-0.3, 0.0, -0.3), Vec3::new(0.3, pedestal_top, 0.3), 2, false),
        pedestal_mat,
        Vec3::ZERO,
    );
    object(
        &mut w,
        "RedBox",
        &cuboid(Vec3::new(-0.25, 0.0, -0.25), Vec3::new(0.25, 0.5, 0.25), 2, false),
        red,
        Vec3::new(-1.6, 0.0, -1.9),
    );
    object(&mut w, "BlueColumn", &column(0.12, 2.0), blue, Vec3::new(1.7, 0.0, -1.5));
    let (walls, floor) = room(3.0, 3.0);
    object(&mut w, "Walls", &walls, wall_mat, Vec3::ZERO);
    object(&mut w, "Floor", &floor, floor_mat, Vec3::ZERO);
    light_node(&mut w, "Lamp", 16.0, 0.1, Vec3::new(0.6, 2.6, 0.8), true);
    camera_node(&mut w, 35.0, TARGET, 1.6, 20.0, 0.0);
    w.write(dir, variant.name)?;

    let toml = format!(
        r#"{header}
name = "{name}"
gltf = "{name}.gltf"
resolution = [160, 120]
spp = 4

[camera]
node = "Camera"
yfov_deg = 35

[object.TeapotBody]
role = "reflective"

[object.TeapotLid]
role = "reflective"

# The view path partially circles the teapot; the paper preset samples it at 1° per
# sample, as in the seed.
[[dimension]]
name = "view"
driver = "orbit"
samples = 4
target = [{tx}, {ty}, {tz}]
radius = 1.6
elevation_deg = 20
azimuth_deg = [0, 7]

[preset.paper]
resolution = [640, 480]
spp = 16
samples = {{ view = 8 }}
"#,
        header = toml_header(variant.title),
        name = variant.name,
        tx = TARGET.x,
        ty = TARGET.y,
        tz = TARGET.z,
    );
    std::fs::write(dir.join("scene.toml"), toml)
}
