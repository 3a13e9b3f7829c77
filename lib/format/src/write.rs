//! Serializing a container, and writing it atomically: the bytes go to a temporary file in
//! the destination's folder, which is flushed to disk and renamed over the destination, so a
//! crash or error never leaves a partial `.pis`.

use std::io::Write;
use std::path::Path;

use crate::binary::{Sink, Span};
use crate::chunk::{
    self, FourCC, ALIGN, ENTRY_LEN, HEADER_LEN, MAGIC, VERSION_MAJOR, VERSION_MINOR,
};
use crate::master::Master;
use crate::model::{Codestream, Container, Mapping, Placement, ShellShape, StreamRef};
use crate::{checks, payload_write as pw, Error};

/// The bytes of a `.pis` file holding `c`. Fails if `c` breaks a rule of the spec.
pub fn to_bytes(c: &Container) -> Result<Vec<u8>, Error> {
    Ok(serialize(c, &[], false)?.bytes)
}

/// The bytes of a `.pis` file holding `c` and its lossless master (one [`Master`] per object,
/// or none), the `MSTR` chunks after all others. Fails if either breaks a rule of the spec.
pub fn to_bytes_with_masters(c: &Container, masters: &[Master]) -> Result<Vec<u8>, Error> {
    Ok(serialize(c, masters, false)?.bytes)
}

/// Like [`to_bytes`], with a label for every field (for annotated hex dumps).
pub fn to_bytes_labelled(c: &Container) -> Result<(Vec<u8>, Vec<Span>), Error> {
    to_bytes_labelled_with_masters(c, &[])
}

/// Like [`to_bytes_with_masters`], with a label for every field.
pub fn to_bytes_labelled_with_masters(
    c: &Container,
    masters: &[Master],
) -> Result<(Vec<u8>, Vec<Span>), Error> {
    let s = serialize(c, masters, true)?;
    Ok((s.bytes, s.spans.unwrap_or_default()))
}

/// Serializes without checking the model: for tests that need files breaking a rule.
#[doc(hidden)]
pub fn to_bytes_unchecked(c: &Container) -> Vec<u8> {
    let s = serialize_inner(c, &[], false);
    s.bytes
}

/// Serializes a container and masters without checking either: for tests that need files
/// breaking a rule of the master.
#[doc(hidden)]
pub fn to_bytes_unchecked_with_masters(c: &Container, masters: &[Master]) -> Vec<u8> {
    serialize_inner(c, masters, false).bytes
}

/// Writes `c` to `path` atomically; returns the file size.
pub fn write(path: &Path, c: &Container) -> Result<u64, Error> {
    write_with_masters(path, c, &[])
}

/// Writes `c` and its lossless master to `path` atomically; returns the file size.
pub fn write_with_masters(path: &Path, c: &Container, masters: &[Master]) -> Result<u64, Error> {
    let bytes = to_bytes_with_masters(c, masters)?;
    write_atomic(path, &bytes)?;
    Ok(bytes.len() as u64)
}

/// Writes `bytes` to `path` through a temporary file and a rename. The file gets the mode a
/// new file gets (the umask's), or the mode of the file it replaces. The temporary file,
/// `.pis-PID-N.tmp` beside the destination, is removed on error; temporary files that
/// processes no longer running left there (killed mid-write) are removed first.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), Error> {
    let io = |source| Error::Io { path: path.to_path_buf(), source };
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    remove_stale_temporaries(dir);
    let mut tmp = Temporary::create(dir).map_err(io)?;
    tmp.file.write_all(bytes).map_err(io)?;
    if let Ok(old) = std::fs::metadata(path) {
        tmp.file.set_permissions(old.permissions()).map_err(io)?;
    }
    tmp.file.sync_all().map_err(io)?;
    std::fs::rename(&tmp.path, path).map_err(io)?;
    tmp.path.clear();
    Ok(())
}

/// A temporary file this process writes, removed when dropped unless renamed (its path
/// cleared).
struct Temporary {
    path: std::path::PathBuf,
    file: std::fs::File,
}

