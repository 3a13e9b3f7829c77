//! Tests of `[environment]` in scene.toml: loading a colour, a Radiance HDR and an OpenEXR
//! image, and the errors for bad keys and bad or unsafe image files.

use std::path::Path;

use glam::Vec3;

use crate::environment::{lat_long_direction, EnvironmentRadiance};
use crate::load;
use crate::load_tests::{load_err, Fixture, TOML};

/// A scene.toml with the fixture's glTF and `environment` appended.
fn with_environment(environment: &str) -> Fixture {
    Fixture::new(&format!("{TOML}\n[environment]\n{environment}\n"), |_, _| {})
}

/// Writes a Radiance HDR image of `w × h` texels, `texel(x, y)` each, row 0 at the top.
fn write_hdr(path: &Path, w: u32, h: u32, texel: impl Fn(u32, u32) -> [f32; 3]) {
    let pixels: Vec<image::Rgb<f32>> = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| image::Rgb(texel(x, y)))
        .collect();
    let file = std::io::BufWriter::new(std::fs::File::create(path).expect("create"));
    image::codecs::hdr::HdrEncoder::new(file)
        .encode(&pixels, w as usize, h as usize)
        .expect("encode");
}

fn err_of(environment: &str, setup: impl FnOnce(&Path)) -> String {
    let f = with_environment(environment);
    setup(f.dir.path());
    load_err(&f).to_string()
}

#[test]
fn a_uniform_colour_loads_with_its_strength_and_lights_the_scene_alone() {
    let f = Fixture::new(
        &format!("{TOML}\n[environment]\ncolor = [0.5, 1, 2]\nstrength = 2\nrotation_deg = 30\n"),
        |doc, _| {
            let doc = doc.as_object_mut().expect("an object");
            doc.remove("extensions");
            doc.remove("extensionsUsed");
            doc["nodes"][2] = serde_json::json!({"name": "Empty"});
        },
    );
    let s = load(&f.toml(), None).unwrap();
    assert!(s.rig.lights.is_empty());
    let env = s.environment.as_ref().expect("an environment");
    assert_eq!(env.radiance, EnvironmentRadiance::Uniform([1.0, 2.0, 4.0]));
    assert!((env.rotation - 30f32.to_radians()).abs() < 1e-6 && !env.background);
    assert!(s.emits(), "the environment alone emits");
    let none = load(&with_environment("color = [0, 0, 0]").toml(), None).unwrap();
    assert!(none.environment.as_ref().is_some_and(|e| !e.emits()));
}

/// An HDR image bright in its top half (+Y) and an EXR one in its right half (+Z side):
/// read row 0 at the top, strength applied, radiance from the directions the docs say.
#[test]
fn hdr_and_exr_images_load_in_the_documented_orientation() {
    let f = with_environment("image = \"sky.hdr\"\nstrength = 0.5\nbackground = true");
    write_hdr(
        &f.dir.path().join("sky.hdr"),
        16,
        8,
        |_, y| if y < 4 { [4.0, 2.0, 1.0] } else { [0.0; 3] },
    );
    let s = load(&f.toml(), None).unwrap();
    let env = s.environment.as_ref().unwrap();
    assert!(env.background);
    assert_eq!(env.radiance(Vec3::new(0.3, 0.9, 0.1).normalize()), [2.0, 1.0, 0.5]);
    assert_eq!(env.radiance(Vec3::new(0.3, -0.9, 0.1).normalize()), [0.0; 3]);
    let EnvironmentRadiance::Image(image) = &env.radiance else { panic!("an image") };
    assert_eq!((image.width, image.height), (16, 8));
    assert!(image.file.ends_with("sky.hdr"));

    let f = with_environment("image = \"sky.exr\"");
    // Columns 8..16 of 16: u ∈ [0.5, 1), from +X through +Z to −X.
    exr::prelude::write_rgb_file(f.dir.path().join("sky.exr"), 16, 8, |x, _| {
        if x >= 8 {
            (1.0f32, 1.0f32, 1.0f32)
        } else {
            (0.0, 0.0, 0.0)
        }
    })
    .expect("exr");
    let s = load(&f.toml(), None).unwrap();
    let env = s.environment.as_ref().unwrap();
    assert_eq!(env.radiance(Vec3::new(0.1, 0.2, 0.9).normalize()), [1.0; 3]);
    assert_eq!(env.radiance(Vec3::new(0.1, 0.2, -0.9).normalize()), [0.0; 3]);
    assert_eq!(env.radiance(lat_long_direction([0.75, 0.5])), [1.0; 3]);
}

