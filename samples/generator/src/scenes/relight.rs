//! still-life relit: the sky of still-life's scene.toml replaced by a sun turned over the
//! upper hemisphere (relight.toml, 64 directions × 4 views), and the scenes its relit file
//! is judged under, traced with exactly those lights: two coloured directional lights
//! (relight-two.toml) and an HDR sky (relight-sky.toml with relight-sky.exr); and the sun
//! moving continuously along an arc (relight-arc.toml), to judge popping. Every direction
//! they light from is one the 64 samples do not hold. relight-soft.toml and
//! relight-soft-arc.toml turn a sphere light of the scene's radius instead of the sun: soft
//! shadows, and highlights as wide as the light.

use std::io;
use std::path::Path;

use glam::Vec3;

use super::wild_toml::{header, orbit};

/// Writes relight.toml, relight-two.toml, relight-sky.toml, relight-sky.exr,
/// relight-arc.toml, relight-soft.toml, relight-soft-arc.toml and relight-soft-two.toml
/// into `dir`.
pub fn write(dir: &Path, target: Vec3) -> io::Result<()> {
    std::fs::write(dir.join("relight.toml"), relight_toml(target))?;
    std::fs::write(dir.join("relight-soft.toml"), soft_toml(target, false))?;
    std::fs::write(dir.join("relight-soft-arc.toml"), soft_toml(target, true))?;
    std::fs::write(dir.join("relight-soft-two.toml"), soft_two_toml(target))?;
    std::fs::write(dir.join("relight-arc.toml"), arc_toml(target))?;
    std::fs::write(dir.join("relight-two.toml"), two_lights_toml(target))?;
    std::fs::write(dir.join("relight-sky.toml"), sky_toml(target))?;
    write_sky(&dir.join("relight-sky.exr"))
}

/// The views every relight scene shares.
fn views(target: Vec3) -> String {
    orbit("view", 4, target, 1.1, 28.0, [-15.0, 15.0])
}

/// The resolution, samples and paper preset every relight scene shares.
const SIZE: &str = "resolution = [160, 120]\nspp = 16\n\n[camera]\nyfov_deg = 40\n";
const PAPER: &str = "[preset.paper]\nresolution = [640, 480]\nspp = 16\n";

/// The sun over 64 directions of the upper hemisphere; `--preset held` traces 12 other
/// directions (a spherical Fibonacci set of another count shares none of them).
fn relight_toml(target: Vec3) -> String {
    format!(
        r#"{header}
name = "still-life-relight"
gltf = "still-life.gltf"
{SIZE}
# The only light: a sun whose direction is the light dimension.
[[light]]
name = "Sun"
kind = "directional"
direction = [0, -1, 0]
intensity = 3

{views}
[[dimension]]
name = "sun"
driver = "light_direction"
light = "Sun"
samples = 64

[preset.held]
samples = {{ sun = 12 }}

{PAPER}"#,
        header = header(
            "still-life-relight — still-life under a sun turned over the upper hemisphere",
            "Exercises: a light_direction dimension (64 directions of the upper hemisphere) x 4\n\
             views; pis-pack stores the objects' surface layers as spherical-harmonic\n\
             coefficients over the sun's direction, and pis-bench relight judges them at the\n\
             12 directions of --preset held, under relight-two.toml's two lights and under\n\
             relight-sky.toml's sky.",
        ),
        views = views(target),
    )
}

/// The radius of still-life's bounding sphere (half the diagonal of its box: the ground's
/// 3 × 3 m and the objects up to 0.54 m), metres.
const SCENE_RADIUS: f32 = 2.14;

/// How far the sphere light stands from the target: clear of the scene's bounding sphere
/// from every direction (6 − 2 × 2.14 = 1.7 m apart).
const SOFT_DISTANCE: f32 = 6.0;

/// relight-soft.toml's presets: 12 other directions (`held`), and view 0 alone at
/// 640×480 over the 64 directions (`paper-view`) and the 12 (`paper-view-held`).
const SOFT_PRESETS: &str = "
[preset.held]
samples = { sun = 12 }

[preset.paper-view]
resolution = [640, 480]
samples = { view = 1 }

[preset.paper-view-held]
resolution = [640, 480]
samples = { view = 1, sun = 12 }
";

