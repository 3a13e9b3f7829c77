//! The .pis container: the in-memory model, a validating random-access reader and an
//! atomic writer. The normative description is `format-spec/SPEC.md`; every rule id in
//! [`issue::RULES`] is listed in its "Validation" section.
//!
//! ```no_run
//! # fn main() -> Result<(), pis_format::Error> {
//! let file = pis_format::PisReader::open("samples/tiny.pis".as_ref())?;
//! let texture = file.texture(0, 0, &[1, 0])?; // object 0, layer 0, point (1, 0)
//! # Ok(()) }
//! ```

mod binary;
pub mod blocks;
pub mod checks;
pub mod chunk;
pub mod display_filter;
mod error;
pub mod filter;
pub mod hexdump;
pub mod issue;
pub mod lens_model;
pub mod master;
pub mod mip;
pub mod model;
mod object_setting;
mod payload_read;
mod payload_write;
pub mod precision;
mod read;
pub mod reconstruct;
pub mod relight;
pub mod samples;
mod source;
pub mod texture;
pub mod tint;
mod validate;
mod write;

pub use binary::Span;
pub use display_filter::DisplayFilter;
pub use error::Error;
pub use filter::FileFilter;
pub use issue::{Issue, Severity};
pub use master::{Master, MasterLayer};
pub use model::*;
pub use pis_codec::{CodecId, PlaneShape};
pub use read::{PisReader, ReadStats};
pub use texture::{LevelLayout, Texture};
pub use validate::{validate_bytes, validate_file, Validation};
pub use write::{
    to_bytes, to_bytes_labelled, to_bytes_labelled_with_masters, to_bytes_unchecked,
    to_bytes_unchecked_with_masters, to_bytes_with_masters, write, write_atomic,
    write_with_masters,
};
