//! demo2 — the seed's demo 2 (section 4.8.2): demo 1's table with a rotating reflective
//! gewgaw added; the parameter space is a view orbit × the gewgaw's rotation (glTF
//! animation `spin`, kind object_motion). The light hangs still.

use std::io;
use std::path::Path;

use glam::{Quat, Vec3};

use super::common::*;
use super::demo1::{furnished_room, ELEVATION_DEG, RADIUS, TARGET};
use crate::gltf_writer::{ChannelDesc, Interp, MaterialDesc, NodeDesc};

/// Writes samples/demo2.
pub fn write(dir: &Path) -> io::Result<()> {
    std::fs::create_dir_all(dir)?;
    let mut w = furnished_room(dir, -5.25)?;
    let chrome = w.add_material(&MaterialDesc::metal("Chrome", [0.9, 0.9, 0.92], 0.03));
    let mesh = w.add_mesh("Gewgaw", &gewgaw(), chrome);
    let node = w.add_node(
        NodeDesc {
            name: "Gewgaw".into(),
            mesh: Some(mesh),
            translation: Some(Vec3::new(0.06, TABLE_HEIGHT, -0.3)),
            ..NodeDesc::default()
        },
        true,
    );
    light_node(&mut w, "Lamp", 8.0, 0.08, Vec3::new(0.3, 1.75, 0.2), true);

    // One turn about +Y; the time is in degrees of rotation (keys every 120°, so each
    // LINEAR slerp takes the intended way round).
    let times = vec![0.0, 120.0, 240.0, 360.0];
    let values: Vec<f32> =
        times.iter().flat_map(|a: &f32| Quat::from_rotation_y(a.to_radians()).to_array()).collect();
    w.add_animation(
        "spin",
        &[ChannelDesc { node, path: "rotation", interpolation: Interp::Linear, times, values }],
    );
    w.write(dir, "demo2")?;

    let toml = format!(
        r#"{header}
name = "demo2"
gltf = "demo2.gltf"
resolution = [160, 120]
spp = 4

[camera]
node = "Camera"
yfov_deg = 40

# The view circles the table; the paper preset samples it at 1.5° per sample.
[[dimension]]
name = "view"
driver = "orbit"
samples = 4
target = [{tx}, {ty}, {tz}]
radius = {radius}
elevation_deg = {elevation}
azimuth_deg = [-5.25, 5.25]

# The gewgaw's rotation; animation time is degrees, so the paper preset's 8 samples
# are 7.5° apart, as in the seed.
[[dimension]]
name = "rotation"
driver = "animation"
animation = "spin"
kind = "object_motion"
samples = 4
time = [0, 52.5]

# One full 8 × 8 block of the view × rotation space at the seed's image size.
[preset.paper]
resolution = [640, 480]
spp = 16
samples = {{ view = 8, rotation = 8 }}
"#,
        header = toml_header("demo2 — the seed's demo 2 (section 4.8.2): view × object rotation"),
        tx = TARGET.x,
        ty = TARGET.y,
        tz = TARGET.z,
        radius = RADIUS,
        elevation = ELEVATION_DEG,
    );
    std::fs::write(dir.join("scene.toml"), toml)
}
