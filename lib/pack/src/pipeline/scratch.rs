//! The pack's scratch file: where a pack that streams (a set larger than its memory budget,
//! [`super::memory`]) keeps what it would otherwise hold, written once and read back where
//! needed. Records are appended and read by their [`Span`]; the file lives beside the output
//! as `.NAME.scratch<pid>` and is removed when the pack ends, whether it succeeds or fails.
//!
//! Records are written by [`Writer`] and read by [`Reader`], little-endian, every length
//! checked against what is left of the record.

use std::fs::File;
use std::io::{Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use anyhow::{anyhow, bail, Context, Result};
use pis_compile::{RenderMatrix, TextureLayout};

/// Where a record lies in the scratch file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Span {
    offset: u64,
    len: u64,
}

/// An append-only scratch file, removed on drop.
pub struct Scratch {
    path: PathBuf,
    file: Mutex<(File, u64)>,
}

impl Scratch {
    /// A new scratch file for the pack writing `output`, in the output's folder. The
    /// scratch files of earlier packs of `output` whose processes are gone (killed before
    /// they could remove their own) are removed first.
    pub fn beside(output: &Path) -> Result<Scratch> {
        let dir = output.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
        let name =
            output.file_name().map_or_else(|| "pack".into(), |n| n.to_string_lossy().into_owned());
        remove_stale(dir, &name);
        Scratch::create(&dir.join(format!(".{name}.scratch{}", std::process::id())))
    }

    /// A new scratch file at `path` (replaced if it exists).
    pub fn create(path: &Path) -> Result<Scratch> {
        let file = std::fs::OpenOptions::new()
            .read(true)
            .write(true)
            .create(true)
            .truncate(true)
            .open(path)
            .with_context(|| format!("creating the scratch file {}", path.display()))?;
        Ok(Scratch { path: path.to_path_buf(), file: Mutex::new((file, 0)) })
    }

    /// Appends a record.
    pub fn put(&self, bytes: &[u8]) -> Result<Span> {
        let mut g = self.file.lock().map_err(|_| anyhow!("the scratch file's lock is poisoned"))?;
        let offset = g.1;
        g.0.seek(SeekFrom::Start(offset))?;
        g.0.write_all(bytes)
            .with_context(|| format!("writing the scratch file {}", self.path.display()))?;
        g.1 += bytes.len() as u64;
        Ok(Span { offset, len: bytes.len() as u64 })
    }

    /// Reads a record back.
    pub fn get(&self, span: Span) -> Result<Vec<u8>> {
        let mut g = self.file.lock().map_err(|_| anyhow!("the scratch file's lock is poisoned"))?;
        if span.offset + span.len > g.1 {
            bail!(
                "scratch record {span:?} lies past the end of {} ({} bytes)",
                self.path.display(),
                g.1
            );
        }
        let mut out = vec![0u8; span.len as usize];
        g.0.seek(SeekFrom::Start(span.offset))?;
        g.0.read_exact(&mut out)
            .with_context(|| format!("reading the scratch file {}", self.path.display()))?;
        Ok(out)
    }

    /// Bytes written so far.
    pub fn len(&self) -> u64 {
        self.file.lock().map_or(0, |g| g.1)
    }

    /// Nothing written yet.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    pub fn path(&self) -> &Path {
        &self.path
    }
}

/// Removes the scratch files `.NAME.scratch<pid>` in `dir` of processes that are not
/// running (where the system tells: Linux's /proc); returns how many were removed.
fn remove_stale(dir: &Path, name: &str) -> usize {
    let prefix = format!(".{name}.scratch");
    let Ok(entries) = std::fs::read_dir(dir) else { return 0 };
    let mut removed = 0;
    for e in entries.filter_map(Result::ok) {
        let file = e.file_name().to_string_lossy().into_owned();
        let Some(pid) = file.strip_prefix(&prefix).and_then(|p| p.parse::<u32>().ok()) else {
            continue;
        };
        if pid != std::process::id() && !running(pid) && std::fs::remove_file(e.path()).is_ok() {
            removed += 1;
        }
    }
    removed
}

