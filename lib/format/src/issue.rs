//! Validation issues: every rule of format-spec/SPEC.md, section "Validation", has a stable
//! numeric id. Ids are grouped by what they check: 1xxx I/O, 2xxx header, 3xxx chunk table,
//! 4xxx parameter space, 5xxx cameras, objects and meshes, 6xxx layers and blocks,
//! 7xxx pyramids, 8xxx codestreams, 9xxx provenance (91xx the lossless master).

use std::fmt;

/// How bad an issue is: errors make a file invalid, warnings do not.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Severity {
    Error,
    Warning,
}

/// One broken rule, with where it was found.
#[derive(Clone, Debug, PartialEq)]
pub struct Issue {
    pub id: u16,
    pub severity: Severity,
    /// The chunk at fault: its type and index in the chunk table (`usize::MAX` when the
    /// index is not known, as for rules checked on an in-memory model).
    pub chunk: Option<(String, usize)>,
    /// Absolute byte offset in the file, where one can be named.
    pub offset: Option<u64>,
    /// What was expected, what was found.
    pub detail: String,
}

impl Issue {
    pub fn new(id: u16, detail: impl Into<String>) -> Self {
        Issue { id, severity: Severity::Error, chunk: None, offset: None, detail: detail.into() }
    }

    pub fn warning(id: u16, detail: impl Into<String>) -> Self {
        Issue { severity: Severity::Warning, ..Issue::new(id, detail) }
    }

    pub fn at(mut self, offset: u64) -> Self {
        self.offset = Some(offset);
        self
    }

    pub fn in_chunk(mut self, fourcc: &str, index: usize) -> Self {
        self.chunk = Some((fourcc.to_string(), index));
        self
    }

    /// The rule's short message, as listed in the spec.
    pub fn summary(&self) -> &'static str {
        summary(self.id)
    }

    /// `error-3004` or `warning-8007`.
    pub fn code(&self) -> String {
        match self.severity {
            Severity::Error => format!("error-{}", self.id),
            Severity::Warning => format!("warning-{}", self.id),
        }
    }
}

impl fmt::Display for Issue {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.code(), self.summary())?;
        let chunk = self.chunk.as_ref().map(|(t, i)| match i {
            &usize::MAX => format!("chunk '{t}'"),
            i => format!("chunk {i} '{t}'"),
        });
        match (chunk, self.offset) {
            (Some(c), Some(o)) => write!(f, " ({c}, byte {o:#x})")?,
            (Some(c), None) => write!(f, " ({c})")?,
            (None, Some(o)) => write!(f, " (byte {o:#x})")?,
            (None, None) => {}
        }
        write!(f, ": {}", self.detail)
    }
}

/// Every rule id with its short message, in spec order.
#[rustfmt::skip]
pub const RULES: &[(u16, &str)] = &[
    (1001, "file cannot be read"),
    (1002, "file is shorter than the header"),
    (1003, "file length in the header differs from the file's size"),
    (2001, "not a PIS file (bad magic)"),
    (2002, "unsupported major version"),
    (2003, "reserved header flags are set"),
    (2004, "header checksum mismatch"),
    (2005, "chunk table does not fit in the file"),
    (3001, "chunk offset is not a multiple of 8"),
    (3002, "chunk extends past the end of the file"),
    (3003, "chunk does not start at the first multiple of 8 after the previous data"),
    (3004, "chunk checksum mismatch"),
    (3005, "padding byte is not zero"),
    (3006, "reserved field is not zero"),
    (3007, "unknown chunk is marked required"),
    (3008, "required chunk is missing"),
    (3009, "chunk appears more than once"),
    (3010, "chunk flags differ from those its type must carry"),
    (3011, "bytes after the last chunk"),
    (4000, "PSPC payload is malformed"),
    (4001, "dimension count out of range"),
    (4002, "dimension name is empty, not UTF-8 or repeated, or its unit is not UTF-8"),
    (4003, "unknown dimension kind"),
    (4004, "dimension has no samples"),
    (4005, "block size is zero"),
    (4006, "sample values are not finite and strictly increasing"),
    (4007, "too many parameter points"),
    (5000, "CAMS payload is malformed"),
    (5001, "table size differs from the product of its dimensions' sample counts"),
    (5002, "dependency mask names a dimension that does not exist"),
    (5003, "camera is not finite or not a valid perspective camera"),
    (5004, "image size is zero or too large"),
    (5100, "OBJS payload is malformed"),
    (5101, "object count out of range"),
    (5102, "object name is empty, not UTF-8 or repeated"),
    (5103, "unknown object role"),
    (5104, "shading constants out of range"),
    (5105, "staggered block origin is not less than the block size"),
    (5106, "transform is not finite, or its 3×3 part is not a rotation within 10⁻³ (section 6.4)"),
    (5200, "MESH payload is malformed"),
    (5201, "mesh names a missing object, or a second mesh names the same object"),
    (5202, "object has no mesh"),
    (5203, "index count is zero or not a multiple of 3"),
    (5204, "vertex index out of range"),
    (5205, "vertex data is not finite"),
    (5206, "more hull triangles than triangles"),
    (5207, "mesh has no vertices"),
    (6000, "LAYR payload is malformed"),
    (6001, "layer names an object that does not exist"),
    (6002, "unknown layer kind, mapping, mip mode, term or combine mode"),
    (6003, "invalid combination of layer fields"),
    (6004, "gamma is not finite and positive"),
    (6005, "block count differs from the layer's block grid"),
    (6006, "texture size is zero, too large, or a shell face is not square"),
    (6007, "block placement is invalid"),
    (6008, "two layers of one object share a term and order"),
    (6009, "a level image decodes to more than 8192 × C bytes (section 12)"),
    (6010, "the level images together decode to more than 131072 × C bytes (section 12)"),
    (7001, "level count out of range"),
    (7002, "top pyramid level holds more than one sample"),
    (7003, "level sample counts decrease or exceed the block extent"),
    (7004, "finest level does not match the block extent"),
    (7005, "layer with dependency mask 0 has more than one level"),
    (8001, "codestream reference names a chunk that is not CSTR"),
    (8002, "codestream lies outside its chunk"),
    (8003, "codestream checksum mismatch"),
    (8004, "unknown codec id"),
    (8005, "codestream does not decode to the declared planes"),
    (8006, "decoded value is not finite"),
    (8007, "codec is reserved and not decodable by this reader"),
    (8008, "codestream has bytes after the end of its data"),
    (9000, "PROV payload is malformed"),
    (9001, "filter setting is unknown, or anisotropic without an anisotropy of 1 to 16"),
    (9002, "display filter setting is unknown, or its sigma or radius is missing or not a number of pixels in (0, 64]"),
    (9003, "setting key appears more than once"),
    (9004, "transmission tint setting names no refractive object, or is not three numbers in [0, 1]"),
    (9100, "MSTR payload is malformed"),
    (9101, "master names a missing object, or a second master names the same object"),
    (9102, "master layers or samples differ from the object's"),
    (9103, "master codec is not raw or lossless"),
    (9104, "master screen area is not finite and positive"),
    (9105, "master texture does not decode to its block's planes"),
    (9106, "decoded master value is not finite"),
    (9107, "some objects have a master and others do not"),
    (9108, "master screen weights do not decode to one finite non-negative value per finest texel"),
];

/// The short message of rule `id` ("unknown rule" for ids not in [`RULES`]).
pub fn summary(id: u16) -> &'static str {
    RULES.iter().find(|(i, _)| *i == id).map(|(_, m)| *m).unwrap_or("unknown rule")
}
