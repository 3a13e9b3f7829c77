//! The lossless master (chunk `MSTR`, SPEC.md 6.7): an object's textures exactly as a writer
//! solved them, before gamma compensation and lossy coding, so that a tool can code the level
//! images again without the error of a first coding. A player never reads it: the reader
//! leaves `MSTR` chunks alone when a file is opened and reads them on request
//! ([`crate::PisReader::masters`]), verifying checksum, structure and the rules of 6.7.

use pis_codec::{CodecError, CodecId, PlaneShape, Rate};

use crate::binary::{Cursor, Sink};
use crate::blocks::BlockGrid;
use crate::chunk::{self, ChunkEntry};
use crate::issue::id;
use crate::model::{Container, Layer, Object};
use crate::source::Source;
use crate::texture::LevelLayout;
use crate::{Error, Issue};

/// One object's master.
#[derive(Clone, Debug, PartialEq)]
pub struct Master {
    /// The object's index in the container.
    pub object: u32,
    /// Mean covered pixels per parameter point: the screen-area weight the writer's storage
    /// allocation gave the object (thesis 4.5), so that a tool coding the master again
    /// allocates as the writer did.
    pub area: f64,
    /// One per layer of the object, in the object's layer order.
    pub layers: Vec<MasterLayer>,
}

/// The master textures of one layer.
#[derive(Clone, Debug, PartialEq)]
pub struct MasterLayer {
    /// An exact codec: `raw` or `lossless`.
    pub codec: CodecId,
    /// One codestream per sample of the layer, in table order over its dependency mask
    /// (SPEC.md 6.2), each holding the linear values of every plane of the sample's block
    /// ([`LevelLayout::planes`] order, gamma 1, MIP levels as values, not residuals).
    pub samples: Vec<Vec<u8>>,
    /// Screen weights, empty or one codestream per sample (same codec): one value per texel
    /// of the sample's finest texture, how much of the screen the texel's error reaches (the
    /// weights of the writer's screen-error allocation), so that a tool coding the master
    /// again allocates as the writer did.
    pub weights: Vec<Vec<u8>>,
}

/// Flag bit of a master layer: screen weights follow every sample's codestream.
const HAS_WEIGHTS: u8 = 1;

/// Sample indices, one per dimension of the space (0 along the dimensions the layer
/// ignores), of entry `index` of a table over `layer`'s dependency mask.
pub fn sample_point<S>(c: &Container<S>, layer: &Layer<S>, mut index: u64) -> Vec<u32> {
    let mut point = vec![0u32; c.space.dims.len()];
    let dims: Vec<usize> = layer.depends_on.dims().collect();
    for &k in dims.iter().rev() {
        let n = c.space.dims[k].values.len() as u64;
        point[k] = (index % n.max(1)) as u32;
        index /= n.max(1);
    }
    point
}

/// The planes of sample `index` of layer `layer` of `o`: those of the block holding it.
pub fn sample_layout<S>(
    c: &Container<S>,
    o: &Object<S>,
    layer: usize,
    index: u64,
) -> Option<LevelLayout> {
    let l = o.layers.get(layer)?;
    let point = sample_point(c, l, index);
    let block = BlockGrid::new(&c.space, l.depends_on, &o.stagger).locate(&point).block;
    l.blocks.get(block).map(|b| LevelLayout::of(l, b))
}

