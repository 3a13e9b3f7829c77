//! Outgoing-ray records of refractive lens objects (thesis 6.3.1) and their little-endian
//! side file (`*.rays.bin`, layout in format-spec/RAYSET.md).

use crate::error::TraceError;
use pis_scene::lens_tree::MAX_TERMS;
use std::path::Path;

/// File magic of a ray-record side file.
pub const RAYS_MAGIC: [u8; 8] = *b"PISRAYS\0";
/// Version of the side-file layout.
pub const RAYS_VERSION: u32 = 1;
/// Bytes of one record before its hits.
pub const RECORD_HEADER_BYTES: usize = 56;
/// Bytes of one hit.
pub const HIT_BYTES: usize = 32;

/// A front-facing hit along a continued outgoing ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RecordHit {
    /// Distance from the exit origin along the exit direction.
    pub t: f32,
    /// World position.
    pub position: [f32; 3],
    /// Index of the object hit (set.json `objects`).
    pub object: u32,
    /// Linear RGB radiance leaving the hit towards the exit origin.
    pub colour: [f32; 3],
}

/// One incoming camera ray of a lens object and the outgoing ray of one term of its model.
#[derive(Clone, Debug, PartialEq)]
pub struct RayRecord {
    /// Index of the lens object (set.json `objects`).
    pub object: u32,
    /// 0 = reflection-first term, 1 = refraction-first term; the tree model's 2 and 3: the
    /// refraction-first terms with one and two internal reflections.
    pub term: u8,
    /// Continuous image position of the incoming camera ray (pixels, origin top-left).
    pub pixel: [f32; 2],
    /// Where the path leaves the lens object (world).
    pub exit_origin: [f32; 3],
    /// Unit direction of the outgoing ray (world).
    pub exit_direction: [f32; 3],
    /// F·G along the path.
    pub modulation: [f32; 3],
    /// Front-facing hits along the continued outgoing ray, nearest first.
    pub hits: Vec<RecordHit>,
}

fn put_f32s(out: &mut Vec<u8>, v: &[f32]) {
    for x in v {
        out.extend_from_slice(&x.to_le_bytes());
    }
}

/// Encodes records into the side-file layout.
pub fn encode_records(records: &[RayRecord]) -> Vec<u8> {
    let hits: usize = records.iter().map(|r| r.hits.len()).sum();
    let mut out = Vec::with_capacity(16 + records.len() * RECORD_HEADER_BYTES + hits * HIT_BYTES);
    out.extend_from_slice(&RAYS_MAGIC);
    out.extend_from_slice(&RAYS_VERSION.to_le_bytes());
    out.extend_from_slice(&(records.len() as u32).to_le_bytes());
    for r in records {
        out.extend_from_slice(&r.object.to_le_bytes());
        out.push(r.term);
        out.push(0);
        out.extend_from_slice(&(r.hits.len().min(u16::MAX as usize) as u16).to_le_bytes());
        put_f32s(&mut out, &r.pixel);
        put_f32s(&mut out, &r.exit_origin);
        put_f32s(&mut out, &r.exit_direction);
        put_f32s(&mut out, &r.modulation);
        out.extend_from_slice(&[0u8; 4]);
        for h in r.hits.iter().take(u16::MAX as usize) {
            out.extend_from_slice(&h.t.to_le_bytes());
            put_f32s(&mut out, &h.position);
            out.extend_from_slice(&h.object.to_le_bytes());
            put_f32s(&mut out, &h.colour);
        }
    }
    out
}

struct Cursor<'a> {
    bytes: &'a [u8],
    at: usize,
    path: &'a Path,
}

