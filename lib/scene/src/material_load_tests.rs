//! Tests of material textures, alpha modes and extensions read from a glTF written on the
//! fly: [`crate::load_tests`]'s triangle with two texture-coordinate sets and two PNG images,
//! `a.png` (2×1: grey 128, white; alpha 0, 255) and `b.png` (1×1 blue).

use serde_json::{json, Value};

use crate::load_tests::{f32s, load_err, Fixture, TOML};
use crate::{load, AlphaMode, SceneError, UvTransform};

/// The fixture with TEXCOORD_0, TEXCOORD_1 (unless `second_set` is false), the two images,
/// one texture for each, and `material` as its only material.
fn textured(material: Value, second_set: bool, edit: impl FnOnce(&mut Value)) -> Fixture {
    let f = Fixture::new(TOML, |doc, bin| {
        for (k, uvs) in [[0.0f32, 0.0, 1.0, 0.0, 0.0, 1.0], [0.5; 6]].iter().enumerate() {
            if k == 1 && !second_set {
                break;
            }
            let offset = bin.len();
            bin.extend(f32s(uvs));
            let views = doc["bufferViews"].as_array_mut().unwrap();
            views.push(json!({"buffer": 0, "byteOffset": offset, "byteLength": 24}));
            let view = views.len() - 1;
            let accessors = doc["accessors"].as_array_mut().unwrap();
            accessors.push(
                json!({"bufferView": view, "componentType": 5126, "count": 3, "type": "VEC2"}),
            );
            let accessor = accessors.len() - 1;
            doc["meshes"][0]["primitives"][0]["attributes"][format!("TEXCOORD_{k}")] =
                json!(accessor);
        }
        doc["buffers"][0]["byteLength"] = json!(bin.len());
        doc["images"] = json!([{"uri": "a.png"}, {"uri": "b.png"}]);
        doc["textures"] = json!([{"source": 0}, {"source": 1}]);
        doc["materials"] = json!([material]);
        doc["extensionsUsed"].as_array_mut().unwrap().push(json!("KHR_texture_transform"));
        edit(doc);
    });
    let a = image::RgbaImage::from_raw(2, 1, vec![128, 128, 128, 0, 255, 255, 255, 255]).unwrap();
    a.save(f.dir.path().join("a.png")).expect("write a.png");
    let b = image::RgbaImage::from_raw(1, 1, vec![0, 0, 255, 255]).unwrap();
    b.save(f.dir.path().join("b.png")).expect("write b.png");
    f
}

#[test]
fn material_maps_are_read_with_their_sets_and_transforms() {
    let material = json!({
        "name": "painted",
        "pbrMetallicRoughness": {
            "baseColorTexture": {"index": 0, "extensions": {"KHR_texture_transform": {"offset": [0.5, 0], "scale": [2, 2]}}},
            "metallicRoughnessTexture": {"index": 0, "texCoord": 1},
            "metallicFactor": 1, "roughnessFactor": 1
        },
        "emissiveFactor": [1, 1, 1],
        "emissiveTexture": {"index": 1},
        "normalTexture": {"index": 1, "scale": 0.5, "extensions": {"KHR_texture_transform": {"texCoord": 1, "rotation": 0.5}}},
        "occlusionTexture": {"index": 1},
        "alphaMode": "MASK"
    });
    let f = textured(material, true, |_| {});
    let s = load(&f.toml(), None).unwrap();
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    let m = &s.materials[0];
    let base = m.base_color_texture.expect("base colour texture");
    assert_eq!(
        (base.tex_coord, base.transform),
        (0, UvTransform { offset: [0.5, 0.0], rotation: 0.0, scale: [2.0, 2.0] })
    );
    let mr = m.metallic_roughness_texture.expect("metallic-roughness texture");
    assert_eq!(mr.tex_coord, 1);
    // One image, two colour spaces: sRGB for base colour, linear for metallic-roughness.
    assert_ne!(base.texture, mr.texture);
    assert!(
        (s.textures[base.texture].texels[0][0] - crate::texture::srgb_to_linear(128.0 / 255.0))
            .abs()
            < 1e-6
    );
    assert!((s.textures[mr.texture].texels[0][0] - 128.0 / 255.0).abs() < 1e-6);
    assert_eq!(s.textures[base.texture].texels[0][3], 0.0, "alpha is read");
    assert!(m.emissive_texture.is_some());
    let normal = m.normal_texture.expect("normal texture");
    assert_eq!((normal.tex_coord, normal.transform.rotation, m.normal_scale), (1, 0.5, 0.5));
    assert_eq!(m.alpha_mode, AlphaMode::Mask { cutoff: 0.5 });
    assert_eq!(s.textures.len(), 4, "a.png twice, b.png twice; the occlusion map is not read");
    assert_eq!(s.objects[0].primitives[0].uvs1.len(), 3);
}

