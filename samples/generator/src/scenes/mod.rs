//! The four sample scenes, one module each.

pub mod common;
pub mod demo1;
pub mod demo2;
pub mod glass;
pub mod teapot_pem;
