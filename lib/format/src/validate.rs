//! Full validation (`pis-inspect --validate`): every rule of the spec, every checksum, and
//! every codestream decoded. Every broken rule is reported, not only the first; a rule is
//! skipped only when what it checks did not parse or builds on a broken rule (SPEC.md 13).

use std::path::Path;

use pis_codec::CodecError;

use crate::issue::id;
use crate::model::StreamRef;
use crate::read::{for_each_ref, load};
use crate::source::{FileSource, Source};
use crate::texture::LevelLayout;
use crate::{chunk::ChunkEntry, Issue, Severity};

/// The outcome of validating one file.
#[derive(Debug, Default)]
pub struct Validation {
    pub issues: Vec<Issue>,
    /// The chunk table, as far as it could be read.
    pub chunks: Vec<ChunkEntry>,
    /// Per chunk: does its payload match its checksum (None = not checked: out of bounds).
    pub chunk_crc_ok: Vec<Option<bool>>,
}

impl Validation {
    pub fn is_valid(&self) -> bool {
        self.issues.iter().all(|i| i.severity != Severity::Error)
    }
}

pub fn validate_file(path: &Path) -> Validation {
    match std::fs::File::open(path).and_then(FileSource::new) {
        Ok(src) => validate_source(&src),
        Err(e) => Validation {
            issues: vec![Issue::new(id::io::FILE_UNREADABLE, format!("{}: {e}", path.display()))],
            ..Default::default()
        },
    }
}

pub fn validate_bytes(bytes: Vec<u8>) -> Validation {
    validate_source(&bytes)
}

fn validate_source(src: &dyn Source) -> Validation {
    let mut issues = Vec::new();
    let loaded = load(src, true, &mut issues);
    let chunk_crc_ok = loaded
        .chunks
        .iter()
        .map(|e| {
            let end = e.offset.checked_add(e.length)?;
            if end > src.len() {
                return None;
            }
            let mut b = vec![0; e.length as usize];
            src.read_at(e.offset, &mut b).ok()?;
            Some(crc32fast::hash(&b) == e.crc)
        })
        .collect();
    if let Some(c) = &loaded.container {
        let chunks = &loaded.chunks;
        let mut layouts = Vec::new();
        for o in &c.objects {
            for l in &o.layers {
                for b in &l.blocks {
                    let layout = LevelLayout::of(l, b);
                    for level in &b.levels {
                        layouts.extend(std::iter::repeat_n(layout.clone(), level.images.len()));
                    }
                }
            }
        }
        let mut k = 0;
        for_each_ref(c, |what, r| {
            // A chunk past the end of the file is reported by the table (rule 3002).
            let in_file = chunks[r.chunk as usize]
                .offset
                .checked_add(chunks[r.chunk as usize].length)
                .is_some_and(|end| end <= src.len());
            if in_file {
                if let Some(issue) = check_stream(src, chunks, r, &layouts[k], &what) {
                    issues.push(issue);
                }
            }
            k += 1;
        });
        // The master: structure, rules and every texture decoded (a container is only
        // returned when its level images are within section 12's limits, which bound the
        // master's textures too).
        crate::master::load(src, chunks, c, true, &mut issues);
    }
    Validation { issues, chunks: loaded.chunks, chunk_crc_ok }
}

fn check_stream(
    src: &dyn Source,
    chunks: &[ChunkEntry],
    r: &StreamRef,
    layout: &LevelLayout,
    what: &str,
) -> Option<Issue> {
    let e = &chunks[r.chunk as usize];
    let at = e.offset + r.offset;
    let tag = |i: Issue| i.in_chunk("CSTR", r.chunk as usize).at(at);
    let mut bytes = vec![0; r.length as usize];
    if let Err(err) = src.read_at(at, &mut bytes) {
        return Some(tag(Issue::new(id::io::FILE_UNREADABLE, format!("{what}: {err}"))));
    }
    let crc = crc32fast::hash(&bytes);
    if crc != r.crc {
        return Some(tag(Issue::new(
            id::codestream::CHECKSUM_MISMATCH,
            format!("{what}: stored {:#010x}, computed {crc:#010x}", r.crc),
        )));
    }
    match pis_codec::decode(r.codec, &layout.planes(), &bytes) {
        Ok(values) => {
            let bad = values.iter().position(|v| !v.is_finite())?;
            Some(tag(Issue::new(
                id::codestream::VALUE_NOT_FINITE,
                format!("{what}: value {bad} is {}", values[bad]),
            )))
        }
        Err(err @ CodecError::TrailingBytes { .. }) => {
            Some(tag(Issue::new(id::codestream::TRAILING_BYTES, format!("{what}: {err}"))))
        }
        Err(CodecError::NotSupported(c)) => Some(tag(Issue::warning(
            id::codestream::RESERVED_CODEC,
            format!("{what}: codec '{c}' cannot be checked by this build"),
        ))),
        Err(err) => {
            Some(tag(Issue::new(id::codestream::PLANES_MISMATCH, format!("{what}: {err}"))))
        }
    }
}