#[test]
fn alpha_modes_and_cutoff_are_read() {
    let f = textured(json!({"alphaMode": "MASK", "alphaCutoff": 0.25}), false, |_| {});
    assert_eq!(
        load(&f.toml(), None).unwrap().materials[0].alpha_mode,
        AlphaMode::Mask { cutoff: 0.25 }
    );
    let f = textured(json!({"alphaMode": "BLEND"}), false, |_| {});
    assert_eq!(load(&f.toml(), None).unwrap().materials[0].alpha_mode, AlphaMode::Blend);
    let f = textured(json!({}), false, |_| {});
    assert_eq!(load(&f.toml(), None).unwrap().materials[0].alpha_mode, AlphaMode::Opaque);
}

#[test]
fn unsupported_extension_is_named_once() {
    let material = json!({"extensions": {"KHR_materials_clearcoat": {"clearcoatFactor": 1}}});
    let f = textured(material, false, |doc| {
        doc["materials"]
            .as_array_mut()
            .unwrap()
            .push(json!({"extensions": {"KHR_materials_clearcoat": {"clearcoatFactor": 0.5}}}));
        let used = doc["extensionsUsed"].as_array_mut().unwrap();
        used.extend([
            json!("KHR_materials_clearcoat"),
            json!("KHR_materials_sheen"),
            json!("KHR_xmp_json_ld"),
        ]);
    });
    let s = load(&f.toml(), None).unwrap();
    assert_eq!(s.warnings.len(), 2, "{:?}", s.warnings);
    assert!(
        s.warnings[0].contains("KHR_materials_clearcoat")
            && s.warnings[1].contains("KHR_materials_sheen"),
        "{:?}",
        s.warnings
    );
}

/// The glTF reader accepts only its own extensions as required; PIS reads more.
#[test]
fn required_extensions_pis_reads_are_accepted() {
    let f = textured(json!({}), false, |doc| {
        doc["extensionsRequired"] = json!([
            "KHR_texture_transform",
            "KHR_materials_volume",
            "KHR_materials_specular",
            "KHR_materials_variants"
        ]);
    });
    load(&f.toml(), None).expect("loads");
    let f = textured(json!({}), false, |doc| {
        doc["extensionsRequired"] = json!(["KHR_materials_ior", "KHR_materials_clearcoat"])
    });
    let e = load_err(&f);
    assert!(matches!(e, SceneError::Unsupported { .. }), "{e}");
    assert!(
        e.to_string().contains("extensionsRequired[1]")
            && e.to_string().contains("KHR_materials_clearcoat"),
        "{e}"
    );
}

#[test]
fn second_texture_set_missing_from_the_mesh_is_warned_of() {
    let f = textured(
        json!({"emissiveTexture": {"index": 1, "texCoord": 1}, "emissiveFactor": [1, 1, 1]}),
        false,
        |_| {},
    );
    let s = load(&f.toml(), None).unwrap();
    assert_eq!(s.warnings.len(), 1, "{:?}", s.warnings);
    assert!(
        s.warnings[0].contains("meshes[0].primitives[0] has no TEXCOORD_1"),
        "{:?}",
        s.warnings
    );
    let f = textured(json!({"emissiveTexture": {"index": 1, "texCoord": 3}}), true, |_| {});
    let s = load(&f.toml(), None).unwrap();
    assert!(
        s.warnings.iter().any(|w| w.contains("emissiveTexture reads TEXCOORD_3")),
        "{:?}",
        s.warnings
    );
    assert_eq!(s.materials[0].emissive_texture.unwrap().tex_coord, 0);
}

#[test]
fn bad_texture_transform_is_an_error_naming_the_field() {
    let material = json!({"emissiveTexture": {"index": 1, "extensions": {"KHR_texture_transform": {"scale": "big"}}}});
    let e = load_err(&textured(material, false, |_| {})).to_string();
    assert!(
        e.contains("materials[0].emissiveTexture.extensions.KHR_texture_transform.scale"),
        "{e}"
    );
}

