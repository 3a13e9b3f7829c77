//! Solved textures kept by a digest of what they were solved from: the render matrices, the
//! ray-traced pixels, the warm start and the solver's settings. A pack split over processes
//! (`pis-pack solve --shard I/N`, then `pis-pack merge`) meets here: each solve shard runs
//! the pack's inference for its objects and writes the solutions it computed to a fragment
//! file; the merge runs the whole pack again, and every solve whose digest a fragment holds
//! is read instead of solved. The solver is deterministic, so the merged file is the one a
//! single process writes, byte for byte; a solve no fragment holds (fragments of other
//! settings, or a missing shard) is solved by the merge itself.
//!
//! A fragment file (little-endian): the magic `PISSOLVD`, a version (u32, 1), the number of
//! solutions (u32), then per solution its digest (16 bytes), its texture layout (width,
//! height, levels, faces: u32), the form (u8: 0 A, 1 AᵀA), n_s and n_t (u64), CG
//! iterations (u32), the residual (RMS and relative, f64), undefined texels (u64),
//! converged (u8), the number of values (u64) and the values (f32).

use std::collections::HashMap;
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};

use anyhow::{anyhow, bail, Context, Result};
use pis_compile::solve::{solve, solve_view_source, Solution, SolveSettings, View};
use pis_compile::{CompileError, Form, RenderMatrix, TextureLayout, ViewSource};

const MAGIC: &[u8; 8] = b"PISSOLVD";
const VERSION: u32 = 1;
/// The extension of a fragment file.
pub const FRAGMENT_EXTENSION: &str = "solved";

/// 128 bits naming a solve's inputs.
type Digest = [u8; 16];

/// A 128-bit digest of a stream of 64-bit words: two multiply–rotate lanes with a final
/// avalanche, the same on every platform and build.
struct Hasher {
    lanes: [u64; 2],
    words: u64,
}

impl Hasher {
    fn new() -> Hasher {
        Hasher { lanes: [0x243F_6A88_85A3_08D3, 0x1319_8A2E_0370_7344], words: 0 }
    }

    fn word(&mut self, w: u64) {
        self.lanes[0] = (self.lanes[0] ^ w).wrapping_mul(0x9E37_79B9_7F4A_7C15).rotate_left(31);
        self.lanes[1] =
            (self.lanes[1] ^ w.rotate_left(23)).wrapping_mul(0xC2B2_AE3D_27D4_EB4F).rotate_left(29);
        self.words += 1;
    }

    fn u32s(&mut self, values: impl IntoIterator<Item = u32>) {
        let mut n = 0u64;
        let mut it = values.into_iter();
        loop {
            match (it.next(), it.next()) {
                (Some(a), Some(b)) => self.word(a as u64 | (b as u64) << 32),
                (Some(a), None) => self.word(a as u64 | 1 << 63),
                _ => break,
            }
            n += 1;
        }
        self.word(n);
    }

    fn f32s(&mut self, values: &[f32]) {
        self.u32s(values.iter().map(|v| v.to_bits()));
    }

    fn bytes(&mut self, b: &[u8]) {
        self.u32s(b.iter().map(|&x| x as u32));
    }

    fn finish(mut self) -> Digest {
        let mix = |mut z: u64| {
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^ (z >> 31)
        };
        let n = self.words;
        self.word(n);
        let (a, b) = (
            mix(self.lanes[0] ^ self.lanes[1].rotate_left(17)),
            mix(self.lanes[1] ^ self.lanes[0].rotate_left(41)),
        );
        let mut d = [0u8; 16];
        d[..8].copy_from_slice(&a.to_le_bytes());
        d[8..].copy_from_slice(&b.to_le_bytes());
        d
    }
}

fn matrix_words(h: &mut Hasher, a: &RenderMatrix) {
    let l = a.layout;
    h.u32s([a.width, a.height, l.width, l.height, l.levels, l.faces]);
    h.u32s(a.pixels.iter().copied());
    h.f32s(&a.coverage);
    h.u32s(a.row_start.iter().copied());
    h.u32s(a.cols.iter().copied());
    h.f32s(&a.vals);
}

