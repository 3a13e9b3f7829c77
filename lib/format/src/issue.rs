//! Validation issues: every rule of format-spec/SPEC.md, section "Validation", has a stable
//! numeric id. Ids are grouped by what they check: 1xxx I/O, 2xxx header, 3xxx chunk table,
//! 4xxx parameter space, 5xxx cameras, objects and meshes, 6xxx layers and blocks,
//! 7xxx pyramids, 8xxx codestreams, 9xxx provenance (91xx the lossless master). Each id has
//! a name in [`id`], one module per group (`id::layers::LEVEL_IMAGE_TOO_LARGE` is 6009), and
//! the checks name it so; the printed code stays the number (`error-6009`).

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

/// Declares each group's named rule ids (`id::layers::LEVEL_IMAGE_TOO_LARGE` is 6009) and
/// [`RULES`], the table of every id with its short message, from one list: an id has a
/// name exactly when it has a row.
macro_rules! rules {
    ($($(#[$group_doc:meta])* pub mod $group:ident { $($name:ident = $id:literal, $message:literal;)+ })+) => {
        /// The rule ids by name, one module per group of section 13.
        pub mod id {
            $($(#[$group_doc])* pub mod $group {
                $(#[doc = concat!("`", stringify!($id), "`: ", $message, ".")] pub const $name: u16 = $id;)+
            })+
        }

        /// Every rule id with its short message, in spec order.
        pub const RULES: &[(u16, &str)] = &[$($(($id, $message),)+)+];
    };
}

#[rustfmt::skip]
rules! {
    /// 1xxx: reading the file.
    pub mod io {
        FILE_UNREADABLE = 1001, "file cannot be read";
        FILE_TOO_SHORT = 1002, "file is shorter than the header";
        FILE_LENGTH_MISMATCH = 1003, "file length in the header differs from the file's size";
    }
    /// 2xxx: the file header.
    pub mod header {
        BAD_MAGIC = 2001, "not a PIS file (bad magic)";
        UNSUPPORTED_VERSION = 2002, "unsupported major version";
        RESERVED_FLAGS_SET = 2003, "reserved header flags are set";
        CHECKSUM_MISMATCH = 2004, "header checksum mismatch";
        CHUNK_TABLE_OUTSIDE_FILE = 2005, "chunk table does not fit in the file";
    }
    /// 3xxx: the chunk table and the fields every chunk has.
    pub mod chunk {
        OFFSET_MISALIGNED = 3001, "chunk offset is not a multiple of 8";
        PAST_END_OF_FILE = 3002, "chunk extends past the end of the file";
        NOT_AT_NEXT_ALIGNED_OFFSET = 3003, "chunk does not start at the first multiple of 8 after the previous data";
        CHECKSUM_MISMATCH = 3004, "chunk checksum mismatch";
        PADDING_NOT_ZERO = 3005, "padding byte is not zero";
        RESERVED_NOT_ZERO = 3006, "reserved field is not zero";
        UNKNOWN_REQUIRED = 3007, "unknown chunk is marked required";
        REQUIRED_MISSING = 3008, "required chunk is missing";
        REPEATED = 3009, "chunk appears more than once";
        FLAGS_MISMATCH = 3010, "chunk flags differ from those its type must carry";
        BYTES_AFTER_LAST_CHUNK = 3011, "bytes after the last chunk";
    }
    /// 4xxx: the parameter space (`PSPC`).
    pub mod space {
        MALFORMED = 4000, "PSPC payload is malformed";
        DIMENSION_COUNT = 4001, "dimension count out of range";
        DIMENSION_NAME = 4002, "dimension name is empty, not UTF-8 or repeated, or its unit is not UTF-8";
        UNKNOWN_DIMENSION_KIND = 4003, "unknown dimension kind";
        NO_SAMPLES = 4004, "dimension has no samples";
        ZERO_BLOCK_SIZE = 4005, "block size is zero";
        VALUES_NOT_INCREASING = 4006, "sample values are not finite and strictly increasing";
        TOO_MANY_POINTS = 4007, "too many parameter points";
    }
    /// 50xx: the cameras (`CAMS`) and the tables indexed by parameter point.
    pub mod cameras {
        MALFORMED = 5000, "CAMS payload is malformed";
        TABLE_SIZE = 5001, "table size differs from the product of its dimensions' sample counts";
        MASK_NAMES_MISSING_DIMENSION = 5002, "dependency mask names a dimension that does not exist";
        INVALID_CAMERA = 5003, "camera is not finite or not a valid perspective camera";
        IMAGE_SIZE = 5004, "image size is zero or too large";
    }
    /// 51xx: the objects (`OBJS`).
    pub mod objects {
        MALFORMED = 5100, "OBJS payload is malformed";
        OBJECT_COUNT = 5101, "object count out of range";
        OBJECT_NAME = 5102, "object name is empty, not UTF-8 or repeated";
        UNKNOWN_ROLE = 5103, "unknown object role";
        SHADING_OUT_OF_RANGE = 5104, "shading constants out of range";
        STAGGER_NOT_BELOW_BLOCK = 5105, "staggered block origin is not less than the block size";
        TRANSFORM_NOT_RIGID = 5106, "transform is not finite, or its 3×3 part is not a rotation within 10⁻³ (section 6.4)";
    }
    /// 52xx: the meshes (`MESH`).
    pub mod mesh {
        MALFORMED = 5200, "MESH payload is malformed";
        UNMATCHED_MESH = 5201, "mesh names a missing object, or a second mesh names the same object";
        OBJECT_WITHOUT_MESH = 5202, "object has no mesh";
        INDEX_COUNT = 5203, "index count is zero or not a multiple of 3";
        INDEX_OUT_OF_RANGE = 5204, "vertex index out of range";
        VERTEX_NOT_FINITE = 5205, "vertex data is not finite";
        TOO_MANY_HULL_TRIANGLES = 5206, "more hull triangles than triangles";
        NO_VERTICES = 5207, "mesh has no vertices";
    }
    /// 6xxx: the layers and their blocks (`LAYR`), and the limits of section 12.
    pub mod layers {
        MALFORMED = 6000, "LAYR payload is malformed";
        UNKNOWN_OBJECT = 6001, "layer names an object that does not exist";
        UNKNOWN_CODE = 6002, "unknown layer kind, mapping, mip mode, term or combine mode";
        INVALID_COMBINATION = 6003, "invalid combination of layer fields";
        GAMMA = 6004, "gamma is not finite and positive";
        BLOCK_COUNT = 6005, "block count differs from the layer's block grid";
        TEXTURE_SIZE = 6006, "texture size is zero, too large, or a shell face is not square";
        BLOCK_PLACEMENT = 6007, "block placement is invalid";
        TERM_ORDER_REPEATED = 6008, "two layers of one object share a term, order and light basis";
        LEVEL_IMAGE_TOO_LARGE = 6009, "a level image decodes to more than 8192 × C bytes (section 12)";
        LEVEL_IMAGES_TOO_LARGE = 6010, "the level images together decode to more than 131072 × C bytes (section 12)";
        LIGHT_BASIS = 6011, "a light-basis layer has no light directions to span, or depends on their dimension";
    }
    /// 7xxx: a block's pyramid levels.
    pub mod pyramid {
        LEVEL_COUNT = 7001, "level count out of range";
        TOP_LEVEL_NOT_ONE_SAMPLE = 7002, "top pyramid level holds more than one sample";
        LEVEL_COUNTS = 7003, "level sample counts decrease or exceed the block extent";
        FINEST_LEVEL_EXTENT = 7004, "finest level does not match the block extent";
        STATIC_LAYER_LEVELS = 7005, "layer with dependency mask 0 has more than one level";
    }
    /// 8xxx: the codestreams (`CSTR`) and what they decode to.
    pub mod codestream {
        NOT_CSTR = 8001, "codestream reference names a chunk that is not CSTR";
        OUTSIDE_CHUNK = 8002, "codestream lies outside its chunk";
        CHECKSUM_MISMATCH = 8003, "codestream checksum mismatch";
        UNKNOWN_CODEC = 8004, "unknown codec id";
        PLANES_MISMATCH = 8005, "codestream does not decode to the declared planes";
        VALUE_NOT_FINITE = 8006, "decoded value is not finite";
        RESERVED_CODEC = 8007, "codec is reserved and not decodable by this reader";
        TRAILING_BYTES = 8008, "codestream has bytes after the end of its data";
    }
    /// 90xx: the provenance (`PROV`) and its settings.
    pub mod provenance {
        MALFORMED = 9000, "PROV payload is malformed";
        FILTER = 9001, "filter setting is unknown, names no object, or anisotropic without an anisotropy of 1 to 16";
        DISPLAY_FILTER = 9002, "display filter setting is unknown, or its sigma or radius is missing or not a number of pixels in (0, 64]";
        KEY_REPEATED = 9003, "setting key appears more than once";
        TINT = 9004, "transmission tint setting names no refractive object, or is not three numbers in [0, 1]";
        LENS_MODEL = 9005, "lens model setting names no refractive object, or is neither greedy nor tree,W,N";
        LIGHT_DIRECTIONS = 9006, "light directions name no light dimension, differ from its samples in count, are not unit, or lack a positive radiance";
    }
    /// 91xx: the lossless master (`MSTR`, section 6.7), checked when a reader reads it.
    pub mod master {
        MALFORMED = 9100, "MSTR payload is malformed";
        UNMATCHED_MASTER = 9101, "master names a missing object, or a second master names the same object";
        LAYOUT_MISMATCH = 9102, "master layers or samples differ from the object's";
        CODEC_NOT_EXACT = 9103, "master codec is not raw or lossless";
        SCREEN_AREA = 9104, "master screen area is not finite and positive";
        PLANES_MISMATCH = 9105, "master texture does not decode to its block's planes";
        VALUE_NOT_FINITE = 9106, "decoded master value is not finite";
        NOT_EVERY_OBJECT = 9107, "some objects have a master and others do not";
        SCREEN_WEIGHTS = 9108, "master screen weights do not decode to one finite non-negative value per finest texel";
    }
}

/// The short message of rule `id` ("unknown rule" for ids not in [`RULES`]).
pub fn summary(id: u16) -> &'static str {
    RULES.iter().find(|(i, _)| *i == id).map(|(_, m)| *m).unwrap_or("unknown rule")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A named id prints as its number, and every id is listed once, in spec order.
    #[test]
    fn named_ids_are_the_spec_numbers() {
        assert_eq!(id::layers::LEVEL_IMAGE_TOO_LARGE, 6009);
        assert_eq!(Issue::new(id::layers::LEVEL_IMAGE_TOO_LARGE, "").code(), "error-6009");
        assert_eq!(Issue::warning(id::codestream::RESERVED_CODEC, "").code(), "warning-8007");
        assert!(RULES.windows(2).all(|w| w[0].0 < w[1].0), "ids repeated or out of order");
    }
}
