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
use crate::model::{Codestream, Container, StreamRef};
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
pub fn to_bytes_labelled_with_masters(c: &Container, masters: &[Master]) -> Result<(Vec<u8>, Vec<Span>), Error> {
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

/// Writes `bytes` to `path` through a temporary file and a rename.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), Error> {
    let io = |source| Error::Io {
        path: path.to_path_buf(),
        source,
    };
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let mut tmp = tempfile::Builder::new()
        .prefix(".pis-")
        .suffix(".tmp")
        .tempfile_in(dir)
        .map_err(io)?;
    tmp.write_all(bytes).map_err(io)?;
    tmp.as_file().sync_all().map_err(io)?;
    tmp.persist(path).map_err(|e| io(e.error))?;
    Ok(())
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
    let too_long = masters.iter().flat_map(|m| &m.layers).flat_map(|l| &l.samples).find(|s| u32::try_from(s.len()).is_err());
    if let Some(s) = too_long {
        return Err(Error::Request(format!("a master codestream of {} bytes exceeds 4 GiB", s.len())));
    }
    for r in c
        .objects
        .iter()
        .flat_map(|o| &o.layers)
        .flat_map(|l| &l.blocks)
        .flat_map(|b| &b.levels)
        .flat_map(|l| &l.images)
    {
        if u32::try_from(r.bytes.len()).is_err() {
            return Err(Error::Request(format!(
                "a codestream of {} bytes exceeds 4 GiB",
                r.bytes.len()
            )));
        }
    }
    let sink = serialize_inner(c, masters, labelled);
    if let Some(issue) = checks::decoded_sizes(c, sink.len() as u64) {
        return Err(Error::InvalidModel(issue));
    }
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
        pw::layr(s, &c.objects, |_| {
            next.next().expect("one reference per image")
        })
    }));
    chunks.push(Chunk {
        fourcc: chunk::CSTR,
        payload: cstr,
    });
    if let Some(p) = &c.provenance {
        chunks.push(chunk(chunk::PROV, &mut |s| pw::prov(s, p)));
    }
    // The master goes last: a file without one is byte for byte what it was before.
    for m in masters {
        chunks.push(chunk(chunk::MSTR, &mut |s| crate::master::write(s, m)));
    }
    assemble(chunks, labelled)
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
        format!(
            "codestream ({}, {} bytes)",
            img.codec.name(),
            img.bytes.len()
        )
    });
    r
}

fn assemble(chunks: Vec<Chunk>, labelled: bool) -> Sink {
    let mut out = Sink::new(labelled);
    out.raw(&MAGIC, || "magic \\x89 P I S \\r \\n \\x1a \\n".into());
    out.u16(VERSION_MAJOR, "major version");
    out.u16(VERSION_MINOR, "minor version");
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
