//! The PIS compile pipeline as a library: a ray-traced set to a `.pis` container (thesis
//! chapters 3–4).
//!
//! [`pack()`] is the whole stage in one call: it reads a ray-traced set (or traces a
//! scene.toml first), optimizes texture coordinates and infers every object's layers by
//! least squares through the render matrices, builds an adaptive Laplacian pyramid per
//! parameter block, allocates storage by equal slopes, codes the level images and writes the
//! container atomically. [`PackSettings`] says how, [`PackReport`] says what came out (the
//! report `pis-pack --json` prints).
//!
//! ```no_run
//! let settings = pis_pack::PackSettings::new().with_ratio(96.0);
//! let report = pis_pack::pack("demo1-set".as_ref(), "demo1.pis".as_ref(), &settings, &pis_pack::NoProgress)?;
//! println!("{:.2} dB at {:.0}:1", report.psnr_db, report.ratio_without_geometry);
//! # Ok::<(), pis_pack::Failure>(())
//! ```

mod error;
pub mod images;
pub mod infer;
pub mod pipeline;
pub mod solutions;

pub use error::{exit_of, format_exit, scene_exit, trace_exit, Exit, Failure};
pub use pipeline::hybrid::{lens, lens_infer};
pub use pipeline::*;