impl Master {
    /// Codes `textures[layer][sample]` (linear values of the planes of the sample's block,
    /// samples in table order) with the `lossless` codec.
    ///
    /// `weights`, when given, are each sample's screen weights (one value per texel of its
    /// finest texture), in the same order.
    pub fn encode<S>(
        c: &Container<S>,
        object: usize,
        area: f64,
        textures: &[Vec<Vec<f32>>],
        weights: Option<&[Vec<Vec<f32>>]>,
    ) -> Result<Master, Error> {
        let o = c
            .objects
            .get(object)
            .ok_or_else(|| Error::Request(format!("object {object} does not exist")))?;
        if textures.len() != o.layers.len() {
            return Err(Error::Request(format!(
                "object {object} has {} layers, the master {}",
                o.layers.len(),
                textures.len()
            )));
        }
        let codec = pis_codec::codec(CodecId::Lossless)
            .ok_or_else(|| Error::NotSupported("codec 'lossless'".into()))?;
        let mut layers = Vec::with_capacity(textures.len());
        for (li, (l, t)) in o.layers.iter().zip(textures).enumerate() {
            let want = c.space.table_len(l.depends_on);
            if t.len() as u64 != want {
                return Err(Error::Request(format!(
                    "object {object} layer {li}: {} master textures, the layer has {want} samples",
                    t.len()
                )));
            }
            let samples = t
                .iter()
                .enumerate()
                .map(|(s, x)| {
                    let layout = sample_layout(c, o, li, s as u64).ok_or_else(|| {
                        Error::Request(format!(
                            "object {object} layer {li}: no block holds sample {s}"
                        ))
                    })?;
                    codec.encode(&layout.planes(), x, Rate::Default).map_err(|e| {
                        Error::Request(format!("object {object} layer {li} sample {s}: {e}"))
                    })
                })
                .collect::<Result<Vec<_>, Error>>()?;
            let weights = match weights.map(|w| w.get(li)) {
                None => Vec::new(),
                Some(None) => {
                    return Err(Error::Request(format!(
                        "object {object} layer {li}: no screen weights"
                    )))
                }
                Some(Some(w)) => {
                    if w.len() != t.len() {
                        return Err(Error::Request(format!(
                            "object {object} layer {li}: {} screen weight maps for {} samples",
                            w.len(),
                            t.len()
                        )));
                    }
                    w.iter()
                        .enumerate()
                        .map(|(s, x)| {
                            let layout = sample_layout(c, o, li, s as u64).ok_or_else(|| {
                                Error::Request(format!(
                                    "object {object} layer {li}: no block holds sample {s}"
                                ))
                            })?;
                            codec.encode(&[weight_plane(&layout)], x, Rate::Default).map_err(|e| {
                                Error::Request(format!(
                                    "object {object} layer {li} sample {s} screen weights: {e}"
                                ))
                            })
                        })
                        .collect::<Result<Vec<_>, Error>>()?
                }
            };
            layers.push(MasterLayer { codec: CodecId::Lossless, samples, weights });
        }
        Ok(Master { object: object as u32, area, layers })
    }

    /// The linear values of sample `sample` of layer `layer`, decoded and checked (rules
    /// 9105 and 9106). `c` is the container the master belongs to.
    pub fn texture<S>(
        &self,
        c: &Container<S>,
        layer: usize,
        sample: usize,
    ) -> Result<Vec<f32>, Error> {
        let what = format!("master of object {} layer {layer} sample {sample}", self.object);
        let (o, l) = c
            .objects
            .get(self.object as usize)
            .and_then(|o| self.layers.get(layer).map(|l| (o, l)))
            .ok_or_else(|| Error::Request(format!("{what} does not exist")))?;
        let bytes = l
            .samples
            .get(sample)
            .ok_or_else(|| Error::Request(format!("{what} does not exist")))?;
        let layout = sample_layout(c, o, layer, sample as u64)
            .ok_or_else(|| Error::Request(format!("{what}: no block holds it")))?;
        let values = pis_codec::decode(l.codec, &layout.planes(), bytes).map_err(|e| match e {
            CodecError::NotSupported(codec) => {
                Error::NotSupported(format!("codec '{codec}' ({what})"))
            }
            e => Error::Invalid(
                Issue::new(id::master::PLANES_MISMATCH, format!("{what}: {e}"))
                    .in_chunk("MSTR", usize::MAX),
            ),
        })?;
        if let Some(bad) = values.iter().position(|v| !v.is_finite()) {
            return Err(Error::Invalid(
                Issue::new(
                    id::master::VALUE_NOT_FINITE,
                    format!("{what}: value {bad} is {}", values[bad]),
                )
                .in_chunk("MSTR", usize::MAX),
            ));
        }
        Ok(values)
    }

