//! The validating random-access reader.
//!
//! Opening a file reads the header, the chunk table and every metadata chunk (checksums
//! verified), checks every rule of the spec that does not need the codestreams, and keeps the
//! codestream references. Textures are then decoded on demand, reading only the codestreams
//! on the pyramid path of the requested parameter point (each checksum-verified). The
//! lossless master (`MSTR`) is not read at all until [`PisReader::masters`] asks for it.
//! Every count, offset and length is checked against the file size before anything is
//! allocated for it.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use pis_codec::CodecError;

use crate::binary::Cursor;
use crate::blocks::{level_image_index, BlockGrid};
use crate::chunk::{self, ChunkEntry, Header, ENTRY_LEN, HEADER_LEN};
use crate::issue::id;
use crate::master::Master;
use crate::model::*;
use crate::source::{FileSource, Source};
use crate::texture::{LevelLayout, Texture};
use crate::{checks, payload_read as pr, reconstruct, Error, Issue, Severity};

/// An open `.pis` file.
pub struct PisReader {
    source: Box<dyn Source>,
    path: PathBuf,
    header: Header,
    chunks: Vec<ChunkEntry>,
    container: Container<StreamRef>,
    reads: AtomicU64,
    read_bytes: AtomicU64,
}

/// Codestream reads since the file was opened.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct ReadStats {
    pub codestreams: u64,
    pub bytes: u64,
}

/// What a structural pass over a file found (its issues go to the caller's list).
pub(crate) struct Loaded {
    pub header: Option<Header>,
    pub chunks: Vec<ChunkEntry>,
    /// The container, when its space and layers parsed and its codestreams can be decoded
    /// within section 12's limits. With `full`, other rules may be broken and the parts that
    /// did not parse (cameras, meshes, provenance) left empty.
    pub container: Option<Container<StreamRef>>,
}

impl PisReader {
    /// Opens and checks `path`.
    pub fn open(path: &Path) -> Result<Self, Error> {
        let io = |source| Error::Io { path: path.to_path_buf(), source };
        let file = std::fs::File::open(path).map_err(io)?;
        let source = FileSource::new(file).map_err(io)?;
        Self::from_source(Box::new(source), path.to_path_buf())
    }

    /// Opens a container held in memory.
    pub fn from_bytes(bytes: Vec<u8>) -> Result<Self, Error> {
        Self::from_source(Box::new(bytes), PathBuf::from("<memory>"))
    }

