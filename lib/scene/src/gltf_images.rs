//! A glTF's images, each read on its own, so that one that cannot be read (a missing file, a
//! format PIS does not decode) leaves only the textures using it unread.

use std::path::Path;

use crate::SceneError;

/// An image of the glTF as read: its data, or why it could not be read (its file missing, or
/// of a format PIS does not decode, such as TGA: exporters write such references).
pub(crate) type ImageData = Result<gltf::image::Data, String>;

/// Every image of `doc`, each read on its own: one whose file is missing or of a format PIS
/// does not decode leaves the textures using it unread, with a warning, instead of failing
/// the whole scene; damaged data of a format it decodes is an error naming the image.
pub(crate) fn import_images(
    path: &Path,
    doc: &gltf::Document,
    base: &Path,
    buffers: &[gltf::buffer::Data],
) -> Result<Vec<ImageData>, SceneError> {
    doc.images()
        .map(|image| {
            let uri = match image.source() {
                gltf::image::Source::Uri { uri, .. } if !uri.starts_with("data:") => {
                    format!(" ('{uri}')")
                }
                _ => String::new(),
            };
            let field = format!("images[{}]", image.index());
            match gltf::image::Data::from_source(image.source(), Some(base), buffers) {
                Ok(data) => Ok(Ok(data)),
                Err(gltf::Error::Io(source)) => {
                    Ok(Err(format!("{field}{uri} cannot be read: {source}")))
                }
                Err(gltf::Error::UnsupportedScheme) => Ok(Err(format!(
                    "{field}{uri} cannot be read: a URI scheme or drive PIS does not read"
                ))),
                Err(gltf::Error::UnsupportedImageEncoding) => Ok(Err(format!(
                    "{field}{uri} is of a format PIS does not decode (PNG and JPEG only)"
                ))),
                Err(other) => Err(SceneError::invalid(path, field, other.to_string())),
            }
        })
        .collect()
}
