//! Little-endian encoding: a bounds-checked payload cursor for reading and a byte sink that
//! can record a label per field (for the annotated hex dump in format-spec/examples/).

use crate::issue::id;
use crate::Issue;

/// Reads one chunk payload. Every read is checked against the payload's end; failures name
/// the field, the chunk and the absolute file offset.
pub struct Cursor<'a> {
    data: &'a [u8],
    pos: usize,
    /// Absolute file offset of `data[0]`.
    base: u64,
    /// Rule id for "payload is malformed" of this chunk type.
    malformed: u16,
    chunk: (&'a str, usize),
    /// Broken rules that leave the payload readable, when the cursor collects them
    /// ([`Cursor::collecting`]); `None`: the first one stops the parse.
    flagged: Option<Vec<Issue>>,
}

impl<'a> Cursor<'a> {
    pub fn new(data: &'a [u8], base: u64, malformed: u16, chunk: (&'a str, usize)) -> Self {
        Cursor { data, pos: 0, base, malformed, chunk, flagged: None }
    }

    /// Keeps parsing past broken rules that leave the payload's structure readable (a
    /// reserved field that is not 0, an undefined flag bit): they are collected, for
    /// [`Cursor::take_flagged`], so that a validator reports every one.
    pub fn collecting(mut self) -> Self {
        self.flagged = Some(Vec::new());
        self
    }

    /// Reports a broken rule after which the payload can still be parsed: collected when the
    /// cursor collects, else returned as the parse's error.
    pub fn flag(&mut self, issue: Issue) -> Result<(), Issue> {
        match &mut self.flagged {
            Some(v) => {
                v.push(issue);
                Ok(())
            }
            None => Err(issue),
        }
    }

    /// The collected broken rules, in payload order.
    pub fn take_flagged(&mut self) -> Vec<Issue> {
        self.flagged.take().unwrap_or_default()
    }

    /// Absolute file offset of the next byte.
    pub fn offset(&self) -> u64 {
        self.base + self.pos as u64
    }

    pub fn remaining(&self) -> usize {
        self.data.len() - self.pos
    }

    /// An issue located at the cursor.
    pub fn issue(&self, id: u16, detail: impl Into<String>) -> Issue {
        Issue::new(id, detail).in_chunk(self.chunk.0, self.chunk.1).at(self.offset())
    }

    fn take(&mut self, n: usize, what: &str) -> Result<&'a [u8], Issue> {
        if self.remaining() < n {
            return Err(self.issue(
                self.malformed,
                format!(
                    "payload ends after {} bytes; {what} needs {n} more",
                    self.pos + self.remaining()
                ),
            ));
        }
        let s = &self.data[self.pos..self.pos + n];
        self.pos += n;
        Ok(s)
    }

    pub fn u8(&mut self, what: &str) -> Result<u8, Issue> {
        Ok(self.take(1, what)?[0])
    }

    pub fn u16(&mut self, what: &str) -> Result<u16, Issue> {
        let b = self.take(2, what)?;
        Ok(u16::from_le_bytes([b[0], b[1]]))
    }

    pub fn u32(&mut self, what: &str) -> Result<u32, Issue> {
        let b = self.take(4, what)?;
        Ok(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    }

    pub fn u64(&mut self, what: &str) -> Result<u64, Issue> {
        let b = self.take(8, what)?;
        Ok(u64::from_le_bytes(b.try_into().expect("8 bytes")))
    }

    /// `n` raw bytes.
    pub fn bytes(&mut self, n: usize, what: &str) -> Result<&'a [u8], Issue> {
        self.take(n, what)
    }

    pub fn f32(&mut self, what: &str) -> Result<f32, Issue> {
        Ok(f32::from_bits(self.u32(what)?))
    }

    pub fn f32s<const N: usize>(&mut self, what: &str) -> Result<[f32; N], Issue> {
        let mut out = [0.0; N];
        for v in &mut out {
            *v = self.f32(what)?;
        }
        Ok(out)
    }

    /// A reserved field: must be zero (rule 3006, see [`Cursor::flag`]).
    pub fn reserved(&mut self, bytes: usize, what: &str) -> Result<(), Issue> {
        let at = self.offset();
        let b = self.take(bytes, what)?;
        if b.iter().any(|&x| x != 0) {
            let issue = Issue::new(
                id::chunk::RESERVED_NOT_ZERO,
                format!("{what} must be 0, found {b:02x?}"),
            )
            .in_chunk(self.chunk.0, self.chunk.1)
            .at(at);
            return self.flag(issue);
        }
        Ok(())
    }

    /// A string: u32 byte length, then UTF-8 bytes. `id` is the rule for bad UTF-8.
    pub fn string(&mut self, what: &str, id: u16) -> Result<String, Issue> {
        let n = self.u32(what)? as usize;
        let at = self.offset();
        let b = self.take(n, what)?;
        String::from_utf8(b.to_vec()).map_err(|_| {
            Issue::new(id, format!("{what} is not UTF-8"))
                .in_chunk(self.chunk.0, self.chunk.1)
                .at(at)
        })
    }

    /// Checks that `count` records of at least `size` bytes each can still follow, before
    /// anything is allocated for them.
    pub fn expect_records(&self, count: u64, size: u64, what: &str) -> Result<usize, Issue> {
        match count.checked_mul(size) {
            Some(n) if n <= self.remaining() as u64 => Ok(count as usize),
            _ => Err(self.issue(
                self.malformed,
                format!(
                    "{count} {what} of {size} bytes do not fit in the {} bytes left",
                    self.remaining()
                ),
            )),
        }
    }

    /// The payload must end here.
    pub fn finish(&self) -> Result<(), Issue> {
        if self.remaining() != 0 {
            return Err(self.issue(
                self.malformed,
                format!("{} bytes after the last field", self.remaining()),
            ));
        }
        Ok(())
    }
}

