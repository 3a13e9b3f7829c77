//! The .pis container: the in-memory model, a validating random-access reader and an
//! atomic writer. The normative description is `format-spec/SPEC.md`.

pub mod model;

pub use model::{DimensionKind, ObjectRole};
