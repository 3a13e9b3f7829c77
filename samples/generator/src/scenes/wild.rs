//! Scenes from the wild: glTF written the way exporters of artists' tools write it, which the
//! seed's scenes never exercise. A centimetre root scale and a mirrored instance; PBR texture
//! maps (base colour, metallic-roughness, normal, emissive) in separate files;
//! `KHR_materials_transmission` glass; non-uniform node scales in a hierarchy. None of them
//! carries a light: scene.toml's `[[light]]` entries and `[environment]` light them.

use std::io;
use std::path::Path;

use glam::{Quat, Vec2, Vec3};

use super::common::{cup, sphere, torus, vase};
use super::wild_toml::{header, orbit};
use crate::gltf_writer::{GltfWriter, MaterialDesc, NodeDesc};
use crate::mesh::{cuboid, quad, Mesh};
use crate::textures::from_fn;

/// The scene folders under `samples/wild/`, in generation order.
pub const WILD: [&str; 4] = ["cm-export", "pbr-props", "glass-shelf", "still-life"];

/// Writes every scene into `root/<name>/` (`root` is normally `samples/wild`).
pub fn write_all(root: &Path) -> io::Result<()> {
    cm_export(&root.join("cm-export"))?;
    pbr_props(&root.join("pbr-props"))?;
    glass_shelf(&root.join("glass-shelf"))?;
    still_life(&root.join("still-life"))
}

/// A node with an optional mesh and its transform (translation, rotation, scale); a scene
/// root when `root`.
fn node(
    w: &mut GltfWriter,
    name: &str,
    mesh: Option<usize>,
    (translation, rotation, scale): (Vec3, Quat, Vec3),
    children: Vec<usize>,
    root: bool,
) -> usize {
    w.add_node(
        NodeDesc {
            name: name.into(),
            mesh,
            translation: (translation != Vec3::ZERO).then_some(translation),
            rotation: (rotation != Quat::IDENTITY).then_some(rotation),
            scale: (scale != Vec3::ONE).then_some(scale),
            children,
            ..NodeDesc::default()
        },
        root,
    )
}

/// A mesh node at `translation` (child of some group).
fn leaf(w: &mut GltfWriter, name: &str, mesh: usize, translation: Vec3) -> usize {
    node(w, name, Some(mesh), (translation, Quat::IDENTITY, Vec3::ONE), vec![], false)
}