/// Whether process `pid` is running; true where the system cannot tell.
fn running(pid: u32) -> bool {
    let proc = Path::new("/proc");
    !proc.join("self").exists() || proc.join(pid.to_string()).exists()
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.path);
    }
}

/// A record being written.
#[derive(Default)]
pub struct Writer(pub Vec<u8>);

impl Writer {
    pub fn u32(&mut self, v: u32) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }

    pub fn u64(&mut self, v: u64) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }

    pub fn str(&mut self, s: &str) {
        self.u64(s.len() as u64);
        self.0.extend_from_slice(s.as_bytes());
    }

    pub fn u32s(&mut self, v: &[u32]) {
        self.u64(v.len() as u64);
        v.iter().for_each(|x| self.0.extend_from_slice(&x.to_le_bytes()));
    }

    pub fn f32s(&mut self, v: &[f32]) {
        self.u64(v.len() as u64);
        v.iter().for_each(|x| self.0.extend_from_slice(&x.to_bits().to_le_bytes()));
    }

    pub fn matrix(&mut self, a: &RenderMatrix) {
        self.u32(a.width);
        self.u32(a.height);
        for v in [a.layout.width, a.layout.height, a.layout.levels, a.layout.faces] {
            self.u32(v);
        }
        self.u32s(&a.pixels);
        self.f32s(&a.coverage);
        self.u32s(&a.row_start);
        self.u32s(&a.cols);
        self.f32s(&a.vals);
    }
}

/// A record being read: every count is checked against the bytes left before anything is
/// allocated by it.
pub struct Reader<'a>(&'a [u8]);

impl<'a> Reader<'a> {
    pub fn new(bytes: &'a [u8]) -> Self {
        Reader(bytes)
    }

