//! The sample scenes, one module each (teapot-glossy reuses teapot-pem's builder).

pub mod common;
pub mod demo1;
pub mod demo2;
pub mod glass;
pub mod relight;
pub mod teapot_glossy;
pub mod teapot_pem;
pub mod wild;
pub mod wild_toml;