impl Cursor<'_> {
    fn take(&mut self, n: usize) -> Result<&[u8], TraceError> {
        let end = self.at.checked_add(n).filter(|&e| e <= self.bytes.len()).ok_or_else(|| {
            TraceError::InvalidSet {
                path: self.path.to_path_buf(),
                message: format!(
                    "truncated ray records: need {n} bytes at offset {}, file has {}",
                    self.at,
                    self.bytes.len()
                ),
            }
        })?;
        let s = &self.bytes[self.at..end];
        self.at = end;
        Ok(s)
    }
    fn u32(&mut self) -> Result<u32, TraceError> {
        let b = self.take(4)?;
        Ok(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    }
    fn f32(&mut self) -> Result<f32, TraceError> {
        Ok(f32::from_bits(self.u32()?))
    }
    fn f32s<const N: usize>(&mut self) -> Result<[f32; N], TraceError> {
        let mut v = [0.0; N];
        for x in &mut v {
            *x = self.f32()?;
        }
        Ok(v)
    }
}

/// Decodes a side file; `path` names the file in errors.
pub fn decode_records(bytes: &[u8], path: &Path) -> Result<Vec<RayRecord>, TraceError> {
    let mut c = Cursor { bytes, at: 0, path };
    let bad = |message: String| TraceError::InvalidSet { path: path.to_path_buf(), message };
    if c.take(8)? != RAYS_MAGIC {
        return Err(bad("not a ray-record file (magic is not \"PISRAYS\\0\")".into()));
    }
    let version = c.u32()?;
    if version != RAYS_VERSION {
        return Err(bad(format!(
            "ray-record version {version} is not supported (expected {RAYS_VERSION})"
        )));
    }
    let count = c.u32()? as usize;
    if count > bytes.len() / RECORD_HEADER_BYTES {
        return Err(bad(format!(
            "record count {count} exceeds what {} bytes can hold",
            bytes.len()
        )));
    }
    let mut records = Vec::with_capacity(count);
    for _ in 0..count {
        let object = c.u32()?;
        let head = c.take(4)?;
        let (term, n_hits) = (head[0], u16::from_le_bytes([head[2], head[3]]) as usize);
        if term as usize >= MAX_TERMS {
            return Err(bad(format!(
                "record {} has term {term} at offset {}; expected 0 to 3",
                records.len(),
                c.at - 4
            )));
        }
        let pixel = c.f32s::<2>()?;
        let exit_origin = c.f32s::<3>()?;
        let exit_direction = c.f32s::<3>()?;
        let modulation = c.f32s::<3>()?;
        c.take(4)?;
        let mut hits = Vec::with_capacity(n_hits);
        for _ in 0..n_hits {
            let t = c.f32()?;
            let position = c.f32s::<3>()?;
            let object = c.u32()?;
            let colour = c.f32s::<3>()?;
            hits.push(RecordHit { t, position, object, colour });
        }
        records.push(RayRecord {
            object,
            term,
            pixel,
            exit_origin,
            exit_direction,
            modulation,
            hits,
        });
    }
    if c.at != bytes.len() {
        return Err(bad(format!("{} trailing bytes after {count} records", bytes.len() - c.at)));
    }
    Ok(records)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn records_round_trip_and_truncation_is_an_error() {
        let r = RayRecord {
            object: 3,
            term: 1,
            pixel: [1.5, 2.25],
            exit_origin: [0.0, 1.0, 2.0],
            exit_direction: [0.0, 0.0, -1.0],
            modulation: [0.9, 0.8, 0.7],
            hits: vec![RecordHit {
                t: 2.0,
                position: [0.0, 1.0, 0.0],
                object: 1,
                colour: [0.5, 0.25, 0.125],
            }],
        };
        let bytes = encode_records(&[r.clone(), RayRecord { hits: vec![], ..r.clone() }]);
        assert_eq!(bytes.len(), 16 + 2 * RECORD_HEADER_BYTES + HIT_BYTES);
        let back = decode_records(&bytes, Path::new("x")).unwrap();
        assert_eq!(back[0], r);
        for cut in [3, 20, bytes.len() - 1] {
            assert!(decode_records(&bytes[..cut], Path::new("x")).is_err());
        }
    }
}
