//! Differences between two containers (`pis-diff A.pis B.pis`): the structure each holds
//! ([`structure`]) and what each decodes to at every parameter sample ([`content`]), with
//! block decoding shared by `pis-reencode` ([`decode`]).

pub mod content;
pub mod decode;
pub mod files;
pub mod gold;
pub mod noise;
pub mod sets;
pub mod structure;

pub use content::{
    compare, BlockDiff, ContentDiff, ErrorMap, FileError, LayerDiff, ObjectDiff, Score,
};
pub use structure::{differences, ChunkBytes};