/// Damaged material and texture fields, and a damaged image, give an error or load; never a
/// panic.
#[test]
fn damaged_material_textures_error_without_panicking() {
    let material = json!({
        "pbrMetallicRoughness": {"baseColorTexture": {"index": 0, "texCoord": 1, "extensions": {"KHR_texture_transform": {"offset": [0.5, 0], "rotation": 1, "scale": [2, 2], "texCoord": 1}}},
                                 "metallicRoughnessTexture": {"index": 1}},
        "normalTexture": {"index": 1, "scale": 2, "texCoord": 0},
        "emissiveTexture": {"index": 0},
        "alphaCutoff": 0.5
    });
    let paths: Vec<Vec<Value>> = vec![
        vec![json!("pbrMetallicRoughness"), json!("baseColorTexture"), json!("index")],
        vec![json!("pbrMetallicRoughness"), json!("baseColorTexture"), json!("texCoord")],
        vec![
            json!("pbrMetallicRoughness"),
            json!("baseColorTexture"),
            json!("extensions"),
            json!("KHR_texture_transform"),
            json!("rotation"),
        ],
        vec![
            json!("pbrMetallicRoughness"),
            json!("baseColorTexture"),
            json!("extensions"),
            json!("KHR_texture_transform"),
            json!("texCoord"),
        ],
        vec![
            json!("pbrMetallicRoughness"),
            json!("baseColorTexture"),
            json!("extensions"),
            json!("KHR_texture_transform"),
            json!("offset"),
            json!(0),
        ],
        vec![json!("pbrMetallicRoughness"), json!("metallicRoughnessTexture"), json!("index")],
        vec![json!("normalTexture"), json!("index")],
        vec![json!("normalTexture"), json!("scale")],
        vec![json!("emissiveTexture"), json!("index")],
        vec![json!("alphaCutoff")],
    ];
    for path in &paths {
        for value in [
            json!(0),
            json!(7),
            json!(1_000_000),
            json!(-1),
            json!(0.5),
            json!(1e39),
            json!("x"),
            json!(null),
        ] {
            let mut m = material.clone();
            let mut slot = &mut m;
            for key in path {
                slot = match key {
                    Value::Number(i) => &mut slot[i.as_u64().unwrap() as usize],
                    k => &mut slot[k.as_str().unwrap()],
                };
            }
            *slot = value.clone();
            let f = textured(m, true, |_| {});
            let result = std::panic::catch_unwind(|| load(&f.toml(), None).map(|_| ()));
            assert!(result.is_ok(), "panic with {path:?} = {value}");
        }
    }
    let f = textured(material, true, |_| {});
    let png = std::fs::read(f.dir.path().join("a.png")).unwrap();
    for cut in [0, 8, 20, png.len() / 2, png.len() - 4] {
        std::fs::write(f.dir.path().join("a.png"), &png[..cut]).unwrap();
        let result = std::panic::catch_unwind(|| load(&f.toml(), None).map(|_| ()));
        assert!(result.is_ok(), "panic with a.png cut to {cut} bytes");
        assert!(cut > 20 || matches!(result, Ok(Err(_))), "a.png cut to {cut} bytes loads");
    }
}

#[test]
fn an_image_that_cannot_be_read_leaves_its_texture_unread_with_a_warning() {
    let material = json!({
        "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "baseColorFactor": [1, 0.5, 0.25, 1]},
        "emissiveTexture": {"index": 1}
    });
    // Image 0 names a file that is not there (as an exporter writes a Windows path), image 1
    // one of a format PIS does not decode.
    let f = textured(material, false, |doc| {
        doc["images"] = json!([{"uri": "textures%5Cwood.tga"}, {"uri": "b.png"}]);
    });
    let s = load(&f.toml(), None).unwrap();
    let m = &s.materials[0];
    assert!(m.base_color_texture.is_none());
    assert_eq!(m.base_color, [1.0, 0.5, 0.25, 1.0]);
    assert!(m.emissive_texture.is_some(), "the readable image is still read");
    assert_eq!(s.warnings.len(), 1, "{:?}", s.warnings);
    let w = &s.warnings[0];
    assert!(
        w.contains("images[0]") && w.contains("wood.tga") && w.contains("baseColorTexture"),
        "{w}"
    );
}