/// The digest of a solve: `stacked` (view-independent) or one view, its views, start and
/// settings.
fn digest<S: ViewSource + ?Sized>(
    stacked: bool,
    views: &S,
    initial: Option<&[f32]>,
    settings: &SolveSettings,
) -> Result<Digest, CompileError> {
    let mut h = Hasher::new();
    h.word(stacked as u64);
    h.word(views.count() as u64);
    for k in 0..views.count() {
        views.visit(k, &mut |v| {
            matrix_words(&mut h, v.a);
            h.f32s(v.b);
            Ok(())
        })?;
    }
    match initial {
        Some(x) => {
            h.word(1);
            h.f32s(x);
        }
        None => h.word(0),
    }
    // Every setting, by its exact printed form (floats print so as to read back exactly).
    h.bytes(format!("{settings:?}").as_bytes());
    Ok(h.finish())
}

/// A store of solutions, by digest, and what it was asked.
#[derive(Default)]
pub struct Solutions {
    map: Mutex<HashMap<Digest, Solution>>,
    /// Keep the solutions this process computes (a solve shard).
    record: bool,
    read: AtomicUsize,
    solved: AtomicUsize,
}

impl Solutions {
    /// An empty store that keeps what is solved through it (for a solve shard's fragment).
    pub fn recording() -> Solutions {
        Solutions { record: true, ..Default::default() }
    }

    /// Solves found in the store, and solves computed.
    pub fn counts(&self) -> (usize, usize) {
        (self.read.load(Ordering::Relaxed), self.solved.load(Ordering::Relaxed))
    }

    /// Solutions held.
    pub fn len(&self) -> usize {
        self.map.lock().expect("the solutions lock").len()
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The solution of `views` from the store, or `solve`d.
    fn through<S: ViewSource + ?Sized>(
        &self,
        stacked: bool,
        views: &S,
        initial: Option<&[f32]>,
        settings: &SolveSettings,
        solve: impl FnOnce() -> Result<Solution, CompileError>,
    ) -> Result<Solution, CompileError> {
        let d = digest(stacked, views, initial, settings)?;
        // A solution read is taken out: each is read once, and the store does not double
        // the textures the pack holds.
        let found = {
            let mut map = self.map.lock().expect("the solutions lock");
            if self.record {
                map.get(&d).cloned()
            } else {
                map.remove(&d)
            }
        };
        if let Some(s) = found {
            self.read.fetch_add(1, Ordering::Relaxed);
            return Ok(s);
        }
        let s = solve()?;
        self.solved.fetch_add(1, Ordering::Relaxed);
        if self.record {
            // What a reader gets back: the solution without its per-channel history and timing.
            let kept = Solution { channels: Vec::new(), solve_ms: 0.0, ..s.clone() };
            self.map.lock().expect("the solutions lock").insert(d, kept);
        }
        Ok(s)
    }

    /// Reads the fragment file `path` into the store; returns the solutions read.
    pub fn read_fragment(&self, path: &Path) -> Result<usize> {
        let bytes = std::fs::read(path)
            .with_context(|| format!("{}: cannot read the fragment", path.display()))?;
        let entries = decode(&bytes).with_context(|| {
            format!("{}: not a solve fragment of this pis-pack", path.display())
        })?;
        let n = entries.len();
        self.map.lock().expect("the solutions lock").extend(entries);
        Ok(n)
    }

    /// Writes every solution held to the fragment file `path` (atomically); returns its
    /// size in bytes.
    pub fn write_fragment(&self, path: &Path) -> Result<u64> {
        let map = self.map.lock().expect("the solutions lock");
        // Ordered by digest: the same solutions give the same bytes.
        let mut entries: Vec<(&Digest, &Solution)> = map.iter().collect();
        entries.sort_by_key(|(d, _)| **d);
        let mut out = Vec::new();
        out.extend_from_slice(MAGIC);
        out.extend_from_slice(&VERSION.to_le_bytes());
        out.extend_from_slice(
            &u32::try_from(entries.len())
                .map_err(|_| anyhow!("too many solutions for one fragment"))?
                .to_le_bytes(),
        );
        for (d, s) in entries {
            out.extend_from_slice(d);
            let l = s.layout;
            for v in [l.width, l.height, l.levels, l.faces] {
                out.extend_from_slice(&v.to_le_bytes());
            }
            out.push(match s.form {
                Form::A => 0,
                Form::Normal => 1,
            });
            out.extend_from_slice(&(s.n_s as u64).to_le_bytes());
            out.extend_from_slice(&(s.n_t as u64).to_le_bytes());
            out.extend_from_slice(&s.iterations.to_le_bytes());
            out.extend_from_slice(&s.residual_rms.to_le_bytes());
            out.extend_from_slice(&s.residual_relative.to_le_bytes());
            out.extend_from_slice(&(s.undefined as u64).to_le_bytes());
            out.push(s.converged as u8);
            out.extend_from_slice(&(s.texels.len() as u64).to_le_bytes());
            for v in &s.texels {
                out.extend_from_slice(&v.to_le_bytes());
            }
        }
        pis_trace::set::write_atomic(path, &out)?;
        Ok(out.len() as u64)
    }
}

/// A cursor over a fragment's bytes that fails, instead of reading past the end.
struct Cursor<'b> {
    bytes: &'b [u8],
}

