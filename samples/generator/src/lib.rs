//! The PIS sample scenes, generated procedurally: glTF (JSON + binary buffer + PNG
//! textures) plus scene.toml for `demo1`, `demo2`, `teapot-pem`, `teapot-glossy` and `glass`
//! (seed thesis, sections 4.8.1, 4.8.2, 5.10, 5.10 with figures 5.11–5.12, and 6.5).
//! `cargo run -p pis-samples --release -- samples/` regenerates them byte for byte.

use std::io;
use std::path::Path;

pub mod gltf_writer;
pub mod mesh;
pub mod scenes;
pub mod teapot;
pub mod teapot_data;
pub mod textures;

/// The sample scene directory names, in generation order.
pub const SAMPLES: [&str; 5] = ["demo1", "demo2", "teapot-pem", "teapot-glossy", "glass"];

/// The scenes from the wild, under `wild/`: glTF as exporters write it (see
/// [`scenes::wild`]).
pub const WILD: [&str; 4] = scenes::wild::WILD;

/// Writes every sample scene into `root/<name>/`, and the scenes from the wild into
/// `root/wild/<name>/`.
pub fn generate_all(root: &Path) -> io::Result<()> {
    scenes::demo1::write(&root.join("demo1"))?;
    scenes::demo2::write(&root.join("demo2"))?;
    scenes::teapot_pem::write(&root.join("teapot-pem"))?;
    scenes::teapot_glossy::write(&root.join("teapot-glossy"))?;
    scenes::glass::write(&root.join("glass"))?;
    scenes::wild::write_all(&root.join("wild"))?;
    Ok(())
}