/// A labelled span of written bytes.
#[derive(Clone, Debug)]
pub struct Span {
    pub start: usize,
    pub len: usize,
    pub label: String,
}

/// Writes little-endian values; optionally records what each byte range is.
#[derive(Default)]
pub struct Sink {
    pub bytes: Vec<u8>,
    pub spans: Option<Vec<Span>>,
}

impl Sink {
    pub fn new(labelled: bool) -> Self {
        Sink { bytes: Vec::new(), spans: labelled.then(Vec::new) }
    }

    pub fn len(&self) -> usize {
        self.bytes.len()
    }

    pub fn raw(&mut self, b: &[u8], label: impl FnOnce() -> String) {
        if let Some(spans) = &mut self.spans {
            if !b.is_empty() {
                spans.push(Span { start: self.bytes.len(), len: b.len(), label: label() });
            }
        }
        self.bytes.extend_from_slice(b);
    }

    pub fn u8(&mut self, v: u8, label: &str) {
        self.raw(&[v], || format!("{label} = {v}"));
    }

    pub fn u16(&mut self, v: u16, label: &str) {
        self.raw(&v.to_le_bytes(), || format!("{label} = {v}"));
    }

    pub fn u32(&mut self, v: u32, label: &str) {
        self.raw(&v.to_le_bytes(), || format!("{label} = {v}"));
    }

    pub fn u32_hex(&mut self, v: u32, label: &str) {
        self.raw(&v.to_le_bytes(), || format!("{label} = {v:#010x}"));
    }

    pub fn u64(&mut self, v: u64, label: &str) {
        self.raw(&v.to_le_bytes(), || format!("{label} = {v}"));
    }

    pub fn f32s(&mut self, v: &[f32], label: &str) {
        let b: Vec<u8> = v.iter().flat_map(|x| x.to_le_bytes()).collect();
        self.raw(&b, || match v {
            [one] => format!("{label} = {one:?}"),
            _ => format!("{label} = {v:?}"),
        });
    }

    pub fn zeros(&mut self, n: usize, label: &str) {
        self.raw(&vec![0; n], || label.to_string());
    }

    pub fn string(&mut self, s: &str, label: &str) {
        self.u32(s.len() as u32, &format!("{label} length"));
        self.raw(s.as_bytes(), || format!("{label} = {s:?}"));
    }

    /// Overwrites 4 bytes already written (used to patch checksums).
    pub fn patch_u32(&mut self, at: usize, v: u32) {
        self.bytes[at..at + 4].copy_from_slice(&v.to_le_bytes());
    }

    pub fn patch_u64(&mut self, at: usize, v: u64) {
        self.bytes[at..at + 8].copy_from_slice(&v.to_le_bytes());
    }

    /// Appends another sink's bytes (and labels, shifted).
    pub fn append(&mut self, other: Sink) {
        let base = self.bytes.len();
        if let (Some(mine), Some(theirs)) = (&mut self.spans, other.spans) {
            mine.extend(theirs.into_iter().map(|s| Span { start: s.start + base, ..s }));
        }
        self.bytes.extend_from_slice(&other.bytes);
    }
}