fn smoothstep(e0: f32, e1: f32, x: f32) -> f32 {
    let t = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// A tangent-space normal map (linear, +Y up the image) of the height field `h(u, v)` over
/// [0, 1)², `strength` scaling its slopes.
fn normal_map(
    path: &Path,
    size: u32,
    strength: f32,
    h: impl Fn(f32, f32) -> f32,
) -> io::Result<()> {
    let d = 1.0 / size as f32;
    from_fn(path, size, |x, y| {
        let (u, v) = ((x as f32 + 0.5) * d, (y as f32 + 0.5) * d);
        let dx = (h(u + d, v) - h(u - d, v)) / (2.0 * d);
        let dy = (h(u, v + d) - h(u, v - d)) / (2.0 * d);
        // Image y runs down; the map's +Y runs up.
        let n = Vec3::new(-dx * strength, dy * strength, 1.0).normalize();
        let e = (n * 0.5 + Vec3::splat(0.5)) * 255.0;
        [e.x.round() as u8, e.y.round() as u8, e.z.round() as u8]
    })
}

/// An L-shaped bookend in centimetres: a base plate and an upright at its -X end, a brace
/// on one side only (so a mirrored copy differs from a turned one).
fn bookend_cm() -> Mesh {
    let mut m = cuboid(Vec3::new(0.0, 0.0, -6.0), Vec3::new(14.0, 1.5, 6.0), 1, false);
    m.append(&cuboid(Vec3::new(0.0, 1.5, -6.0), Vec3::new(2.0, 20.0, 6.0), 1, false));
    m.append(&cuboid(Vec3::new(2.0, 1.5, 3.0), Vec3::new(8.0, 7.0, 5.0), 1, false));
    m
}

/// cm-export: a scene as a centimetre-based tool exports it.
fn cm_export(dir: &Path) -> io::Result<()> {
    std::fs::create_dir_all(dir)?;
    let mut w = GltfWriter::new();
    from_fn(&dir.join("floor_basecolor.png"), 128, |x, y| {
        let (i, j) = (x / 32, y / 32);
        let grain = ((x / 4 * 7 + y / 4 * 13) % 11) as u8;
        if (i + j) % 2 == 0 {
            [190 + grain, 178 + grain, 160]
        } else {
            [120 + grain, 96, 74]
        }
    })?;
    from_fn(&dir.join("wood_basecolor.png"), 128, |x, y| {
        let ring = ((x as f32 * 0.21 + (y as f32 * 0.05).sin() * 3.0).sin() * 0.5 + 0.5) * 40.0;
        [150 + ring as u8, 90 + (ring * 0.6) as u8, 50]
    })?;
    from_fn(&dir.join("spines_basecolor.png"), 64, |x, _| {
        let colours = [[150, 40, 40], [40, 70, 140], [60, 120, 60], [180, 150, 60]];
        let c = colours[(x / 32) as usize % 4];
        if x % 32 < 3 {
            [230, 220, 200]
        } else {
            c
        }
    })?;
    let floor_tex = w.add_png_texture("floor_basecolor.png");
    let wood_tex = w.add_png_texture("wood_basecolor.png");
    let spines_tex = w.add_png_texture("spines_basecolor.png");
    let floor_mat = w.add_material(&MaterialDesc::textured("M_Floor", floor_tex, 0.8));
    let wood_mat = w.add_material(&MaterialDesc::textured("M_Wood", wood_tex, 0.6));
    let book_mat = w.add_material(&MaterialDesc::textured("M_Books", spines_tex, 0.7));
    let globe_mat = w.add_material(&MaterialDesc::plain("M_Globe", [0.2, 0.45, 0.7], 0.45));

    // Everything below is in centimetres.
    let floor = w.add_mesh(
        "SM_Floor",
        &quad(
            Vec3::new(-60.0, 0.0, 60.0),
            Vec3::new(120.0, 0.0, 0.0),
            Vec3::new(0.0, 0.0, -120.0),
            4,
            4,
            Vec2::splat(2.0),
        ),
        floor_mat,
    );
    let bookend = w.add_mesh("SM_Bookend", &bookend_cm(), wood_mat);
    let mut books = Mesh::default();
    for (k, (width, height)) in
        [(3.0, 17.0), (4.0, 15.0), (2.5, 18.0), (3.5, 14.0)].into_iter().enumerate()
    {
        let x = -10.0 + [0.0, 3.2, 7.4, 10.1][k];
        books.append(&cuboid(
            Vec3::new(x, 1.5, -5.0),
            Vec3::new(x + width, 1.5 + height, 5.0),
            1,
            false,
        ));
    }
    let books = w.add_mesh("SM_Books", &books, book_mat);
    let globe = w.add_mesh("SM_Globe", &sphere(9.0, 12, 24), globe_mat);

    let floor_node = leaf(&mut w, "Floor", floor, Vec3::ZERO);
    let left = leaf(&mut w, "Bookend_L", bookend, Vec3::new(-14.0, 0.0, 0.0));
    // The right bookend is the same mesh mirrored in X, as a "mirror modifier" exports it.
    let right = node(
        &mut w,
        "Bookend_R",
        Some(bookend),
        (Vec3::new(14.0, 0.0, 0.0), Quat::IDENTITY, Vec3::new(-1.0, 1.0, 1.0)),
        vec![],
        false,
    );
    let books_node = leaf(&mut w, "Books", books, Vec3::ZERO);
    let globe_node = leaf(&mut w, "Globe", globe, Vec3::new(0.0, 9.0, 0.0));
    let pivot = node(
        &mut w,
        "GlobePivot",
        None,
        (Vec3::new(26.0, 0.0, 16.0), Quat::from_rotation_y(0.6), Vec3::ONE),
        vec![globe_node],
        false,
    );
    let shelf = node(
        &mut w,
        "Shelf",
        None,
        (Vec3::ZERO, Quat::from_rotation_y(-0.3), Vec3::ONE),
        vec![left, right, books_node, pivot],
        false,
    );
    node(
        &mut w,
        "RootNode",
        None,
        (Vec3::ZERO, Quat::IDENTITY, Vec3::splat(0.01)),
        vec![floor_node, shelf],
        true,
    );
    w.write(dir, "cm-export")?;

    let target = Vec3::new(0.05, 0.1, 0.0);
    let toml = format!(
        r#"{header}
name = "cm-export"
gltf = "cm-export.gltf"
resolution = [160, 120]
spp = 16

[camera]
yfov_deg = 40

# A sphere light moving over the shelf, and a fill light; the glTF has none.
[[light]]
name = "Key"
kind = "sphere"
position = [0.5, 0.9, 0.6]
radius = 0.06
color = [1.0, 0.95, 0.85]
intensity = 1.6

[[light]]
name = "Fill"
kind = "point"
position = [-0.8, 0.6, 0.3]
color = [0.7, 0.8, 1.0]
intensity = 0.5

[[dimension]]
name = "light"
driver = "light_path"
light = "Key"
samples = 2
path = [[0.5, 0.9, 0.6], [-0.2, 0.9, 0.7]]

{view}
[preset.paper]
resolution = [640, 480]
spp = 16
samples = {{ light = 8, view = 8 }}
"#,
        header = header(
            "cm-export — a shelf as a centimetre-based tool exports it",
            "Exercises: a root node scaled 0.01 over geometry in centimetres, a mesh instanced twice\n\
             (Bookend_R is Bookend_L's mesh under scale [-1, 1, 1]: a mirrored axis, the winding\n\
             reversed), a rotated group, base-colour textures, lights from scene.toml only.",
        ),
        view = orbit("view", 4, target, 0.9, 25.0, [-10.0, 10.0]),
    );
    std::fs::write(dir.join("scene.toml"), toml)
}

/// pbr-props: props with full PBR texture sets.
fn pbr_props(dir: &Path) -> io::Result<()> {
    std::fs::create_dir_all(dir)?;
    let mut w = GltfWriter::new();
    let n = 128u32;
    // The crate: planks with a metal frame near the edges of every face.
    let frame = |x: u32, y: u32| {
        let e = x.min(y).min(n - 1 - x).min(n - 1 - y);
        e < 14
    };
    from_fn(&dir.join("crate_basecolor.png"), n, |x, y| {
        if frame(x, y) {
            [150, 150, 155]
        } else {
            let plank = (y / 20) as u8;
            let g = (((x as f32) * 0.3 + plank as f32).sin() * 12.0) as i32;
            [(160 + g - 8 * plank as i32) as u8, (110 + g) as u8, 60]
        }
    })?;
    from_fn(&dir.join("crate_metallicroughness.png"), n, |x, y| {
        if frame(x, y) {
            [255, 90, 255]
        } else {
            [255, 200, 0]
        }
    })?;
    normal_map(&dir.join("crate_normal.png"), n, 0.04, |_, v| {
        let groove = (v * 6.4).fract();
        -smoothstep(0.0, 0.06, 0.06 - groove.min(1.0 - groove).min(0.06))
    })?;
    // The wall panel: raised tiles.
    from_fn(&dir.join("tiles_basecolor.png"), n, |x, y| {
        let (i, j) = (x / 32, y / 32);
        let mortar = x % 32 < 3 || y % 32 < 3;
        if mortar {
            [170, 165, 160]
        } else if (i + j) % 2 == 0 {
            [70, 110, 150]
        } else {
            [220, 215, 200]
        }
    })?;
    normal_map(&dir.join("tiles_normal.png"), n, 0.05, |u, v| {
        let (fu, fv) = ((u * 4.0).fract(), (v * 4.0).fract());
        let edge = fu.min(1.0 - fu).min(fv).min(1.0 - fv);
        smoothstep(0.02, 0.1, edge)
    })?;
    // The sign: glowing bars and dots on a dark plate.
    from_fn(&dir.join("sign_basecolor.png"), n, |_, _| [30, 30, 34])?;
    from_fn(&dir.join("sign_emissive.png"), n, |x, y| {
        let bar = (16..40).contains(&y) || (88..112).contains(&y);
        let dot = (y > 52 && y < 76) && ((x / 24) % 2 == 1) && x < 120;
        if bar || dot {
            [255, 190, 90]
        } else {
            [0, 0, 0]
        }
    })?;
    let t = |w: &mut GltfWriter, f: &str| w.add_png_texture(f);
    let (crate_bc, crate_mr, crate_n) = (
        t(&mut w, "crate_basecolor.png"),
        t(&mut w, "crate_metallicroughness.png"),
        t(&mut w, "crate_normal.png"),
    );
    let (tiles_bc, tiles_n) = (t(&mut w, "tiles_basecolor.png"), t(&mut w, "tiles_normal.png"));
    let (sign_bc, sign_e) = (t(&mut w, "sign_basecolor.png"), t(&mut w, "sign_emissive.png"));
    let crate_mat = w.add_material(&MaterialDesc {
        base_color_texture: Some(crate_bc),
        metallic_roughness_texture: Some(crate_mr),
        normal_texture: Some((crate_n, 1.0)),
        metallic: 1.0,
        ..MaterialDesc::plain("Crate", [1.0; 3], 1.0)
    });
    let tiles_mat = w.add_material(&MaterialDesc {
        base_color_texture: Some(tiles_bc),
        normal_texture: Some((tiles_n, 1.0)),
        ..MaterialDesc::plain("Tiles", [1.0; 3], 0.6)
    });
    let sign_mat = w.add_material(&MaterialDesc {
        base_color_texture: Some(sign_bc),
        emissive_texture: Some(sign_e),
        emissive: Some(([1.0, 1.0, 1.0], 1.5)),
        ..MaterialDesc::plain("NeonSign", [1.0; 3], 0.5)
    });
    let floor_mat = w.add_material(&MaterialDesc::plain("Concrete", [0.45, 0.44, 0.42], 0.9));

    let crate_mesh =
        w.add_mesh("Crate", &cuboid(Vec3::splat(-0.2), Vec3::splat(0.2), 1, false), crate_mat);
    let panel_mesh = w.add_mesh(
        "Panel",
        &cuboid(Vec3::new(-0.5, 0.0, -0.02), Vec3::new(0.5, 0.75, 0.02), 1, false),
        tiles_mat,
    );
    let sign_mesh = w.add_mesh(
        "Sign",
        &cuboid(Vec3::new(-0.18, -0.07, -0.01), Vec3::new(0.18, 0.07, 0.01), 1, false),
        sign_mat,
    );
    let floor_mesh = w.add_mesh(
        "Floor",
        &quad(
            Vec3::new(-1.2, 0.0, 1.2),
            Vec3::new(2.4, 0.0, 0.0),
            Vec3::new(0.0, 0.0, -2.4),
            2,
            2,
            Vec2::ONE,
        ),
        floor_mat,
    );
    let crate_node = node(
        &mut w,
        "Crate",
        Some(crate_mesh),
        (Vec3::new(0.15, 0.2, 0.1), Quat::from_rotation_y(0.5), Vec3::ONE),
        vec![],
        false,
    );
    let small = node(
        &mut w,
        "CrateSmall",
        Some(crate_mesh),
        (Vec3::new(-0.3, 0.1, 0.25), Quat::from_rotation_y(-0.3), Vec3::splat(0.5)),
        vec![],
        false,
    );
    let panel = leaf(&mut w, "Panel", panel_mesh, Vec3::new(0.0, 0.0, -0.35));
    let sign = node(
        &mut w,
        "Sign",
        Some(sign_mesh),
        (Vec3::new(0.0, 0.55, -0.32), Quat::from_rotation_x(-0.1), Vec3::ONE),
        vec![],
        false,
    );
    let floor = leaf(&mut w, "Floor", floor_mesh, Vec3::ZERO);
    node(
        &mut w,
        "Props",
        None,
        (Vec3::ZERO, Quat::IDENTITY, Vec3::ONE),
        vec![floor, panel, sign, crate_node, small],
        true,
    );
    w.write(dir, "pbr-props")?;

    let target = Vec3::new(0.0, 0.3, 0.0);
    let toml = format!(
        r#"{header}
name = "pbr-props"
gltf = "pbr-props.gltf"
resolution = [160, 120]
spp = 16

[camera]
yfov_deg = 45

# A dim sky and a sun; the glTF has no light (the sign glows by its emissive map).
[environment]
color = [0.2, 0.22, 0.26]

[[light]]
name = "Sun"
kind = "directional"
direction = [-0.4, -1.0, -0.5]
color = [1.0, 0.96, 0.9]
intensity = 2.5

{view}
[preset.paper]
resolution = [640, 480]
spp = 16
samples = {{ view = 8 }}
"#,
        header = header(
            "pbr-props — props with full PBR texture sets",
            "Exercises: base-colour, metallic-roughness (metal frame, rough planks: a diffuse object\n\
             by the map's mean), normal (grooves, raised tiles; no TANGENT attribute) and emissive\n\
             maps in separate PNG files, a mesh instanced at half scale, an [environment] and a\n\
             directional [[light]].",
        ),
        view = orbit("view", 8, target, 1.5, 22.0, [-12.0, 12.0]),
    );
    std::fs::write(dir.join("scene.toml"), toml)
}

/// glass-shelf: glass on a shelf, as exported with KHR_materials_transmission.
fn glass_shelf(dir: &Path) -> io::Result<()> {
    std::fs::create_dir_all(dir)?;
    let mut w = GltfWriter::new();
    from_fn(&dir.join("backdrop_basecolor.png"), 128, |x, y| {
        let stripe = ((x + y / 2) / 16) % 2 == 0;
        if stripe {
            [200, 190, 170]
        } else {
            [120, 60, 50]
        }
    })?;
    let back_tex = w.add_png_texture("backdrop_basecolor.png");
    let glass = |name| MaterialDesc {
        transmission: Some(1.0),
        ior: Some(1.45),
        ..MaterialDesc::plain(name, [1.0, 1.0, 1.0], 0.0)
    };
    let clear = w.add_material(&glass("Glass_Clear"));
    let tinted =
        w.add_material(&MaterialDesc { base_color: [0.7, 0.9, 0.75, 1.0], ..glass("Glass_Green") });
    let back_mat = w.add_material(&MaterialDesc::textured("Backdrop", back_tex, 0.9));
    let shelf_mat = w.add_material(&MaterialDesc::plain("ShelfOak", [0.55, 0.38, 0.22], 0.7));
    let cube_mat = w.add_material(&MaterialDesc::plain("RedPaint", [0.75, 0.1, 0.08], 0.5));

    let ball = w.add_mesh("GlassBall", &sphere(0.08, 16, 32), clear);
    let tumbler = w.add_mesh("Tumbler", &cup(1.2), tinted);
    let cube =
        w.add_mesh("Cube", &cuboid(Vec3::splat(-0.06), Vec3::splat(0.06), 1, false), cube_mat);
    let shelf = w.add_mesh(
        "Shelf",
        &cuboid(Vec3::new(-0.5, -0.03, -0.2), Vec3::new(0.5, 0.0, 0.2), 1, false),
        shelf_mat,
    );
    let back = w.add_mesh(
        "Backdrop",
        &quad(
            Vec3::new(-0.7, 0.0, -0.2),
            Vec3::new(1.4, 0.0, 0.0),
            Vec3::new(0.0, 0.8, 0.0),
            2,
            2,
            Vec2::ONE,
        ),
        back_mat,
    );
    let nodes = vec![
        leaf(&mut w, "GlassBall", ball, Vec3::new(-0.12, 0.08, 0.05)),
        leaf(&mut w, "Tumbler", tumbler, Vec3::new(0.13, 0.0, 0.02)),
        node(
            &mut w,
            "Cube",
            Some(cube),
            (Vec3::new(0.0, 0.06, -0.1), Quat::from_rotation_y(0.7), Vec3::ONE),
            vec![],
            false,
        ),
        leaf(&mut w, "Shelf", shelf, Vec3::ZERO),
        leaf(&mut w, "Backdrop", back, Vec3::new(0.0, -0.03, 0.0)),
    ];
    node(
        &mut w,
        "Scene_Root",
        None,
        (Vec3::new(0.0, 0.5, 0.0), Quat::IDENTITY, Vec3::ONE),
        nodes,
        true,
    );
    w.write(dir, "glass-shelf")?;

    let target = Vec3::new(0.0, 0.58, 0.0);
    let toml = format!(
        r#"{header}
name = "glass-shelf"
gltf = "glass-shelf.gltf"
resolution = [160, 120]
spp = 16

[camera]
yfov_deg = 40

# A soft key light and a point light from the other side; the glTF has none.
[[light]]
name = "Softbox"
kind = "sphere"
position = [0.6, 1.3, 0.9]
radius = 0.1
intensity = 3.0

[[light]]
name = "Rim"
kind = "point"
position = [-0.7, 0.9, 0.6]
color = [0.8, 0.85, 1.0]
intensity = 0.8

{view}
[preset.paper]
resolution = [640, 480]
spp = 16
samples = {{ view = 8 }}
"#,
        header = header(
            "glass-shelf — glass on a shelf, exported with KHR_materials_transmission",
            "Exercises: transmission glass (a ball and a green tumbler: KHR_materials_transmission\n\
             and KHR_materials_ior only, no volume), an opaque cube seen through them, a textured\n\
             backdrop, all under a translated root node, lights from scene.toml only.",
        ),
        view = orbit("view", 8, target, 0.85, 15.0, [-8.0, 8.0]),
    );
    std::fs::write(dir.join("scene.toml"), toml)
}

/// still-life: several objects in a hierarchy of non-uniform scales, lit by the sky alone.
fn still_life(dir: &Path) -> io::Result<()> {
    std::fs::create_dir_all(dir)?;
    let mut w = GltfWriter::new();
    from_fn(&dir.join("glaze_basecolor.png"), 128, |x, y| {
        let band = ((y as f32 * 0.25 + (x as f32 * 0.098).sin() * 2.0).sin() * 0.5 + 0.5) * 60.0;
        [40 + band as u8, 90 + band as u8, 120 + band as u8]
    })?;
    from_fn(&dir.join("cloth_basecolor.png"), 128, |x, y| {
        let check = ((x / 32) + (y / 32)) % 2 == 0;
        let line = x % 64 < 4 || y % 64 < 4;
        if line {
            [200, 40, 40]
        } else if check {
            [235, 230, 215]
        } else {
            [210, 200, 185]
        }
    })?;
    let glaze_tex = w.add_png_texture("glaze_basecolor.png");
    let cloth_tex = w.add_png_texture("cloth_basecolor.png");
    let glaze = w.add_material(&MaterialDesc::textured("Glaze", glaze_tex, 0.35));
    let cloth = w.add_material(&MaterialDesc::textured("Tablecloth", cloth_tex, 0.95));
    let fruit = w.add_material(&MaterialDesc::plain("Fruit", [0.7, 0.25, 0.08], 0.5));
    let brass = w.add_material(&MaterialDesc::metal("Brass", [0.8, 0.6, 0.3], 0.45));
    let clay = w.add_material(&MaterialDesc::plain("Clay", [0.6, 0.4, 0.3], 0.8));
    let ground = w.add_material(&MaterialDesc::plain("Ground", [0.35, 0.35, 0.33], 0.9));

    let unit_box =
        w.add_mesh("UnitBox", &cuboid(Vec3::splat(-0.5), Vec3::splat(0.5), 2, false), cloth);
    let vase_mesh = w.add_mesh("Vase", &vase(), glaze);
    let fruit_mesh = w.add_mesh("Fruit", &sphere(0.04, 10, 20), fruit);
    let ring_mesh = w.add_mesh("Ring", &torus(0.06, 0.012, 10, 32), brass);
    let bowl_mesh = w.add_mesh("Bowl", &cup(1.6), clay);
    let ground_mesh = w.add_mesh(
        "Ground",
        &quad(
            Vec3::new(-1.5, 0.0, 1.5),
            Vec3::new(3.0, 0.0, 0.0),
            Vec3::new(0.0, 0.0, -3.0),
            2,
            2,
            Vec2::ONE,
        ),
        ground,
    );

    // A unit box squashed into a low table top by its node's scale (normals need the
    // inverse transpose), and objects on it under a group scaled 1.25 and turned 30°.
    let top = node(
        &mut w,
        "TableTop",
        Some(unit_box),
        (Vec3::new(0.0, 0.05, 0.0), Quat::IDENTITY, Vec3::new(0.7, 0.1, 0.45)),
        vec![],
        false,
    );
    let vase_node = leaf(&mut w, "Vase", vase_mesh, Vec3::new(-0.15, 0.1, -0.05));
    let apple = node(
        &mut w,
        "Apple",
        Some(fruit_mesh),
        (Vec3::new(0.1, 0.135, 0.1), Quat::IDENTITY, Vec3::new(1.0, 0.85, 1.0)),
        vec![],
        false,
    );
    let pear = node(
        &mut w,
        "Pear",
        Some(fruit_mesh),
        (Vec3::new(0.2, 0.14, 0.02), Quat::from_rotation_z(0.4), Vec3::new(0.8, 1.2, 0.8)),
        vec![],
        false,
    );
    let ring = node(
        &mut w,
        "Ring",
        Some(ring_mesh),
        (Vec3::new(0.05, 0.115, -0.12), Quat::from_rotation_x(0.25), Vec3::ONE),
        vec![],
        false,
    );
    let bowl = node(
        &mut w,
        "Bowl",
        Some(bowl_mesh),
        (Vec3::new(0.16, 0.1, 0.06), Quat::IDENTITY, Vec3::new(1.0, 0.6, 1.0)),
        vec![],
        false,
    );
    let group = node(
        &mut w,
        "StillLife",
        None,
        (Vec3::ZERO, Quat::from_rotation_y(30f32.to_radians()), Vec3::splat(1.25)),
        vec![top, vase_node, apple, pear, ring, bowl],
        false,
    );
    let ground_node = leaf(&mut w, "Ground", ground_mesh, Vec3::ZERO);
    node(
        &mut w,
        "Root",
        None,
        (Vec3::ZERO, Quat::IDENTITY, Vec3::ONE),
        vec![ground_node, group],
        true,
    );
    w.write(dir, "still-life")?;

    let target = Vec3::new(0.0, 0.22, 0.0);
    let toml = format!(
        r#"{header}
name = "still-life"
gltf = "still-life.gltf"
resolution = [160, 120]
spp = 16

[camera]
yfov_deg = 40

# Lit by the sky alone: no light in the glTF, no [[light]].
[environment]
color = [0.9, 0.92, 1.0]

{view}
[preset.paper]
resolution = [640, 480]
spp = 16
samples = {{ view = 8 }}
"#,
        header = header(
            "still-life — several objects in a hierarchy of non-uniform scales, lit by the sky",
            "Exercises: seven objects, six under a group scaled 1.25 and turned 30°: a unit box\n\
             squashed to a table top and fruit stretched by their nodes' non-uniform scales,\n\
             base-colour textures, a rough brass ring; a uniform [environment] is the only light.",
        ),
        view = orbit("view", 8, target, 1.1, 28.0, [-15.0, 15.0]),
    );
    std::fs::write(dir.join("scene.toml"), toml)?;
    super::relight::write(dir, target)
}