impl<'b> Cursor<'b> {
    fn take(&mut self, n: usize) -> Result<&'b [u8]> {
        if n > self.bytes.len() {
            bail!("truncated: {n} bytes wanted, {} left", self.bytes.len());
        }
        let (a, b) = self.bytes.split_at(n);
        self.bytes = b;
        Ok(a)
    }
    fn u8(&mut self) -> Result<u8> {
        Ok(self.take(1)?[0])
    }
    fn u32(&mut self) -> Result<u32> {
        Ok(u32::from_le_bytes(self.take(4)?.try_into().expect("4 bytes")))
    }
    fn u64(&mut self) -> Result<u64> {
        Ok(u64::from_le_bytes(self.take(8)?.try_into().expect("8 bytes")))
    }
    fn f64(&mut self) -> Result<f64> {
        Ok(f64::from_le_bytes(self.take(8)?.try_into().expect("8 bytes")))
    }
}

fn decode(bytes: &[u8]) -> Result<Vec<(Digest, Solution)>> {
    let mut c = Cursor { bytes };
    if c.take(8)? != MAGIC {
        bail!("no PISSOLVD magic");
    }
    let version = c.u32()?;
    if version != VERSION {
        bail!("version {version}, this pis-pack reads {VERSION}");
    }
    let count = c.u32()? as usize;
    // Each solution takes at least its fixed fields: a count the file cannot hold is refused
    // before anything is allocated for it.
    const FIXED: usize = 16 + 16 + 1 + 16 + 4 + 16 + 8 + 1 + 8;
    if count > c.bytes.len() / FIXED {
        bail!("{count} solutions announced, the file holds at most {}", c.bytes.len() / FIXED);
    }
    let mut out = Vec::with_capacity(count);
    for k in 0..count {
        let d: Digest = c.take(16)?.try_into().expect("16 bytes");
        let layout =
            TextureLayout { width: c.u32()?, height: c.u32()?, levels: c.u32()?, faces: c.u32()? };
        let form = match c.u8()? {
            0 => Form::A,
            1 => Form::Normal,
            f => bail!("solution {k}: form {f}"),
        };
        let (n_s, n_t) = (c.u64()? as usize, c.u64()? as usize);
        let iterations = c.u32()?;
        let (residual_rms, residual_relative) = (c.f64()?, c.f64()?);
        let undefined = c.u64()? as usize;
        let converged = c.u8()? != 0;
        let n = c.u64()?;
        if n > (c.bytes.len() / 4) as u64 {
            bail!("solution {k}: {n} values announced, {} bytes left", c.bytes.len());
        }
        let texels: Vec<f32> = c
            .take(n as usize * 4)?
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes(b.try_into().expect("4 bytes")))
            .collect();
        let solution = Solution {
            layout,
            texels,
            form,
            n_s,
            n_t,
            iterations,
            channels: Vec::new(),
            residual_rms,
            residual_relative,
            undefined,
            converged,
            solve_ms: 0.0,
        };
        out.push((d, solution));
    }
    if !c.bytes.is_empty() {
        bail!("{} bytes after the last solution", c.bytes.len());
    }
    Ok(out)
}

/// Where a pack's solves go: to the solver, or through a store of solutions
/// ([`Solutions`]).
#[derive(Clone, Default)]
pub struct Solver(pub Option<Arc<Solutions>>);

impl std::fmt::Debug for Solver {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match &self.0 {
            None => write!(f, "Solver(direct)"),
            Some(s) => write!(f, "Solver(store of {})", s.len()),
        }
    }
}

impl Solver {
    /// Through `store`.
    pub fn with(store: Arc<Solutions>) -> Solver {
        Solver(Some(store))
    }