impl Temporary {
    /// `.pis-PID-N.tmp` in `dir`, created new with the default mode (0666 less the umask).
    fn create(dir: &Path) -> std::io::Result<Temporary> {
        static NEXT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
        loop {
            let n = NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            let path = dir.join(format!(".pis-{}-{n}.tmp", std::process::id()));
            match std::fs::OpenOptions::new().write(true).create_new(true).open(&path) {
                Ok(file) => return Ok(Temporary { path, file }),
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
                Err(e) => return Err(e),
            }
        }
    }
}

impl Drop for Temporary {
    fn drop(&mut self) {
        if !self.path.as_os_str().is_empty() {
            let _ = std::fs::remove_file(&self.path);
        }
    }
}

/// Removes `.pis-PID-N.tmp` files in `dir` whose process PID no longer runs (where the
/// system says which processes run: /proc).
fn remove_stale_temporaries(dir: &Path) {
    let proc = Path::new("/proc/self");
    if !proc.exists() {
        return;
    }
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    for e in entries.flatten() {
        let name = e.file_name();
        let Some(pid) = name.to_str().and_then(|n| {
            n.strip_prefix(".pis-")?.strip_suffix(".tmp")?.split_once('-')?.0.parse::<u32>().ok()
        }) else {
            continue;
        };
        if pid != std::process::id() && !Path::new("/proc").join(pid.to_string()).exists() {
            let _ = std::fs::remove_file(e.path());
        }
    }
}

struct Chunk {
    fourcc: FourCC,
    payload: Sink,
}

fn serialize(c: &Container, masters: &[Master], labelled: bool) -> Result<Sink, Error> {
    if let Some(issue) = checks::check(c).into_iter().next() {
        return Err(Error::InvalidModel(issue));
    }
    if let Some(issue) = crate::master::check(c, masters).into_iter().next() {
        return Err(Error::InvalidModel(issue));
    }
    let too_long = masters
        .iter()
        .flat_map(|m| &m.layers)
        .flat_map(|l| &l.samples)
        .find(|s| u32::try_from(s.len()).is_err());
    if let Some(s) = too_long {
        return Err(Error::Request(format!(
            "a master codestream of {} bytes exceeds 4 GiB",
            s.len()
        )));
    }
    for r in c.level_images() {
        if u32::try_from(r.bytes.len()).is_err() {
            return Err(Error::Request(format!(
                "a codestream of {} bytes exceeds 4 GiB",
                r.bytes.len()
            )));
        }
    }
    // The writer stores every codestream once, in one CSTR chunk (see `serialize_inner`).
    let codestream_bytes = c.level_images().map(|r| r.bytes.len() as u64).sum();
    if let Some(issue) = checks::decoded_sizes(c, codestream_bytes) {
        return Err(Error::InvalidModel(issue));
    }
    let sink = serialize_inner(c, masters, labelled);
    Ok(sink)
}

fn serialize_inner(c: &Container, masters: &[Master], labelled: bool) -> Sink {
    let mut chunks = Vec::new();
    let chunk = |fourcc: FourCC, fill: &mut dyn FnMut(&mut Sink)| {
        let mut payload = Sink::new(labelled);
        fill(&mut payload);
        Chunk { fourcc, payload }
    };
    chunks.push(chunk(chunk::PSPC, &mut |s| pw::pspc(s, &c.space)));
    chunks.push(chunk(chunk::CAMS, &mut |s| pw::cams(s, &c.cameras)));
    chunks.push(chunk(chunk::OBJS, &mut |s| pw::objs(s, &c.objects)));
    for (i, o) in c.objects.iter().enumerate() {
        chunks.push(chunk(chunk::MESH, &mut |s| pw::mesh(s, i as u32, &o.mesh)));
    }
    // Codestreams go into one CSTR chunk, in layer, block, level, image order.
    let cstr_index = chunks.len() as u32 + 1;
    let mut cstr = Sink::new(labelled);
    let mut refs = Vec::new();
    for o in &c.objects {
        for l in &o.layers {
            for b in &l.blocks {
                for level in &b.levels {
                    for img in &level.images {
                        refs.push(place(&mut cstr, cstr_index, img));
                    }
                }
            }
        }
    }
    let mut next = refs.into_iter();
    chunks.push(chunk(chunk::LAYR, &mut |s| {
        pw::layr(s, &c.objects, |_| next.next().expect("one reference per image"))
    }));
    chunks.push(Chunk { fourcc: chunk::CSTR, payload: cstr });
    if let Some(p) = &c.provenance {
        chunks.push(chunk(chunk::PROV, &mut |s| pw::prov(s, p)));
    }
    // The master goes last: a file without one is byte for byte what it was before.
    for m in masters {
        chunks.push(chunk(chunk::MSTR, &mut |s| crate::master::write(s, m)));
    }
    assemble(chunks, minor_version(c), labelled)
}

