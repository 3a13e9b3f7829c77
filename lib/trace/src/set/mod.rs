//! The ray-traced set on disk (format-spec/RAYSET.md): `set.json`, one multi-layer OpenEXR
//! per parameter point and little-endian ray-record side files; while a trace is under way,
//! one record per point done in `shards/` ([`Shard`], [`merge_set`]).

mod atomic;
mod exr_io;
mod halves;
mod meta;
mod reader;
mod shards;
mod writer;

pub use atomic::write_atomic;
pub use exr_io::{decode_exr, encode_exr};
pub use halves::{denoise_halves, HalvesReport};
pub use meta::*;
pub use reader::RaySet;
pub use shards::{is_complete, merge_set, Begin, MergeReport, Shard, SHARDS_DIR};
pub use writer::SetWriter;

/// Name of the metadata file inside a set directory.
pub const SET_JSON: &str = "set.json";
/// Value of `format` in set.json.
pub const SET_FORMAT: &str = "pis-rayset";
/// Value of `version` in set.json.
pub const SET_VERSION: u32 = 1;
