//! Each object reaches the container with its scene role, its material's shading constants
//! and, for reflective and refractive objects, its vertex normals (SPEC.md 6.4, 6.5): demo1
//! with its vase made a half-metallic glaze of IOR 1.7, traced small and packed.

use std::path::{Path, PathBuf};

use pis_format::{ObjectRole, PisReader};
use pis_pack::{NoProgress, PackSettings};

const VASE_BASE: [f32; 3] = [0.8, 0.5, 0.2];
const VASE_METALLIC: f32 = 0.5;
const VASE_IOR: f32 = 1.7;

/// samples/demo1 copied into `dir` over a 2 × 2 space, its vase's material (GlazedCeramic)
/// given [`VASE_BASE`], [`VASE_METALLIC`] and [`VASE_IOR`]; returns the copy's scene.toml.
fn demo1_with_a_metallic_vase(dir: &Path) -> PathBuf {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../samples/demo1");
    for e in std::fs::read_dir(&src).expect("samples/demo1").filter_map(Result::ok) {
        if e.path().is_file() {
            std::fs::copy(e.path(), dir.join(e.file_name())).expect("copy demo1");
        }
    }
    let toml = dir.join("scene.toml");
    let text = std::fs::read_to_string(&toml).expect("scene.toml");
    assert_eq!(
        text.matches("samples = 4\n").count(),
        2,
        "demo1 samples both dimensions 4 times: adapt the test"
    );
    std::fs::write(&toml, text.replace("samples = 4\n", "samples = 2\n"))
        .expect("write scene.toml");
    let gltf = dir.join("demo1.gltf");
    let mut doc: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&gltf).expect("the glTF")).expect("glTF JSON");
    let glaze = doc["materials"]
        .as_array_mut()
        .expect("materials")
        .iter_mut()
        .find(|m| m["name"] == "GlazedCeramic")
        .expect("demo1's vase material");
    glaze["pbrMetallicRoughness"]["baseColorFactor"] =
        serde_json::json!([VASE_BASE[0], VASE_BASE[1], VASE_BASE[2], 1.0]);
    glaze["pbrMetallicRoughness"]["metallicFactor"] = serde_json::json!(VASE_METALLIC);
    glaze["extensions"] = serde_json::json!({ "KHR_materials_ior": { "ior": VASE_IOR } });
    std::fs::write(&gltf, serde_json::to_vec(&doc).expect("JSON")).expect("write the glTF");
    toml
}

fn close(a: [f32; 3], b: [f32; 3]) -> bool {
    a.iter().zip(&b).all(|(a, b)| (a - b).abs() < 1e-5)
}

#[test]
fn objects_carry_their_role_shading_and_normals_into_the_file() {
    let dir = tempfile::tempdir().expect("temp dir");
    let scene = demo1_with_a_metallic_vase(dir.path());
    let file = dir.path().join("demo1.pis");
    let mut settings = PackSettings::new().with_ratio(48.0);
    settings.resolution = Some((32, 24));
    settings.spp = Some(1);
    pis_pack::pack(&scene, &file, &settings, &NoProgress).expect("demo1 packs");
    let reader = PisReader::open(&file).expect("the file reads back");
    let objects = &reader.container().objects;
    let object = |name: &str| {
        objects.iter().find(|o| o.name == name).unwrap_or_else(|| panic!("no object {name}"))
    };

    // The vase: reflective (scene.toml), f0 = F0(ior) · (1 − metallic) + base · metallic.
    let vase = object("Vase");
    assert_eq!(vase.role, ObjectRole::Reflective);
    let r0 = ((VASE_IOR - 1.0) / (VASE_IOR + 1.0)).powi(2);
    let f0 = VASE_BASE.map(|b| r0 * (1.0 - VASE_METALLIC) + b * VASE_METALLIC);
    assert!(close(vase.shading.f0, f0), "vase f0 {:?}, the material's {f0:?}", vase.shading.f0);
    assert_eq!((vase.shading.ior, vase.shading.absorption), (VASE_IOR, [0.0; 3]));

    // The glass cup: refractive, IOR 1.5, absorbing as its volume's attenuation says
    // (colour (0.85, 0.95, 0.9) over 0.5 units).
    let cup = object("GlassCup");
    assert_eq!(cup.role, ObjectRole::Refractive);
    assert_eq!(cup.shading.ior, 1.5);
    let absorption = [0.85f32, 0.95, 0.9].map(|c| -c.ln() / 0.5);
    assert!(
        close(cup.shading.absorption, absorption),
        "cup absorption {:?}, want {absorption:?}",
        cup.shading.absorption
    );

    for o in [vase, cup] {
        let normals = o.mesh.normals.as_ref().unwrap_or_else(|| panic!("{}: no normals", o.name));
        assert_eq!(normals.len(), o.mesh.positions.len(), "{}", o.name);
        for n in normals {
            let len = n.iter().map(|c| c * c).sum::<f32>().sqrt();
            assert!((len - 1.0).abs() < 1e-5, "{}: normal {n:?} of length {len}", o.name);
        }
    }
    let walls = object("Walls");
    assert_eq!(walls.role, ObjectRole::Diffuse);
    assert!(walls.mesh.normals.is_none(), "a diffuse object carries no normals");
    assert!(pis_format::validate_file(&file).is_valid(), "the file validates");
}