#[test]
fn bad_keys_are_errors_naming_the_field() {
    for (bad, field) in [
        ("color = [1, -1, 0]", "environment.color"),
        ("color = [1, 1, 1]\nstrength = -2", "environment.strength"),
        ("color = [1, 1, 1]\nstrength = nan", "environment.strength"),
        ("color = [1, 1, 1]\nrotation_deg = inf", "environment.rotation_deg"),
        ("color = [1, 1, 1]\nimage = \"sky.hdr\"", "environment.image"),
        ("strength = 1", "environment"),
        ("image = \"\"", "environment.image"),
    ] {
        let e = err_of(bad, |_| {});
        assert!(e.contains(&format!("`{field}`")), "{bad}: {e}");
    }
    let e = err_of("colour = [1, 1, 1]", |_| {});
    assert!(e.contains("colour"), "an unknown key: {e}");
}

/// A missing, unreadable, oversized, non-finite or unsupported image is an error naming
/// `environment.image` and the file; nothing panics.
#[test]
fn bad_image_files_are_errors_naming_the_file() {
    let e = err_of("image = \"missing.hdr\"", |_| {});
    assert!(e.contains("environment.image") && e.contains("missing.hdr"), "{e}");
    let e = err_of("image = \"junk.hdr\"", |dir| {
        std::fs::write(dir.join("junk.hdr"), b"not an image").unwrap()
    });
    assert!(e.contains("environment.image") && e.contains("junk.hdr"), "{e}");
    // A header that claims 100000 × 100000 texels: refused before any texel is allocated.
    let e = err_of("image = \"huge.hdr\"", |dir| {
        std::fs::write(
            dir.join("huge.hdr"),
            b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 100000 +X 100000\n",
        )
        .unwrap()
    });
    assert!(e.contains("huge.hdr") && e.contains("100000x100000"), "{e}");
    let e = err_of("image = \"nan.exr\"", |dir| {
        exr::prelude::write_rgb_file(dir.join("nan.exr"), 4, 2, |x, y| {
            if (x, y) == (3, 1) {
                (f32::NAN, 0.0f32, 0.0f32)
            } else {
                (1.0, 1.0, 1.0)
            }
        })
        .unwrap()
    });
    assert!(e.contains("nan.exr") && e.contains("(3, 1)"), "{e}");
    let e = err_of("image = \"sky.png\"", |dir| std::fs::write(dir.join("sky.png"), b"").unwrap());
    assert!(e.contains("sky.png") && e.contains(".hdr"), "{e}");
}

/// The image must lie in scene.toml's folder, as the glTF's files must lie in the glTF's,
/// unless `allow_outside_files = true`.
#[test]
fn an_image_outside_the_scene_folder_is_refused() {
    let outside = tempfile::tempdir().unwrap();
    let sky = outside.path().join("sky.hdr");
    write_hdr(&sky, 4, 2, |_, _| [1.0; 3]);
    let e = err_of(&format!("image = {:?}", sky.display().to_string()), |_| {});
    assert!(e.contains("environment.image") && e.contains("absolute path"), "{e}");
    let e = err_of("image = \"../sky.hdr\"", |_| {});
    assert!(e.contains("environment.image") && e.contains("leaves scene.toml's folder"), "{e}");
    // Through a link inside the folder to the file outside it.
    #[cfg(unix)]
    {
        let e = err_of("image = \"link.hdr\"", |dir| {
            std::os::unix::fs::symlink(&sky, dir.join("link.hdr")).unwrap()
        });
        assert!(e.contains("leaves scene.toml's folder"), "{e}");
    }
    let f = Fixture::new(
        &format!(
            "allow_outside_files = true\n{TOML}\n[environment]\nimage = {:?}\n",
            sky.display().to_string()
        ),
        |_, _| {},
    );
    assert!(load(&f.toml(), None).is_ok(), "allow_outside_files = true reads it");
}