    /// The screen weights of sample `sample` of layer `layer` (one per texel of its finest
    /// texture), decoded and checked (rule 9108); None where the layer carries none.
    pub fn weights<S>(
        &self,
        c: &Container<S>,
        layer: usize,
        sample: usize,
    ) -> Result<Option<Vec<f32>>, Error> {
        let what = format!(
            "master of object {} layer {layer} sample {sample} screen weights",
            self.object
        );
        let (o, l) = c
            .objects
            .get(self.object as usize)
            .and_then(|o| self.layers.get(layer).map(|l| (o, l)))
            .ok_or_else(|| Error::Request(format!("{what} do not exist")))?;
        if l.weights.is_empty() {
            return Ok(None);
        }
        let bytes =
            l.weights.get(sample).ok_or_else(|| Error::Request(format!("{what} do not exist")))?;
        let layout = sample_layout(c, o, layer, sample as u64)
            .ok_or_else(|| Error::Request(format!("{what}: no block holds the sample")))?;
        let values =
            pis_codec::decode(l.codec, &[weight_plane(&layout)], bytes).map_err(|e| match e {
                CodecError::NotSupported(codec) => {
                    Error::NotSupported(format!("codec '{codec}' ({what})"))
                }
                e => Error::Invalid(
                    Issue::new(id::master::SCREEN_WEIGHTS, format!("{what}: {e}"))
                        .in_chunk("MSTR", usize::MAX),
                ),
            })?;
        if let Some(bad) = values.iter().position(|v| !(v.is_finite() && *v >= 0.0)) {
            return Err(Error::Invalid(
                Issue::new(
                    id::master::SCREEN_WEIGHTS,
                    format!("{what}: value {bad} is {}", values[bad]),
                )
                .in_chunk("MSTR", usize::MAX),
            ));
        }
        Ok(Some(values))
    }

    /// Bytes of the master's payload in the file.
    pub fn payload_len(&self) -> u64 {
        24 + self
            .layers
            .iter()
            .map(|l| {
                8 + l.samples.iter().map(|s| 4 + s.len() as u64).sum::<u64>()
                    + l.weights.iter().map(|s| 4 + s.len() as u64).sum::<u64>()
            })
            .sum::<u64>()
    }
}

/// The plane of a sample's screen weights: one value per texel of its finest texture.
fn weight_plane(layout: &LevelLayout) -> PlaneShape {
    PlaneShape::new(layout.width, layout.height, 1)
}

impl Master {}

/// Writes a master's payload.
pub(crate) fn write(s: &mut Sink, m: &Master) {
    s.u32(m.object, "master object index");
    s.u32(0, "master reserved");
    s.raw(&m.area.to_le_bytes(), || format!("master screen area = {}", m.area));
    s.u32(m.layers.len() as u32, "master layer count");
    s.u32(0, "master reserved");
    for (li, l) in m.layers.iter().enumerate() {
        s.u8(l.codec.code() as u8, &format!("master layer {li} codec"));
        s.u8(
            if l.weights.is_empty() { 0 } else { HAS_WEIGHTS },
            &format!("master layer {li} flags"),
        );
        s.zeros(2, &format!("master layer {li} reserved"));
        s.u32(l.samples.len() as u32, &format!("master layer {li} sample count"));
        for (si, b) in l.samples.iter().enumerate() {
            s.u32(b.len() as u32, &format!("master layer {li} sample {si} length"));
            s.raw(b, || format!("master layer {li} sample {si} codestream ({} bytes)", b.len()));
            if let Some(w) = l.weights.get(si) {
                s.u32(w.len() as u32, &format!("master layer {li} sample {si} weights length"));
                s.raw(w, || {
                    format!("master layer {li} sample {si} screen weights ({} bytes)", w.len())
                });
            }
        }
    }
}