/// A sphere light of the scene's radius turned over 64 directions of the upper hemisphere
/// (`--preset held`: 12 others), or along relight-arc.toml's arc (`arc`). Its intensity
/// gives the target the sun's 3 lux (I = E d²); camera rays pass through it, so that where
/// it stands behind the objects it does not cover the background that no file draws.
fn soft_toml(target: Vec3, arc: bool) -> String {
    let (name, title, directions) = if arc {
        (
            "still-life-relight-soft-arc",
            "still-life-relight-soft-arc — still-life under a sphere light moving along an arc",
            "samples = 24\ndirections = \"arc\"\nelevation_deg = 35\nazimuth_deg = [0, 90]",
        )
    } else {
        (
            "still-life-relight-soft",
            "still-life-relight-soft — still-life under a sphere light of the scene's radius",
            "samples = 64",
        )
    };
    let what = if arc {
        "Exercises: the reference for relight-soft.toml's file as its light moves\n\
         continuously (pis-bench relight FILE --held SET reports the frame-to-frame change)."
    } else {
        "Exercises: a light_direction dimension turning a sphere light as large as the scene\n\
         (soft shadows, wide highlights) over 64 directions of the upper hemisphere x 4\n\
         views; pis-bench relight judges the relit file at the 12 directions of --preset held."
    };
    format!(
        r#"{header}
name = "{name}"
gltf = "still-life.gltf"
{SIZE}
# The only light: a sphere of the scene's radius whose direction is the light dimension,
# unseen by camera rays.
[[light]]
name = "Sun"
kind = "sphere"
position = [0, {SOFT_DISTANCE}, 0]
radius = {SCENE_RADIUS}
visible_camera = false
intensity = {intensity}

{views}
[[dimension]]
name = "sun"
driver = "light_direction"
light = "Sun"
{directions}
center = [{x}, {y}, {z}]
distance = {SOFT_DISTANCE}
{held}
{PAPER}"#,
        header = header(title, what),
        intensity = 3.0 * SOFT_DISTANCE * SOFT_DISTANCE,
        views = views(target),
        held = if arc { "" } else { SOFT_PRESETS },
        x = target.x,
        y = target.y,
        z = target.z,
    )
}

/// Where relight-soft.toml places its light seen at azimuth `az` and elevation `el`
/// (degrees) from the target.
fn placed(target: Vec3, az: f32, el: f32) -> String {
    let p = target + SOFT_DISTANCE * toward(az, el);
    format!("[{:.4}, {:.4}, {:.4}]", p.x, p.y, p.z)
}

/// relight-two.toml's key and fill as relight-soft.toml's sphere light placed from their
/// directions, of the intensities that give the target their illuminance.
fn soft_two_toml(target: Vec3) -> String {
    let sphere = |name: &str, az: f32, el: f32, color: &str, lux: f32| {
        format!(
            "[[light]]\nname = \"{name}\"\nkind = \"sphere\"\nposition = {}\n\
             radius = {SCENE_RADIUS}\nvisible_camera = false\ncolor = {color}\n\
             intensity = {:.1}\n",
            placed(target, az, el),
            lux * SOFT_DISTANCE * SOFT_DISTANCE
        )
    };
    format!(
        r#"{header}
name = "still-life-relight-soft-two"
gltf = "still-life.gltf"
{SIZE}
# A warm key (azimuth 40°, elevation 50°) and a cool fill (azimuth -130°, elevation 25°).
{key}
{fill}
{views}
{PAPER}"#,
        header = header(
            "still-life-relight-soft-two — still-life under two coloured sphere lights",
            "Exercises: the reference for relighting relight-soft.toml's file with its light\n\
             placed from two directions in two colours (pis-bench relight FILE --held SET\n\
             --fitted relight-soft.toml's set).",
        ),
        key = sphere("Key", 40.0, 50.0, "[1.0, 0.72, 0.45]", 2.5),
        fill = sphere("Fill", -130.0, 25.0, "[0.45, 0.62, 1.0]", 1.6),
        views = views(target),
    )
}

/// The sun along an arc at elevation 35°, azimuth 0° to 90° in 24 steps of 3.2°: the light
/// moving continuously, its own frame-to-frame change the measure of a relit file's popping.
fn arc_toml(target: Vec3) -> String {
    format!(
        r#"{header}
name = "still-life-relight-arc"
gltf = "still-life.gltf"
{SIZE}
[[light]]
name = "Sun"
kind = "directional"
direction = [0, -1, 0]
intensity = 3

{views}
[[dimension]]
name = "sun"
driver = "light_direction"
light = "Sun"
samples = 24
directions = "arc"
elevation_deg = 35
azimuth_deg = [0, 90]

{PAPER}"#,
        header = header(
            "still-life-relight-arc — still-life under a sun moving along an arc",
            "Exercises: the reference for relight.toml's file as its light moves continuously\n\
             (pis-bench relight FILE --held SET reports the frame-to-frame change).",
        ),
        views = views(target),
    )
}