    /// [`pis_compile::solve()`], through the store when there is one.
    pub fn solve(
        &self,
        a: &RenderMatrix,
        b: &[f32],
        initial: Option<&[f32]>,
        settings: &SolveSettings,
    ) -> Result<Solution, CompileError> {
        match &self.0 {
            None => solve(a, b, initial, settings),
            Some(s) => s.through(false, &[View { a, b }][..], initial, settings, || {
                solve(a, b, initial, settings)
            }),
        }
    }

    /// [`pis_compile::solve_view_independent`], through the store when there is one.
    pub fn solve_view_independent(
        &self,
        views: &[View<'_>],
        initial: Option<&[f32]>,
        settings: &SolveSettings,
    ) -> Result<Solution, CompileError> {
        self.solve_view_source(views, initial, settings)
    }

    /// [`pis_compile::solve_view_source`] (the views read one at a time), through the store
    /// when there is one.
    pub fn solve_view_source<S: ViewSource + ?Sized>(
        &self,
        views: &S,
        initial: Option<&[f32]>,
        settings: &SolveSettings,
    ) -> Result<Solution, CompileError> {
        match &self.0 {
            None => solve_view_source(views, initial, settings),
            Some(s) => s.through(true, views, initial, settings, || {
                solve_view_source(views, initial, settings)
            }),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use pis_compile::synthetic;

    fn problem() -> (RenderMatrix, Vec<f32>) {
        let layout = TextureLayout::full(8, 8);
        let a = synthetic::warp_matrix(40, 30, layout, pis_compile::Filter::Trilinear, |x, y| {
            (x > 4.0).then_some((x / 40.0, (y / 30.0).powf(1.3)))
        });
        let b: Vec<f32> = (0..a.rows() * 3).map(|i| ((i * 37 % 101) as f32) / 101.0).collect();
        (a, b)
    }

    #[test]
    fn a_fragment_gives_back_the_solutions_bit_for_bit() {
        let (a, b) = problem();
        let settings = SolveSettings::decimated();
        let shard = Arc::new(Solutions::recording());
        let solved = Solver::with(shard.clone()).solve(&a, &b, None, &settings).unwrap();
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("0.solved");
        shard.write_fragment(&path).unwrap();
        let merge = Arc::new(Solutions::default());
        assert_eq!(merge.read_fragment(&path).unwrap(), 1);
        let read = Solver::with(merge.clone()).solve(&a, &b, None, &settings).unwrap();
        assert_eq!(merge.counts(), (1, 0), "read, not solved");
        assert!(
            read.texels.iter().zip(&solved.texels).all(|(x, y)| x.to_bits() == y.to_bits())
                && read.texels.len() == solved.texels.len()
        );
        assert_eq!(
            (read.iterations, read.layout, read.form, read.residual_rms.to_bits()),
            (solved.iterations, solved.layout, solved.form, solved.residual_rms.to_bits())
        );
        // Another start, other pixels or other settings are other solves.
        let mut b2 = b.clone();
        b2[5] += 1e-3;
        Solver::with(merge.clone()).solve(&a, &b2, None, &settings).unwrap();
        Solver::with(merge.clone()).solve(&a, &b, None, &SolveSettings::pyramidal()).unwrap();
        assert_eq!(merge.counts(), (1, 2));
    }

    #[test]
    fn a_damaged_fragment_is_refused_without_a_panic() {
        let (a, b) = problem();
        let shard = Arc::new(Solutions::recording());
        Solver::with(shard.clone()).solve(&a, &b, None, &SolveSettings::decimated()).unwrap();
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("0.solved");
        shard.write_fragment(&path).unwrap();
        let good = std::fs::read(&path).unwrap();
        for cut in [0, 7, 12, 16, 40, good.len() - 1] {
            assert!(decode(&good[..cut]).is_err(), "cut at {cut}");
        }
        let mut huge = good.clone();
        huge[12..16].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(decode(&huge).is_err(), "a count the file cannot hold");
        let mut values = good.clone();
        let at = 16 + 16 + 16 + 1 + 16 + 4 + 16 + 8 + 1;
        values[at..at + 8].copy_from_slice(&u64::MAX.to_le_bytes());
        assert!(decode(&values).is_err(), "a value count the file cannot hold");
        let mut extra = good;
        extra.push(0);
        assert!(decode(&extra).is_err());
    }
}