/// Parses a master's payload: its structure alone (rule 9100, reserved fields 3006).
pub(crate) fn parse(c: &mut Cursor) -> Result<Master, Issue> {
    let object = c.u32("object index")?;
    c.reserved(4, "reserved")?;
    let area = f64::from_le_bytes(c.u64("screen area")?.to_le_bytes());
    let n = c.u32("layer count")?;
    c.reserved(4, "reserved")?;
    let n = c.expect_records(n as u64, 8, "master layers")?;
    let mut layers = Vec::with_capacity(n);
    for li in 0..n {
        let at = c.offset();
        let code = c.u8("codec id")?;
        let flags = c.u8("flags")?;
        if flags & !HAS_WEIGHTS != 0 {
            c.flag(
                Issue::new(
                    id::master::MALFORMED,
                    format!("layer {li}: unknown flags {flags:#04x}"),
                )
                .in_chunk("MSTR", usize::MAX)
                .at(at + 1),
            )?;
        }
        c.reserved(2, "reserved")?;
        let codec = CodecId::from_code(code as u16).filter(|k| !k.is_lossy()).ok_or_else(|| {
            Issue::new(
                id::master::CODEC_NOT_EXACT,
                format!("layer {li}: codec id {code}; a master uses raw (0) or lossless (1)"),
            )
            .in_chunk("MSTR", usize::MAX)
            .at(at)
        })?;
        let count = c.u32("sample count")?;
        let count = c.expect_records(count as u64, 4, "master samples")?;
        let mut samples = Vec::with_capacity(count);
        let mut weights = Vec::new();
        for _ in 0..count {
            let len = c.u32("sample length")?;
            let len = c.expect_records(len as u64, 1, "codestream bytes")?;
            samples.push(c.bytes(len, "codestream")?.to_vec());
            if flags & HAS_WEIGHTS != 0 {
                let len = c.u32("weights length")?;
                let len = c.expect_records(len as u64, 1, "screen weight bytes")?;
                weights.push(c.bytes(len, "screen weights")?.to_vec());
            }
        }
        layers.push(MasterLayer { codec, samples, weights });
    }
    c.finish()?;
    Ok(Master { object, area, layers })
}

/// Rules 9101–9104 and 9107 for `masters` of container `c`.
pub fn check<S>(c: &Container<S>, masters: &[Master]) -> Vec<Issue> {
    let mut out = Vec::new();
    let e = |id, d: String| Issue::new(id, d).in_chunk("MSTR", usize::MAX);
    let mut seen = vec![false; c.objects.len()];
    for m in masters {
        let oi = m.object as usize;
        match seen.get_mut(oi) {
            Some(s @ false) => *s = true,
            _ => {
                out.push(e(
                    id::master::UNMATCHED_MASTER,
                    format!(
                        "names object {oi}; {} objects, this one missing or already given a master",
                        c.objects.len()
                    ),
                ));
                continue;
            }
        }
        let o = &c.objects[oi];
        if !(m.area.is_finite() && m.area > 0.0) {
            out.push(e(
                id::master::SCREEN_AREA,
                format!("object {oi} '{}': screen area {}", o.name, m.area),
            ));
        }
        if m.layers.len() != o.layers.len() {
            out.push(e(
                id::master::LAYOUT_MISMATCH,
                format!(
                    "object {oi} '{}': {} master layers, the object has {}",
                    o.name,
                    m.layers.len(),
                    o.layers.len()
                ),
            ));
            continue;
        }
        for (li, (ml, l)) in m.layers.iter().zip(&o.layers).enumerate() {
            if ml.codec.is_lossy() {
                out.push(e(
                    id::master::CODEC_NOT_EXACT,
                    format!("object {oi} layer {li}: codec {} is lossy", ml.codec),
                ));
            }
            let want = c.space.table_len(l.depends_on);
            if ml.samples.len() as u64 != want {
                out.push(e(
                    id::master::LAYOUT_MISMATCH,
                    format!(
                        "object {oi} '{}' layer {li}: {} master samples, the layer has {want}",
                        o.name,
                        ml.samples.len()
                    ),
                ));
            }
            if !ml.weights.is_empty() && ml.weights.len() != ml.samples.len() {
                out.push(e(
                    id::master::LAYOUT_MISMATCH,
                    format!(
                        "object {oi} '{}' layer {li}: {} screen weight maps for {} master samples",
                        o.name,
                        ml.weights.len(),
                        ml.samples.len()
                    ),
                ));
            }
        }
    }
    if !masters.is_empty() {
        if let Some(oi) = seen.iter().position(|&s| !s) {
            out.push(e(
                id::master::NOT_EVERY_OBJECT,
                format!("object {oi} '{}' has no master while others have one", c.objects[oi].name),
            ));
        }
    }
    out
}

