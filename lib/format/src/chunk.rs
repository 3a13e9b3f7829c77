//! The file header and the chunk table (SPEC.md sections "File header" and "Chunk table").

use crate::issue::id;
use crate::Issue;

/// `\x89PIS\r\n\x1a\n`: a non-ASCII first byte, the name, and line-ending and EOF bytes
/// that reveal text-mode transfers (as in PNG).
pub const MAGIC: [u8; 8] = [0x89, b'P', b'I', b'S', 0x0D, 0x0A, 0x1A, 0x0A];
pub const VERSION_MAJOR: u16 = 1;
/// The minor version of this text (SPEC.md 10.1); writers write the lowest one a file needs.
pub const VERSION_MINOR: u16 = 6;
pub const HEADER_LEN: u64 = 32;
pub const ENTRY_LEN: u64 = 32;
/// Chunk payloads start at multiples of this.
pub const ALIGN: u64 = 8;
/// Chunk flag bit 0: a reader that does not know the chunk type must refuse the file.
pub const FLAG_REQUIRED: u32 = 1;

/// A chunk type code.
pub type FourCC = [u8; 4];

pub const PSPC: FourCC = *b"PSPC";
pub const CAMS: FourCC = *b"CAMS";
pub const OBJS: FourCC = *b"OBJS";
pub const MESH: FourCC = *b"MESH";
pub const LAYR: FourCC = *b"LAYR";
pub const CSTR: FourCC = *b"CSTR";
pub const PROV: FourCC = *b"PROV";
pub const MSTR: FourCC = *b"MSTR";

/// What version 1 says of each chunk type it defines.
pub struct ChunkRule {
    pub fourcc: FourCC,
    pub required: bool,
    pub min: usize,
    /// None = any number.
    pub max: Option<usize>,
    /// Rule id for a malformed payload.
    pub malformed: u16,
}

pub const KNOWN: [ChunkRule; 8] = [
    ChunkRule {
        fourcc: PSPC,
        required: true,
        min: 1,
        max: Some(1),
        malformed: id::space::MALFORMED,
    },
    ChunkRule {
        fourcc: CAMS,
        required: true,
        min: 1,
        max: Some(1),
        malformed: id::cameras::MALFORMED,
    },
    ChunkRule {
        fourcc: OBJS,
        required: true,
        min: 1,
        max: Some(1),
        malformed: id::objects::MALFORMED,
    },
    ChunkRule { fourcc: MESH, required: true, min: 1, max: None, malformed: id::mesh::MALFORMED },
    ChunkRule {
        fourcc: LAYR,
        required: true,
        min: 1,
        max: Some(1),
        malformed: id::layers::MALFORMED,
    },
    ChunkRule {
        fourcc: CSTR,
        required: true,
        min: 0,
        max: None,
        malformed: id::codestream::OUTSIDE_CHUNK,
    },
    ChunkRule {
        fourcc: PROV,
        required: false,
        min: 0,
        max: Some(1),
        malformed: id::provenance::MALFORMED,
    },
    ChunkRule {
        fourcc: MSTR,
        required: false,
        min: 0,
        max: None,
        malformed: id::master::MALFORMED,
    },
];

pub fn rule(fourcc: FourCC) -> Option<&'static ChunkRule> {
    KNOWN.iter().find(|r| r.fourcc == fourcc)
}

/// The chunk type as text (non-printable bytes escaped).
pub fn fourcc_str(f: FourCC) -> String {
    f.iter()
        .map(
            |&b| {
                if b.is_ascii_graphic() {
                    (b as char).to_string()
                } else {
                    format!("\\x{b:02x}")
                }
            },
        )
        .collect()
}

/// The fixed 32-byte header.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Header {
    pub major: u16,
    pub minor: u16,
    pub flags: u32,
    pub file_length: u64,
    pub chunk_count: u32,
    pub crc: u32,
}

/// One chunk-table entry.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ChunkEntry {
    pub fourcc: FourCC,
    pub flags: u32,
    pub offset: u64,
    pub length: u64,
    pub crc: u32,
}

impl ChunkEntry {
    pub fn name(&self) -> String {
        fourcc_str(self.fourcc)
    }

    pub fn required(&self) -> bool {
        self.flags & FLAG_REQUIRED != 0
    }

    pub fn end(&self) -> u64 {
        self.offset.saturating_add(self.length)
    }
}