/// The lowest minor version whose rules the file needs (SPEC.md 10.1): 6 where a layer holds
/// a light-basis coefficient (7.1), 5 where a shell block
/// has shape `depth` (7.3), 4 where an object has a filter of its own (a `filter.NAME`
/// setting, 6.6), 3 where an object is translucent (a surface layer of 4 channels, 7.1),
/// else 2.
fn minor_version(c: &Container) -> u16 {
    if c.objects.iter().flat_map(|o| &o.layers).any(|l| l.basis != 0) {
        return VERSION_MINOR;
    }
    let depth_shell = c
        .objects
        .iter()
        .flat_map(|o| &o.layers)
        .flat_map(|l| &l.blocks)
        .any(|b| matches!(b.placement, Placement::Shell { shape: ShellShape::Depth, .. }));
    let own_filter = c.provenance.as_ref().is_some_and(|p| {
        p.settings.iter().any(|(k, _)| k.starts_with(crate::filter::OBJECT_FILTER_PREFIX))
    });
    let translucent = c
        .objects
        .iter()
        .flat_map(|o| &o.layers)
        .any(|l| l.mapping == Mapping::Surface && l.channels == 4);
    if depth_shell {
        5
    } else if own_filter {
        4
    } else if translucent {
        3
    } else {
        2
    }
}

fn place(cstr: &mut Sink, chunk: u32, img: &Codestream) -> StreamRef {
    let length = img.bytes.len() as u32; // checked by `serialize`
    let r = StreamRef {
        codec: img.codec,
        chunk,
        offset: cstr.len() as u64,
        length,
        crc: crc32fast::hash(&img.bytes),
    };
    cstr.raw(&img.bytes, || {
        format!("codestream ({}, {} bytes)", img.codec.name(), img.bytes.len())
    });
    r
}

fn assemble(chunks: Vec<Chunk>, minor: u16, labelled: bool) -> Sink {
    let mut out = Sink::new(labelled);
    out.raw(&MAGIC, || "magic \\x89 P I S \\r \\n \\x1a \\n".into());
    out.u16(VERSION_MAJOR, "major version");
    out.u16(minor, "minor version");
    out.u32(0, "flags");
    out.u64(0, "file length");
    out.u32(chunks.len() as u32, "chunk count");
    out.u32(0, "header crc32 (of bytes 0..28 and the chunk table)");
    let mut offset = HEADER_LEN + chunks.len() as u64 * ENTRY_LEN;
    let mut layout = Vec::with_capacity(chunks.len());
    for (i, ch) in chunks.iter().enumerate() {
        offset = offset.next_multiple_of(ALIGN);
        let name = chunk::fourcc_str(ch.fourcc);
        let required = chunk::rule(ch.fourcc).is_some_and(|r| r.required);
        let crc = crc32fast::hash(&ch.payload.bytes);
        let p = format!("chunk {i}");
        out.raw(&ch.fourcc, || format!("{p} type '{name}'"));
        out.u32(required as u32, &format!("{p} flags (1 = required)"));
        out.u64(offset, &format!("{p} offset"));
        out.u64(ch.payload.len() as u64, &format!("{p} length"));
        out.u32_hex(crc, &format!("{p} crc32"));
        out.u32(0, &format!("{p} reserved"));
        layout.push(offset);
        offset += ch.payload.len() as u64;
    }
    for (ch, at) in chunks.into_iter().zip(layout) {
        let pad = (at - out.len() as u64) as usize;
        out.zeros(pad, "padding to a multiple of 8");
        out.append(ch.payload);
    }
    let len = out.len() as u64;
    out.patch_u64(16, len);
    let count = u32::from_le_bytes(out.bytes[24..28].try_into().expect("4 bytes")) as usize;
    let table = HEADER_LEN as usize..HEADER_LEN as usize + count * ENTRY_LEN as usize;
    let crc = chunk::header_crc(&out.bytes[..28], &out.bytes[table]);
    out.patch_u32(28, crc);
    if let Some(spans) = &mut out.spans {
        for s in spans.iter_mut() {
            if s.start == 16 {
                s.label = format!("file length = {len}");
            }
            if s.start == 28 {
                s.label =
                    format!("header crc32 (of bytes 0..28 and the chunk table) = {crc:#010x}");
            }
        }
    }
    out
}