/// Reads, checksums, parses and checks every `MSTR` chunk of a file whose container parsed.
/// With `decode`, also decodes every master texture (rules 9105, 9106).
pub(crate) fn load<S>(
    src: &dyn Source,
    entries: &[ChunkEntry],
    c: &Container<S>,
    decode: bool,
    issues: &mut Vec<Issue>,
) -> Vec<Master> {
    let mut masters = Vec::new();
    for (i, e) in entries.iter().enumerate().filter(|(_, e)| e.fourcc == chunk::MSTR) {
        // A chunk past the end of the file is reported by the table (rule 3002).
        if e.offset.checked_add(e.length).is_none_or(|end| end > src.len()) {
            continue;
        }
        let mut bytes = vec![0; e.length as usize];
        if let Err(err) = src.read_at(e.offset, &mut bytes) {
            issues.push(
                Issue::new(id::io::FILE_UNREADABLE, err.to_string())
                    .in_chunk("MSTR", i)
                    .at(e.offset),
            );
            continue;
        }
        let crc = crc32fast::hash(&bytes);
        if crc != e.crc {
            issues.push(
                Issue::new(
                    id::chunk::CHECKSUM_MISMATCH,
                    format!("stored {:#010x}, computed {crc:#010x}", e.crc),
                )
                .in_chunk("MSTR", i)
                .at(e.offset),
            );
            continue;
        }
        let mut cursor =
            Cursor::new(&bytes, e.offset, id::master::MALFORMED, ("MSTR", i)).collecting();
        let parsed = parse(&mut cursor);
        issues.extend(cursor.take_flagged());
        match parsed {
            Ok(m) => masters.push((i, m)),
            Err(issue) => issues.push(issue),
        }
    }
    let all: Vec<Master> = masters.iter().map(|(_, m)| m.clone()).collect();
    let before = issues.len();
    for mut issue in check(c, &all) {
        // Name the chunk where the issue's object identifies one.
        if let Some((_, idx)) = &mut issue.chunk {
            if let [(i, _)] = masters.as_slice() {
                *idx = *i;
            }
        }
        issues.push(issue);
    }
    if decode && issues.len() == before {
        for (i, m) in &masters {
            for (li, l) in m.layers.iter().enumerate() {
                for s in 0..l.samples.len() {
                    if let Err(Error::Invalid(issue)) = m.texture(c, li, s) {
                        issues.push(Issue { chunk: Some(("MSTR".into(), *i)), ..issue });
                    }
                    if let Err(Error::Invalid(issue)) = m.weights(c, li, s) {
                        issues.push(Issue { chunk: Some(("MSTR".into(), *i)), ..issue });
                    }
                }
            }
        }
    }
    masters.into_iter().map(|(_, m)| m).collect()
}