    fn from_source(source: Box<dyn Source>, path: PathBuf) -> Result<Self, Error> {
        let mut issues = Vec::new();
        let loaded = load(source.as_ref(), false, &mut issues);
        if let Some(first) = issues.into_iter().find(|i| i.severity == Severity::Error) {
            return Err(match first.id {
                id::io::FILE_UNREADABLE => {
                    Error::Io { path, source: std::io::Error::other(first.detail) }
                }
                _ => Error::Invalid(first),
            });
        }
        match (loaded.header, loaded.container) {
            (Some(header), Some(container)) => Ok(PisReader {
                source,
                path,
                header,
                chunks: loaded.chunks,
                container,
                reads: AtomicU64::new(0),
                read_bytes: AtomicU64::new(0),
            }),
            _ => {
                Err(Error::Invalid(Issue::new(id::io::FILE_UNREADABLE, "file could not be parsed")))
            }
        }
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    pub fn header(&self) -> &Header {
        &self.header
    }

    pub fn chunks(&self) -> &[ChunkEntry] {
        &self.chunks
    }

    pub fn len(&self) -> u64 {
        self.source.len()
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The container, with codestreams as references into the file.
    pub fn container(&self) -> &Container<StreamRef> {
        &self.container
    }

    pub fn stats(&self) -> ReadStats {
        ReadStats {
            codestreams: self.reads.load(Ordering::Relaxed),
            bytes: self.read_bytes.load(Ordering::Relaxed),
        }
    }

    /// The bytes of one codestream, checksum verified.
    pub fn codestream(&self, r: &StreamRef) -> Result<Vec<u8>, Error> {
        let entry = &self.chunks[r.chunk as usize];
        let mut buf = vec![0; r.length as usize];
        self.source
            .read_at(entry.offset + r.offset, &mut buf)
            .map_err(|source| Error::Io { path: self.path.clone(), source })?;
        self.reads.fetch_add(1, Ordering::Relaxed);
        self.read_bytes.fetch_add(r.length as u64, Ordering::Relaxed);
        let crc = crc32fast::hash(&buf);
        if crc != r.crc {
            return Err(Error::Invalid(
                Issue::new(
                    id::codestream::CHECKSUM_MISMATCH,
                    format!("stored {:#010x}, computed {crc:#010x}", r.crc),
                )
                .in_chunk("CSTR", r.chunk as usize)
                .at(entry.offset + r.offset),
            ));
        }
        Ok(buf)
    }

    /// Checks an (object, layer, point) request against the file.
    fn request(&self, object: usize, layer: usize, point: &[u32]) -> Result<(), Error> {
        let c = &self.container;
        let o = c.objects.get(object).ok_or_else(|| {
            Error::Request(format!(
                "object {object} does not exist; the file has {}",
                c.objects.len()
            ))
        })?;
        if layer >= o.layers.len() {
            return Err(Error::Request(format!(
                "object '{}' has {} layers, not {}",
                o.name,
                o.layers.len(),
                layer + 1
            )));
        }
        if point.len() != c.space.dims.len() {
            return Err(Error::Request(format!(
                "a point needs {} sample indices, got {}",
                c.space.dims.len(),
                point.len()
            )));
        }
        for (k, (&s, d)) in point.iter().zip(&c.space.dims).enumerate() {
            if s as usize >= d.values.len() {
                return Err(Error::Request(format!(
                    "sample {s} of dimension {k} '{}' does not exist; it has {}",
                    d.name,
                    d.values.len()
                )));
            }
        }
        Ok(())
    }

    /// The codestreams a texture at `point` is rebuilt from, top pyramid level first.
    pub fn texture_path(
        &self,
        object: usize,
        layer: usize,
        point: &[u32],
    ) -> Result<(usize, Vec<StreamRef>), Error> {
        self.request(object, layer, point)?;
        let o = &self.container.objects[object];
        let l = &o.layers[layer];
        let pos = BlockGrid::new(&self.container.space, l.depends_on, &o.stagger).locate(point);
        let block = &l.blocks[pos.block];
        let refs = block
            .levels
            .iter()
            .map(|level| level.images[level_image_index(&level.counts, &pos.local, &pos.extent)])
            .collect();
        Ok((pos.block, refs))
    }

    /// Decodes the texture of layer `layer` of object `object` at parameter point `point`
    /// (one sample index per dimension).
    pub fn texture(&self, object: usize, layer: usize, point: &[u32]) -> Result<Texture, Error> {
        let (bi, refs) = self.texture_path(object, layer, point)?;
        let l = &self.container.objects[object].layers[layer];
        let layout = LevelLayout::of(l, &l.blocks[bi]);
        let planes = layout.planes();
        let mut sum: Option<Vec<f32>> = None;
        for (lv, r) in refs.iter().enumerate() {
            let bytes = self.codestream(r)?;
            let values = pis_codec::decode(r.codec, &planes, &bytes).map_err(|e| match e {
                CodecError::NotSupported(c) => {
                    Error::NotSupported(format!("codec '{c}' (object {object}, layer {layer})"))
                }
                e @ CodecError::TrailingBytes { .. } => Error::Invalid(
                    Issue::new(
                        id::codestream::TRAILING_BYTES,
                        format!("object {object} layer {layer} block {bi} level {lv}: {e}"),
                    )
                    .in_chunk("CSTR", r.chunk as usize),
                ),
                e => Error::Invalid(
                    Issue::new(
                        id::codestream::PLANES_MISMATCH,
                        format!("object {object} layer {layer} block {bi} level {lv}: {e}"),
                    )
                    .in_chunk("CSTR", r.chunk as usize),
                ),
            })?;
            if let Some(bad) = values.iter().position(|v| !v.is_finite()) {
                return Err(Error::Invalid(
                    Issue::new(id::codestream::VALUE_NOT_FINITE, format!("object {object} layer {layer} block {bi} level {lv}: value {bad} is {}", values[bad]))
                        .in_chunk("CSTR", r.chunk as usize),
                ));
            }
            match &mut sum {
                None => sum = Some(values),
                Some(acc) => acc.iter_mut().zip(&values).for_each(|(a, v)| *a += v),
            }
        }
        let data = reconstruct::finish(l, &layout, sum.unwrap_or_default());
        Ok(Texture { layout, data })
    }

    /// True when the file carries a lossless master (`MSTR` chunks), without reading it.
    pub fn has_master(&self) -> bool {
        self.chunks.iter().any(|e| e.fourcc == chunk::MSTR)
    }

    /// Bytes of the `MSTR` payloads: the part of the file a player does not use.
    pub fn master_bytes(&self) -> u64 {
        self.chunks.iter().filter(|e| e.fourcc == chunk::MSTR).map(|e| e.length).sum()
    }

    /// The lossless master, one per object (empty when the file has none): every `MSTR`
    /// chunk read, checksum-verified, parsed and checked against the container (SPEC.md
    /// 6.7). Its textures are decoded, and checked, by [`Master::texture`].
    pub fn masters(&self) -> Result<Vec<Master>, Error> {
        let mut issues = Vec::new();
        let masters = crate::master::load(
            self.source.as_ref(),
            &self.chunks,
            &self.container,
            false,
            &mut issues,
        );
        match issues.into_iter().next() {
            Some(i) if i.id == id::io::FILE_UNREADABLE => {
                Err(Error::Io { path: self.path.clone(), source: std::io::Error::other(i.detail) })
            }
            Some(i) => Err(Error::Invalid(i)),
            None => Ok(masters),
        }
    }

    /// Reads every codestream into memory: the whole container, ready to re-encode or write.
    pub fn load_all(&self) -> Result<Container<Codestream>, Error> {
        self.container
            .try_map(&mut |r| Ok(Codestream { codec: r.codec, bytes: self.codestream(r)? }))
    }
}

/// The structural pass shared by [`PisReader::open`] and `validate`: header, table, metadata
/// chunks, model rules and codestream ranges. With `full` (validation), also every checksum
/// of chunks the reader otherwise reads lazily (`CSTR`, unknown chunks), and every rule that
/// can be checked: a reader stops at the first broken rule, a validator reports every rule
/// whose inputs are readable (a chunk whose checksum fails is not parsed, and the rules that
/// build on its content are not checked).
///
/// The container is returned when its space and layers parsed and the rules that bound
/// decoding hold (the space, block grids, pyramids, codestream ranges and section 12's
/// limits), so that its codestreams can be decoded; other rules may be broken.
pub(crate) fn load(src: &dyn Source, full: bool, issues: &mut Vec<Issue>) -> Loaded {
    let mut out = Loaded { header: None, chunks: Vec::new(), container: None };
    let len = src.len();
    let mut head = vec![0u8; len.min(HEADER_LEN) as usize];
    if let Err(e) = src.read_at(0, &mut head) {
        issues.push(Issue::new(id::io::FILE_UNREADABLE, e.to_string()));
        return out;
    }
    let header = match chunk::parse_header(&head, len) {
        Ok(h) => h,
        Err(i) => {
            issues.push(i);
            return out;
        }
    };
    // parse_header checked that the table fits in the file.
    let mut table = vec![0u8; header.chunk_count as usize * ENTRY_LEN as usize];
    if let Err(e) = src.read_at(HEADER_LEN, &mut table) {
        issues.push(Issue::new(id::io::FILE_UNREADABLE, e.to_string()));
        return out;
    }
    let entries = chunk::parse_table(&head, &header, &table, issues);
    let mut read = |at: u64, n: usize| {
        let mut b = vec![0; n];
        src.read_at(at, &mut b).ok().map(|_| b)
    };
    chunk::check_padding(&entries, &mut read, issues);
    out.header = Some(header);

    // Read and verify the chunks; keep the metadata payloads whose checksums hold.
    let mut payloads: Vec<Option<Vec<u8>>> = vec![None; entries.len()];
    let mut ok = true;
    for (i, e) in entries.iter().enumerate() {
        let in_bounds = e.offset.checked_add(e.length).is_some_and(|end| end <= len);
        // Codestreams and masters are read on demand: a player never reads a master.
        let is_meta = chunk::rule(e.fourcc)
            .is_some_and(|r| r.fourcc != chunk::CSTR && r.fourcc != chunk::MSTR);
        if !in_bounds || !(is_meta || full) {
            ok &= in_bounds;
            continue;
        }
        let Some(bytes) = read(e.offset, e.length as usize) else {
            issues.push(
                Issue::new(id::io::FILE_UNREADABLE, "read failed")
                    .in_chunk(&e.name(), i)
                    .at(e.offset),
            );
            ok = false;
            continue;
        };
        let crc = crc32fast::hash(&bytes);
        if crc != e.crc {
            issues.push(
                Issue::new(
                    id::chunk::CHECKSUM_MISMATCH,
                    format!("stored {:#010x}, computed {crc:#010x}", e.crc),
                )
                .in_chunk(&e.name(), i)
                .at(e.offset),
            );
            ok = false;
            continue;
        }
        if is_meta {
            payloads[i] = Some(bytes);
        }
    }
    out.chunks = entries;
    // A reader refuses the file at its first broken rule; a validator goes on.
    if !full && (!ok || issues.iter().any(|i| i.severity == Severity::Error)) {
        return out;
    }
    out.container = parse(&out.chunks, &payloads, issues);
    out
}

/// Parses the metadata chunk `i` with `f`, when its payload was read and its checksum held
/// (else its issue is already reported). Broken rules that leave the payload readable are
/// reported and parsing goes on.
fn parse_chunk<T>(
    entries: &[ChunkEntry],
    payloads: &[Option<Vec<u8>>],
    i: usize,
    issues: &mut Vec<Issue>,
    f: impl FnOnce(&mut Cursor) -> Result<T, Issue>,
) -> Option<T> {
    let data = payloads[i].as_deref()?;
    let e = &entries[i];
    let malformed = chunk::rule(e.fourcc).map_or(id::chunk::CHECKSUM_MISMATCH, |r| r.malformed);
    let mut c = Cursor::new(data, e.offset, malformed, (chunk_name(e), i)).collecting();
    let parsed = f(&mut c);
    issues.extend(c.take_flagged());
    parsed.map_err(|issue| issues.push(issue)).ok()
}

/// Whether a broken rule leaves the file's codestreams undecodable or their decoded size
/// unbounded: the space, block origins, layer masks, block grids, texture sizes, pyramids
/// and codestream ranges.
fn guards_decoding(i: &Issue) -> bool {
    let layr = i.chunk.as_ref().is_some_and(|(t, _)| t == "LAYR");
    (4000..5000).contains(&i.id)
        || i.id == id::objects::STAGGER_NOT_BELOW_BLOCK
        || (i.id == id::cameras::MASK_NAMES_MISSING_DIMENSION && layr)
        || (6000..8000).contains(&i.id)
        || i.id == id::codestream::NOT_CSTR
        || i.id == id::codestream::OUTSIDE_CHUNK
}

fn parse(
    entries: &[ChunkEntry],
    payloads: &[Option<Vec<u8>>],
    issues: &mut Vec<Issue>,
) -> Option<Container<StreamRef>> {
    let find = |f: chunk::FourCC| entries.iter().position(|e| e.fourcc == f);
    let before = issues.len();
    let space = find(chunk::PSPC).and_then(|i| parse_chunk(entries, payloads, i, issues, pr::pspc));
    let cameras =
        find(chunk::CAMS).and_then(|i| parse_chunk(entries, payloads, i, issues, pr::cams));
    // OBJS needs the dimension count.
    let mut objects = match (&space, find(chunk::OBJS)) {
        (Some(s), Some(i)) => {
            let d = s.dims.len();
            parse_chunk(entries, payloads, i, issues, |c| pr::objs(c, d))
        }
        _ => None,
    };
    // Each MESH parses alone; it is given to its object when OBJS parsed.
    let mut has_mesh = vec![false; objects.as_ref().map_or(0, Vec::len)];
    let mut every_mesh_parsed = true;
    for (i, e) in entries.iter().enumerate().filter(|(_, e)| e.fourcc == chunk::MESH) {
        let Some((oi, mesh)) = parse_chunk(entries, payloads, i, issues, pr::mesh) else {
            every_mesh_parsed = false;
            continue;
        };
        let Some(objects) = objects.as_mut() else {
            continue;
        };
        match has_mesh.get_mut(oi as usize) {
            Some(seen @ false) => {
                *seen = true;
                objects[oi as usize].mesh = mesh;
            }
            _ => {
                issues.push(
                    Issue::new(
                        id::mesh::UNMATCHED_MESH,
                        format!(
                            "names object {oi}; {} objects, this one already meshed or missing",
                            objects.len()
                        ),
                    )
                    .in_chunk("MESH", i)
                    .at(e.offset),
                );
            }
        }
    }
    if let Some(objects) = &objects {
        // A MESH that did not parse may be the missing one.
        if every_mesh_parsed {
            for (oi, _) in has_mesh.iter().enumerate().filter(|(_, &m)| !m) {
                issues.push(Issue::new(
                    id::mesh::OBJECT_WITHOUT_MESH,
                    format!("object {oi} '{}' has no MESH chunk", objects[oi].name),
                ));
            }
        }
    }
    let layers = match (objects.as_mut(), find(chunk::LAYR)) {
        (Some(objects), Some(i)) => {
            let grid = space.as_ref().filter(|s| checks::space_holds(s));
            parse_chunk(entries, payloads, i, issues, |c| pr::layr(c, objects, grid)).is_some()
        }
        _ => false,
    };
    let provenance = match find(chunk::PROV) {
        Some(i) => parse_chunk(entries, payloads, i, issues, pr::prov).map(Some),
        None => Some(None),
    };

    let parsed = checks::Parsed {
        space: space.as_ref(),
        cameras: cameras.as_ref(),
        objects: objects.as_deref(),
        meshes: &has_mesh,
        layers,
        provenance: provenance.as_ref().map(Option::as_ref),
    };
    for mut issue in checks::check_parsed(&parsed) {
        // Name the chunk's index where its type occurs once.
        if let Some((t, idx)) = &mut issue.chunk {
            let matches: Vec<usize> = entries
                .iter()
                .enumerate()
                .filter(|(_, e)| chunk_name(e) == t)
                .map(|(i, _)| i)
                .collect();
            if matches.len() == 1 {
                *idx = matches[0];
            }
        }
        issues.push(issue);
    }
    // The codestreams need the space and the layers; what else did not parse is left empty
    // (its issues are reported, so a reader never uses such a container).
    let (Some(space), Some(objects), true) = (space, objects, layers) else {
        return None;
    };
    let container = Container {
        space,
        cameras: cameras.unwrap_or(CameraTable {
            width: 0,
            height: 0,
            depends_on: DepMask::NONE,
            cameras: Vec::new(),
        }),
        objects,
        provenance: provenance.flatten(),
    };
    stream_ranges(entries, &container, issues);
    if issues[before..].iter().any(guards_decoding) {
        return None;
    }
    if let Some(issue) = checks::decoded_sizes(&container, checks::referenced_bytes(&container)) {
        issues.push(issue);
        return None;
    }
    Some(container)
}

fn chunk_name(e: &ChunkEntry) -> &'static str {
    chunk::rule(e.fourcc).map_or("????", |r| match r.fourcc {
        chunk::PSPC => "PSPC",
        chunk::CAMS => "CAMS",
        chunk::OBJS => "OBJS",
        chunk::MESH => "MESH",
        chunk::LAYR => "LAYR",
        chunk::CSTR => "CSTR",
        chunk::MSTR => "MSTR",
        _ => "PROV",
    })
}

/// Rules 8001 and 8002: every reference lies inside a `CSTR` chunk.
fn stream_ranges(entries: &[ChunkEntry], c: &Container<StreamRef>, issues: &mut Vec<Issue>) {
    for_each_ref(c, |what, r| match entries.get(r.chunk as usize) {
        Some(e) if e.fourcc == chunk::CSTR => {
            if r.offset.checked_add(r.length as u64).is_none_or(|end| end > e.length) {
                issues.push(
                    Issue::new(
                        id::codestream::OUTSIDE_CHUNK,
                        format!(
                            "{what}: {} bytes at {} in a chunk of {}",
                            r.length, r.offset, e.length
                        ),
                    )
                    .in_chunk("LAYR", usize::MAX),
                );
            }
        }
        _ => issues.push(
            Issue::new(id::codestream::NOT_CSTR, format!("{what}: chunk {}", r.chunk))
                .in_chunk("LAYR", usize::MAX),
        ),
    });
}

/// Calls `f` with a description and each codestream reference, in file order.
pub(crate) fn for_each_ref(c: &Container<StreamRef>, mut f: impl FnMut(String, &StreamRef)) {
    for (oi, o) in c.objects.iter().enumerate() {
        for (li, l) in o.layers.iter().enumerate() {
            for (bi, b) in l.blocks.iter().enumerate() {
                for (lv, level) in b.levels.iter().enumerate() {
                    for (ii, r) in level.images.iter().enumerate() {
                        f(format!("object {oi} layer {li} block {bi} level {lv} image {ii}"), r);
                    }
                }
            }
        }
    }
}