#[cfg(all(test, unix))]
mod tests {
    use super::*;
    use std::os::unix::fs::PermissionsExt;

    fn mode(p: &Path) -> u32 {
        std::fs::metadata(p).unwrap().permissions().mode() & 0o777
    }

    fn temporaries(dir: &Path) -> Vec<String> {
        std::fs::read_dir(dir)
            .unwrap()
            .flatten()
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .filter(|n| n.ends_with(".tmp"))
            .collect()
    }

    /// Outputs were once created 0600, and rewriting a 0644 file made it 0600.
    #[test]
    fn a_written_file_gets_the_default_mode_or_keeps_the_old_one() {
        let dir = tempfile::tempdir().unwrap();
        let (a, b) = (dir.path().join("a.pis"), dir.path().join("b.pis"));
        write_atomic(&a, b"new").unwrap();
        std::fs::write(&b, b"plain").unwrap();
        assert_eq!(
            mode(&a),
            mode(&b),
            "a new file gets the mode std gives any new file (the umask's)"
        );
        std::fs::set_permissions(&a, std::fs::Permissions::from_mode(0o640)).unwrap();
        write_atomic(&a, b"again").unwrap();
        assert_eq!(mode(&a), 0o640, "a replaced file keeps its mode");
        assert_eq!(std::fs::read(&a).unwrap(), b"again");
        assert!(temporaries(dir.path()).is_empty());
    }

    /// A write killed mid-way (kill -9) once left `.pis-*.tmp` files no later run removed.
    #[test]
    fn temporaries_of_processes_no_longer_running_are_removed() {
        if !Path::new("/proc/self").exists() {
            return;
        }
        let dir = tempfile::tempdir().unwrap();
        // pid_max is at most 2^22: this process cannot exist
        let stale = dir.path().join(".pis-99999999-0.tmp");
        let mine = dir.path().join(format!(".pis-{}-999.tmp", std::process::id()));
        let other = dir.path().join(".pis-notes.tmp");
        for p in [&stale, &mine, &other] {
            std::fs::write(p, b"partial").unwrap();
        }
        write_atomic(&dir.path().join("out.pis"), b"whole").unwrap();
        assert!(!stale.exists(), "a dead process's temporary is removed");
        assert!(mine.exists() && other.exists(), "a live process's temporary and other files stay");
    }

    #[test]
    fn a_failed_write_leaves_no_temporary() {
        let dir = tempfile::tempdir().unwrap();
        // renaming a file over a folder fails
        let target = dir.path().join("folder");
        std::fs::create_dir(&target).unwrap();
        std::fs::write(target.join("keep"), b"x").unwrap();
        assert!(write_atomic(&target, b"bytes").is_err());
        assert!(temporaries(dir.path()).is_empty(), "{:?}", temporaries(dir.path()));
    }
}
