//! Bounds and type checks on glTF accessors before they are read.
//!
//! The gltf crate's readers trust the document: an accessor whose count, offset or stride
//! points past its buffer view, or whose type differs from what the attribute needs, makes
//! them panic or misread. Every accessor PIS reads passes through [`check_accessor`] first.

use std::path::Path;

use gltf::accessor::{DataType, Dimensions};

use crate::SceneError;

/// Checks that `accessor` has one of the allowed `dims` and `types`, at least one element,
/// no sparse storage, and that all its elements lie inside its buffer view and the view
/// inside its buffer. `field` names the referencing glTF field for the error.
pub(crate) fn check_accessor(
    path: &Path,
    field: &str,
    accessor: &gltf::Accessor,
    buffers: &[gltf::buffer::Data],
    dims: &[Dimensions],
    types: &[DataType],
) -> Result<(), SceneError> {
    let at = format!("{field} (accessors[{}])", accessor.index());
    let invalid = |message: String| SceneError::invalid(path, &at, message);
    if !dims.contains(&accessor.dimensions()) || !types.contains(&accessor.data_type()) {
        return Err(invalid(format!(
            "accessor is {:?} of {:?}; expected {:?} of {:?}",
            accessor.dimensions(),
            accessor.data_type(),
            dims,
            types
        )));
    }
    if accessor.sparse().is_some() {
        return Err(SceneError::unsupported(path, &at, "sparse accessors"));
    }
    let count = accessor.count();
    if count == 0 {
        return Err(invalid("accessor count is 0".into()));
    }
    let Some(view) = accessor.view() else {
        return Err(SceneError::unsupported(path, &at, "accessors without a buffer view"));
    };
    let size = accessor.size();
    let stride = view.stride().unwrap_or(size);
    if stride < size {
        return Err(invalid(format!(
            "buffer view stride {stride} is smaller than the element size {size}"
        )));
    }
    let end = stride
        .checked_mul(count - 1)
        .and_then(|x| x.checked_add(size))
        .and_then(|x| x.checked_add(accessor.offset()));
    match end {
        Some(end) if end <= view.length() => {}
        _ => {
            return Err(invalid(format!(
                "{count} elements of {size} bytes (stride {stride}) from offset {} exceed buffer view {} of {} bytes",
                accessor.offset(),
                view.index(),
                view.length()
            )))
        }
    }
    let buffer_len = buffers.get(view.buffer().index()).map(|b| b.len()).unwrap_or(0);
    match view.offset().checked_add(view.length()) {
        Some(end) if end <= buffer_len => Ok(()),
        _ => Err(invalid(format!(
            "buffer view {} (offset {}, length {}) exceeds buffer {} of {buffer_len} bytes",
            view.index(),
            view.offset(),
            view.length(),
            view.buffer().index()
        ))),
    }
}