    fn take(&mut self, n: usize) -> Result<&'a [u8]> {
        if n > self.0.len() {
            bail!("a scratch record ends early ({n} bytes wanted, {} left)", self.0.len());
        }
        let (a, b) = self.0.split_at(n);
        self.0 = b;
        Ok(a)
    }

    pub fn u32(&mut self) -> Result<u32> {
        Ok(u32::from_le_bytes(self.take(4)?.try_into()?))
    }

    pub fn u64(&mut self) -> Result<u64> {
        Ok(u64::from_le_bytes(self.take(8)?.try_into()?))
    }

    fn count(&mut self, size: usize) -> Result<usize> {
        let n = self.u64()?;
        if n.checked_mul(size as u64).is_none_or(|b| b > self.0.len() as u64) {
            bail!("a scratch record counts {n} values, more than it holds");
        }
        Ok(n as usize)
    }

    pub fn str(&mut self) -> Result<String> {
        let n = self.count(1)?;
        Ok(String::from_utf8(self.take(n)?.to_vec())?)
    }

    pub fn u32s(&mut self) -> Result<Vec<u32>> {
        let n = self.count(4)?;
        Ok(self
            .take(n * 4)?
            .chunks_exact(4)
            .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect())
    }

    pub fn f32s(&mut self) -> Result<Vec<f32>> {
        let n = self.count(4)?;
        Ok(self
            .take(n * 4)?
            .chunks_exact(4)
            .map(|c| f32::from_bits(u32::from_le_bytes([c[0], c[1], c[2], c[3]])))
            .collect())
    }

    pub fn matrix(&mut self) -> Result<RenderMatrix> {
        let (width, height) = (self.u32()?, self.u32()?);
        let layout = TextureLayout {
            width: self.u32()?,
            height: self.u32()?,
            levels: self.u32()?,
            faces: self.u32()?,
        };
        let (pixels, coverage, row_start, cols, vals) =
            (self.u32s()?, self.f32s()?, self.u32s()?, self.u32s()?, self.f32s()?);
        if coverage.len() != pixels.len()
            || row_start.len() != pixels.len() + 1
            || cols.len() != vals.len()
            || row_start.last().is_some_and(|&e| e as usize != cols.len())
        {
            bail!("a scratch render matrix is inconsistent");
        }
        Ok(RenderMatrix { width, height, layout, pixels, coverage, row_start, cols, vals })
    }

    /// Whether every byte was read.
    pub fn done(&self) -> Result<()> {
        if !self.0.is_empty() {
            bail!("a scratch record has {} bytes left over", self.0.len());
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn records_come_back_as_written_and_the_file_goes_with_the_scratch() {
        let dir = tempfile::tempdir().unwrap();
        let s = Scratch::beside(&dir.path().join("out.pis")).unwrap();
        let path = s.path().to_path_buf();
        assert!(
            path.is_file()
                && path.file_name().unwrap().to_string_lossy().starts_with(".out.pis.scratch")
        );
        let a = RenderMatrix {
            width: 4,
            height: 3,
            layout: TextureLayout::full(2, 2),
            pixels: vec![1, 5],
            coverage: vec![1.0, 0.5],
            row_start: vec![0, 2, 3],
            cols: vec![0, 3, 4],
            vals: vec![0.25, 0.75, -0.0],
        };
        let mut w = Writer::default();
        w.str("object.vase");
        w.matrix(&a);
        w.f32s(&[f32::NAN, 1.5]);
        let first = s.put(&w.0).unwrap();
        let second = s.put(b"xyz").unwrap();
        assert_eq!(s.get(second).unwrap(), b"xyz");
        let bytes = s.get(first).unwrap();
        let mut r = Reader::new(&bytes);
        assert_eq!(r.str().unwrap(), "object.vase");
        let b = r.matrix().unwrap();
        assert_eq!(
            (b.pixels, b.cols, b.row_start),
            (a.pixels.clone(), a.cols.clone(), a.row_start.clone())
        );
        assert!(
            b.vals.iter().zip(&a.vals).all(|(x, y)| x.to_bits() == y.to_bits()),
            "values bit for bit, -0 included"
        );
        let v = r.f32s().unwrap();
        assert!(v[0].is_nan() && v[1] == 1.5);
        r.done().unwrap();
        // A damaged record is an error, not an allocation sized by it.
        let mut bad = bytes.clone();
        bad[..8].copy_from_slice(&u64::MAX.to_le_bytes());
        assert!(Reader::new(&bad).str().is_err());
        let mut short = Reader::new(&bytes[..bytes.len() - 1]);
        short.str().unwrap();
        short.matrix().unwrap();
        assert!(short.f32s().is_err(), "a record cut short is an error");
        drop(s);
        assert!(!path.exists(), "the scratch file is removed with the scratch");
    }

    #[test]
    fn the_scratch_files_of_packs_that_are_gone_are_removed() {
        let dir = tempfile::tempdir().unwrap();
        // pid_max is at most 2^22 on Linux: this process cannot be running.
        let gone = dir.path().join(".out.pis.scratch4294967");
        let other = dir.path().join(".other.pis.scratch4294967");
        let kept = dir.path().join(".out.pis.scratch-notes");
        for p in [&gone, &other, &kept] {
            std::fs::write(p, b"x").unwrap();
        }
        let s = Scratch::beside(&dir.path().join("out.pis")).unwrap();
        if Path::new("/proc/self").exists() {
            assert!(!gone.exists(), "a dead pack's scratch file is removed");
        }
        assert!(
            other.exists() && kept.exists(),
            "other outputs' files and other names are left alone"
        );
        assert!(s.path().exists(), "this pack's own file is there");
        // A pack that is running keeps its file: this process's is not removed by another.
        assert_eq!(remove_stale(dir.path(), "out.pis"), 0);
        assert!(s.path().exists());
    }
}