/// The direction a light shines along, for one seen at azimuth `az` (from +X towards +Z)
/// and elevation `el`, degrees.
fn shining(az: f32, el: f32) -> String {
    let w = toward(az, el);
    format!("[{:.4}, {:.4}, {:.4}]", -w.x, -w.y, -w.z)
}

/// The unit direction towards azimuth `az` (from +X towards +Z) and elevation `el`, degrees.
fn toward(az: f32, el: f32) -> Vec3 {
    let (az, el) = (az.to_radians(), el.to_radians());
    Vec3::new(el.cos() * az.cos(), el.sin(), el.cos() * az.sin())
}

/// A warm key light and a cool fill from directions the 64 samples do not hold.
fn two_lights_toml(target: Vec3) -> String {
    format!(
        r#"{header}
name = "still-life-relight-two"
gltf = "still-life.gltf"
{SIZE}
# A warm key (azimuth 40°, elevation 50°) and a cool fill (azimuth -130°, elevation 25°).
[[light]]
name = "Key"
kind = "directional"
direction = {key}
color = [1.0, 0.72, 0.45]
intensity = 2.5

[[light]]
name = "Fill"
kind = "directional"
direction = {fill}
color = [0.45, 0.62, 1.0]
intensity = 1.6

{views}
{PAPER}"#,
        header = header(
            "still-life-relight-two — still-life under two coloured suns",
            "Exercises: the reference for relighting relight.toml's file with two directional\n\
             lights of different colours (pis-bench relight FILE --held SET).",
        ),
        key = shining(40.0, 50.0),
        fill = shining(-130.0, 25.0),
        views = views(target),
    )
}

/// An HDR sky (relight-sky.exr), turned 30° about +Y, as the only light.
fn sky_toml(target: Vec3) -> String {
    format!(
        r#"{header}
name = "still-life-relight-sky"
gltf = "still-life.gltf"
{SIZE}
[environment]
image = "relight-sky.exr"
rotation_deg = 30

{views}
{PAPER}"#,
        header = header(
            "still-life-relight-sky — still-life under an HDR sky",
            "Exercises: the reference for relighting relight.toml's file with a sky projected\n\
             into its basis (pis-bench relight FILE --held SET); relight-sky.exr is a blue\n\
             sky over a black ground with a warm glow 10 degrees wide at elevation 35 degrees.",
        ),
        views = views(target),
    )
}

/// The sky's width and height in texels.
const SKY: (usize, usize) = (96, 48);

/// Radiance of the sky towards the image-frame direction `d`: a blue gradient from a pale
/// horizon to the zenith and a warm Gaussian glow (σ 10°) around azimuth 60°, elevation 35°;
/// black below the horizon.
fn sky_radiance(d: Vec3) -> [f32; 3] {
    if d.y <= 0.0 {
        return [0.0; 3];
    }
    let (horizon, zenith) = (Vec3::new(0.32, 0.36, 0.42), Vec3::new(0.10, 0.17, 0.36));
    let sky = horizon.lerp(zenith, d.y.sqrt());
    let (az, el) = (60f32.to_radians(), 35f32.to_radians());
    let sun = Vec3::new(el.cos() * az.cos(), el.sin(), el.cos() * az.sin());
    let angle = d.dot(sun).clamp(-1.0, 1.0).acos();
    let sigma = 10f32.to_radians();
    let glow = Vec3::new(10.0, 8.0, 5.5) * (-angle * angle / (2.0 * sigma * sigma)).exp();
    (sky + glow).to_array()
}

/// Writes the sky as an equirectangular OpenEXR image (docs/SCENE.md's lat-long convention).
fn write_sky(path: &Path) -> io::Result<()> {
    let (w, h) = SKY;
    let at = |x: usize, y: usize| {
        let (u, v) = ((x as f32 + 0.5) / w as f32, (y as f32 + 0.5) / h as f32);
        let phi = std::f32::consts::TAU * (u - 0.5);
        let (sin_t, cos_t) = (std::f32::consts::PI * v).sin_cos();
        let [r, g, b] = sky_radiance(Vec3::new(sin_t * phi.cos(), cos_t, sin_t * phi.sin()));
        (r, g, b)
    };
    use exr::prelude::*;
    // One thread, increasing scan lines: the same bytes on every run.
    let encoding = Encoding {
        compression: Compression::ZIP16,
        blocks: Blocks::ScanLines,
        line_order: LineOrder::Increasing,
    };
    let pixels = SpecificChannels::rgb(|p: Vec2<usize>| at(p.x(), p.y()));
    let layer = Layer::new((w, h), LayerAttributes::default(), encoding, pixels);
    Image::from_layer(layer).write().non_parallel().to_file(path).map_err(io::Error::other)
}
