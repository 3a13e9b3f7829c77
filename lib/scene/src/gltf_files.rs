//! The files a glTF reads beside itself: its buffers and images. A reference that leaves the
//! glTF's own folder (an absolute path, a `file:` URI, a relative path that climbs out with
//! `..` or through a link) is refused unless scene.toml allows it (`allow_outside_files`),
//! so that a scene from elsewhere cannot read the machine's other files; a buffer shorter
//! than its declared `byteLength` is refused (the glTF reader pads up to 3 missing bytes
//! with zeros).

use std::path::{Component, Path, PathBuf};

use crate::SceneError;

/// What a URI names.
enum Reference<'a> {
    /// Inline base64 data (`data:…;base64,DATA`).
    Data(&'a str),
    /// A file: its path (percent-decoded) and whether the URI names it absolutely.
    File(String, bool),
    /// Another scheme (`http:` …): the glTF reader refuses it.
    Other,
}

fn reference(uri: &str) -> Reference<'_> {
    if let Some(rest) = uri.strip_prefix("data:") {
        return Reference::Data(rest.split_once(',').map_or("", |(_, d)| d));
    }
    if let Some(rest) = uri.strip_prefix("file://").or_else(|| uri.strip_prefix("file:")) {
        return Reference::File(percent_decode(rest), true);
    }
    // A scheme is letters before a colon, as in `http:`; a Windows drive is one letter.
    if uri
        .split_once(':')
        .is_some_and(|(s, _)| s.len() > 1 && s.chars().all(|c| c.is_ascii_alphabetic()))
    {
        return Reference::Other;
    }
    let path = percent_decode(uri);
    let absolute =
        Path::new(&path).is_absolute() || path.starts_with('/') || path.starts_with('\\');
    Reference::File(path, absolute)
}

/// `%XX` escapes decoded as the glTF reader decodes them (the path it would open).
fn percent_decode(s: &str) -> String {
    urlencoding::decode(s).map_or_else(|_| s.to_string(), |d| d.into_owned())
}

/// Bytes that base64 text decodes to.
fn base64_len(data: &str) -> usize {
    let body = data.trim_end_matches('=');
    body.len() * 3 / 4
}

/// The file `rel` names beside the glTF at `gltf`, refused when it leaves the glTF's folder
/// and `allow_outside` is false.
fn resolve(
    gltf: &Path,
    field: &str,
    uri: &str,
    rel: &str,
    absolute: bool,
    allow_outside: bool,
) -> Result<PathBuf, SceneError> {
    let base = gltf.parent().unwrap_or(Path::new(""));
    let target = base.join(rel);
    if allow_outside {
        return Ok(target);
    }
    let refuse = |why: &str| {
        SceneError::invalid(
            gltf,
            format!("{field}.uri"),
            format!("{uri:?} {why}; refused (scene.toml `allow_outside_files = true` allows it)"),
        )
    };
    if absolute {
        return Err(refuse("is an absolute path, outside the glTF's folder"));
    }
    if stays_inside(base, &target, rel) {
        Ok(target)
    } else {
        Err(refuse("leaves the glTF's folder"))
    }
}

/// Whether `target`, the relative path `rel` joined to the folder `base`, lies inside
/// `base`: where the file exists, where it really is (`..`, links); else where its path
/// leads (never above `base`, no root or drive).
pub(crate) fn stays_inside(base: &Path, target: &Path, rel: &str) -> bool {
    match (target.canonicalize(), base.canonicalize()) {
        (Ok(t), Ok(b)) => t.starts_with(&b),
        _ => {
            let mut depth = 0i32;
            Path::new(rel).components().all(|c| {
                depth += match c {
                    Component::ParentDir => -1,
                    Component::Normal(_) => 1,
                    _ => 0,
                };
                depth >= 0 && !matches!(c, Component::RootDir | Component::Prefix(_))
            })
        }
    }
}

/// Checks the buffer and image references of `gltf`, read from `path`.
pub(crate) fn check_files(
    path: &Path,
    gltf: &gltf::Gltf,
    allow_outside: bool,
) -> Result<(), SceneError> {
    for b in gltf.buffers() {
        let field = format!("buffers[{}]", b.index());
        let have = match b.source() {
            gltf::buffer::Source::Bin => gltf.blob.as_ref().map(Vec::len),
            gltf::buffer::Source::Uri(uri) => match reference(uri) {
                Reference::Data(data) => Some(base64_len(data)),
                Reference::File(rel, absolute) => {
                    let file = resolve(path, &field, uri, &rel, absolute, allow_outside)?;
                    std::fs::metadata(&file).ok().map(|m| m.len() as usize)
                }
                Reference::Other => None,
            },
        };
        if let Some(have) = have.filter(|&n| n < b.length()) {
            let msg = format!("declares {} bytes; the data holds {have}", b.length());
            return Err(SceneError::invalid(path, format!("{field}.byteLength"), msg));
        }
    }
    for image in gltf.images() {
        if let gltf::image::Source::Uri { uri, .. } = image.source() {
            if let Reference::File(rel, absolute) = reference(uri) {
                resolve(
                    path,
                    &format!("images[{}]", image.index()),
                    uri,
                    &rel,
                    absolute,
                    allow_outside,
                )?;
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uris_name_data_files_or_other_schemes() {
        assert!(matches!(
            reference("data:application/octet-stream;base64,AAAA"),
            Reference::Data("AAAA")
        ));
        assert!(
            matches!(reference("scene%20one.bin"), Reference::File(p, false) if p == "scene one.bin")
        );
        assert!(matches!(reference("/etc/passwd"), Reference::File(_, true)));
        assert!(matches!(reference("file:///etc/passwd"), Reference::File(_, true)));
        assert!(matches!(reference("https://example.com/a.bin"), Reference::Other));
        assert_eq!(base64_len("AAAA"), 3);
        assert_eq!(base64_len("AAA="), 2);
        assert_eq!(base64_len("AA=="), 1);
    }
}