/// Parses the header from the first 32 bytes. Fatal problems (nothing after them can be
/// trusted) are returned as `Err`.
pub fn parse_header(b: &[u8], actual_len: u64) -> Result<Header, Issue> {
    if actual_len < HEADER_LEN || b.len() < HEADER_LEN as usize {
        return Err(Issue::new(
            id::io::FILE_TOO_SHORT,
            format!("file has {actual_len} bytes, the header alone needs {HEADER_LEN}"),
        ));
    }
    if b[0..8] != MAGIC {
        return Err(Issue::new(
            id::header::BAD_MAGIC,
            format!("first 8 bytes are {:02x?}, expected {MAGIC:02x?}", &b[0..8]),
        )
        .at(0));
    }
    let u16_at = |o: usize| u16::from_le_bytes([b[o], b[o + 1]]);
    let u32_at = |o: usize| u32::from_le_bytes([b[o], b[o + 1], b[o + 2], b[o + 3]]);
    let h = Header {
        major: u16_at(8),
        minor: u16_at(10),
        flags: u32_at(12),
        file_length: u64::from_le_bytes(b[16..24].try_into().expect("8 bytes")),
        chunk_count: u32_at(24),
        crc: u32_at(28),
    };
    if h.major != VERSION_MAJOR {
        return Err(Issue::new(
            id::header::UNSUPPORTED_VERSION,
            format!("major version {}, this reader reads {VERSION_MAJOR}", h.major),
        )
        .at(8));
    }
    if h.file_length != actual_len {
        return Err(Issue::new(
            id::io::FILE_LENGTH_MISMATCH,
            format!(
                "header says {} bytes, the file has {actual_len} (truncated or extended)",
                h.file_length
            ),
        )
        .at(16));
    }
    let table_end =
        (h.chunk_count as u64).checked_mul(ENTRY_LEN).and_then(|t| t.checked_add(HEADER_LEN));
    match table_end {
        Some(end) if end <= actual_len => Ok(h),
        _ => Err(Issue::new(
            id::header::CHUNK_TABLE_OUTSIDE_FILE,
            format!("{} chunk entries do not fit in {actual_len} bytes", h.chunk_count),
        )
        .at(24)),
    }
}

/// CRC-32 that covers the header's first 28 bytes followed by the chunk table.
pub fn header_crc(header: &[u8], table: &[u8]) -> u32 {
    let mut h = crc32fast::Hasher::new();
    h.update(&header[..28]);
    h.update(table);
    h.finalize()
}

/// Parses and checks the chunk table. Non-fatal issues (header flags, checksum, entry
/// problems) are pushed to `issues`; every entry is returned so that `--chunks` can list it.
pub fn parse_table(
    header_bytes: &[u8],
    h: &Header,
    table: &[u8],
    issues: &mut Vec<Issue>,
) -> Vec<ChunkEntry> {
    if h.flags != 0 {
        issues.push(
            Issue::new(
                id::header::RESERVED_FLAGS_SET,
                format!("flags are {:#x}, version 1 defines none", h.flags),
            )
            .at(12),
        );
    }
    let crc = header_crc(header_bytes, table);
    if crc != h.crc {
        issues.push(
            Issue::new(
                id::header::CHECKSUM_MISMATCH,
                format!("stored {:#010x}, computed {crc:#010x}", h.crc),
            )
            .at(28),
        );
    }
    let mut entries = Vec::with_capacity(h.chunk_count as usize);
    let table_end = HEADER_LEN + h.chunk_count as u64 * ENTRY_LEN;
    let mut prev_end = table_end;
    for (i, e) in table.chunks_exact(ENTRY_LEN as usize).enumerate() {
        let at = HEADER_LEN + i as u64 * ENTRY_LEN;
        let entry = ChunkEntry {
            fourcc: [e[0], e[1], e[2], e[3]],
            flags: u32::from_le_bytes(e[4..8].try_into().expect("4 bytes")),
            offset: u64::from_le_bytes(e[8..16].try_into().expect("8 bytes")),
            length: u64::from_le_bytes(e[16..24].try_into().expect("8 bytes")),
            crc: u32::from_le_bytes(e[24..28].try_into().expect("4 bytes")),
        };
        let reserved = u32::from_le_bytes(e[28..32].try_into().expect("4 bytes"));
        let name = entry.name();
        let tag = |id: u16, d: String| Issue::new(id, d).in_chunk(&name, i);
        if reserved != 0 {
            issues.push(
                tag(
                    id::chunk::RESERVED_NOT_ZERO,
                    format!("entry's reserved word is {reserved:#x}"),
                )
                .at(at + 28),
            );
        }
        if entry.flags & !FLAG_REQUIRED != 0 {
            issues.push(
                tag(
                    id::chunk::RESERVED_NOT_ZERO,
                    format!("flags {:#x} set undefined bits", entry.flags),
                )
                .at(at + 4),
            );
        }
        match rule(entry.fourcc) {
            Some(r) if r.required != entry.required() => issues.push(
                tag(
                    id::chunk::FLAGS_MISMATCH,
                    format!(
                        "'{name}' must {}carry the required flag",
                        if r.required { "" } else { "not " }
                    ),
                )
                .at(at + 4),
            ),
            None if entry.required() => issues.push(
                tag(
                    id::chunk::UNKNOWN_REQUIRED,
                    format!("chunk type '{name}' is not defined by version 1"),
                )
                .at(at),
            ),
            _ => {}
        }
        if !entry.offset.is_multiple_of(ALIGN) {
            issues.push(
                tag(
                    id::chunk::OFFSET_MISALIGNED,
                    format!("offset {} is not a multiple of {ALIGN}", entry.offset),
                )
                .at(at + 8),
            );
        }
        if entry.offset.checked_add(entry.length).is_none_or(|end| end > h.file_length) {
            issues.push(
                tag(
                    id::chunk::PAST_END_OF_FILE,
                    format!(
                        "{} bytes at offset {} end past the file's {} bytes",
                        entry.length, entry.offset, h.file_length
                    ),
                )
                .at(at + 16),
            );
        } else if entry.offset != prev_end.next_multiple_of(ALIGN) {
            issues.push(
                tag(
                    id::chunk::NOT_AT_NEXT_ALIGNED_OFFSET,
                    format!(
                    "starts at {}; the previous data ends at {prev_end}, so it must start at {}",
                    entry.offset,
                    prev_end.next_multiple_of(ALIGN)
                ),
                )
                .at(at + 8),
            );
            prev_end = prev_end.max(entry.end());
        } else {
            prev_end = entry.end();
        }
        entries.push(entry);
    }
    if issues.iter().all(|i| !(3001..=id::chunk::NOT_AT_NEXT_ALIGNED_OFFSET).contains(&i.id))
        && prev_end != h.file_length
    {
        issues.push(
            Issue::new(
                id::chunk::BYTES_AFTER_LAST_CHUNK,
                format!("last chunk ends at {prev_end}, the file at {}", h.file_length),
            )
            .at(prev_end),
        );
    }
    // Counts per known type.
    for r in &KNOWN {
        let n = entries.iter().filter(|e| e.fourcc == r.fourcc).count();
        let name = fourcc_str(r.fourcc);
        if n < r.min {
            issues.push(Issue::new(id::chunk::REQUIRED_MISSING, format!("no '{name}' chunk")));
        }
        if r.max.is_some_and(|m| n > m) {
            issues.push(Issue::new(
                id::chunk::REPEATED,
                format!("{n} '{name}' chunks, at most {} allowed", r.max.unwrap_or(0)),
            ));
        }
    }
    entries
}

