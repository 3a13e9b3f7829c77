//! The PIS sample scenes, generated procedurally: glTF (JSON + binary buffer) plus
//! scene.toml for `demo1`, `demo2`, `teapot-pem` and `glass` (seed thesis, sections 4.8.1,
//! 4.8.2, 5.10 and 6.5). `cargo run -p pis-samples --release -- samples/` regenerates them.

pub mod mesh;
pub mod teapot;
pub mod teapot_data;