/// Checks the padding between the table and the first chunk and between chunks (all zero).
pub fn check_padding(
    entries: &[ChunkEntry],
    read: &mut dyn FnMut(u64, usize) -> Option<Vec<u8>>,
    issues: &mut Vec<Issue>,
) {
    let mut pos = HEADER_LEN + entries.len() as u64 * ENTRY_LEN;
    for e in entries {
        if e.offset > pos && e.offset - pos < ALIGN {
            if let Some(pad) = read(pos, (e.offset - pos) as usize) {
                if let Some(k) = pad.iter().position(|&b| b != 0) {
                    issues.push(
                        Issue::new(
                            id::chunk::PADDING_NOT_ZERO,
                            format!("padding byte is {:#04x}", pad[k]),
                        )
                        .at(pos + k as u64),
                    );
                }
            }
        }
        pos = pos.max(e.end());
    }
}

/// Recomputes every chunk's checksum and the header's (as far as the chunk table is there) in
/// `b`: for crafting files whose damage lies past the checksums, as mutation tests do.
pub fn reseal(b: &mut [u8]) {
    let u32_at = |b: &[u8], at: usize| u32::from_le_bytes(b[at..at + 4].try_into().unwrap());
    let u64_at = |b: &[u8], at: usize| u64::from_le_bytes(b[at..at + 8].try_into().unwrap());
    if b.len() < HEADER_LEN as usize {
        return;
    }
    let count = (u32_at(b, 24) as usize).min((b.len() - HEADER_LEN as usize) / ENTRY_LEN as usize);
    for i in 0..count {
        let e = (HEADER_LEN + i as u64 * ENTRY_LEN) as usize;
        let (off, len) = (u64_at(b, e + 8) as usize, u64_at(b, e + 16) as usize);
        if off.checked_add(len).is_some_and(|end| end <= b.len()) {
            let crc = crc32fast::hash(&b[off..off + len]);
            b[e + 24..e + 28].copy_from_slice(&crc.to_le_bytes());
        }
    }
    let table_end = (HEADER_LEN + u32_at(b, 24) as u64 * ENTRY_LEN).min(b.len() as u64) as usize;
    let crc = header_crc(&b[..28], &b[32..table_end]);
    b[28..32].copy_from_slice(&crc.to_le_bytes());
}
