//! Damaged containers against every tool that reads them: seeded mutants of valid files
//! (bytes flipped, fields set to extreme values, checksums resealed or not, truncations,
//! duplicated spans, unknown chunks) go through what pis-inspect (summary, --validate,
//! --extract), pis-reencode, pis-diff and pis-play (headless frames, on the GPU) do with a
//! file. Each must end in a result or an error: no panic, no mutant running longer than
//! [`HANG_S`], and the process's peak resident memory under [`RSS_LIMIT_BYTES`].
//!
//! The test runs `PIS_MUTANTS` mutants (default 300); the figure in docs/benchmarks/container.md
//! comes from `PIS_MUTANTS=100000 cargo test --release --test mutants -- --nocapture`.

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use pis_eval::diff::files::DiffRequest;
use pis_eval::headless::{run_frames, HeadlessRequest, PathChoice};
use pis_eval::reencode::ReencodeRequest;
use pis_format::chunk::{reseal, ENTRY_LEN, HEADER_LEN};
use pis_format::{CodecId, PisReader};
use pis_play::{Gpu, Player, PlayerOptions};

/// A mutant that has not finished after this many seconds is a hang.
const HANG_S: u64 = 60;
/// Peak resident memory the whole run may reach.
const RSS_LIMIT_BYTES: u64 = 1 << 30;

fn repo(rel: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..").join(rel)
}

/// SplitMix64: the mutants are a function of their index.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// Values that make fields interesting: zero, one, signs, powers of two, the extremes.
const EXTREMES: [u64; 10] =
    [0, 1, 2, 0x7f, 0xff, 0xffff, 0x7fff_ffff, 0x8000_0000, 0xffff_ffff, u64::MAX];

/// One mutant of `good`.
fn mutate(rng: &mut Rng, good: &[u8]) -> Vec<u8> {
    let mut b = good.to_vec();
    let payload_start = HEADER_LEN as usize;
    let mut resealed = true;
    match rng.below(7) {
        // A few bytes flipped anywhere.
        0 => {
            for _ in 0..1 + rng.below(8) {
                let at = rng.below(b.len());
                b[at] ^= 1 << rng.below(8);
            }
            resealed = rng.below(2) == 0;
        }
        // A 4- or 8-byte field set to an extreme value.
        1 | 2 => {
            let width = if rng.below(2) == 0 { 4 } else { 8 };
            let at =
                payload_start + rng.below((b.len() - payload_start).saturating_sub(width)) / 4 * 4;
            let v = EXTREMES[rng.below(EXTREMES.len())]
                ^ if rng.below(4) == 0 { rng.next() & 0xff } else { 0 };
            if at + width <= b.len() {
                b[at..at + width].copy_from_slice(&v.to_le_bytes()[..width]);
            }
        }
        // A float field set to NaN, infinity, a negative or a huge value.
        3 => {
            let at = payload_start + rng.below(b.len() - payload_start - 4) / 4 * 4;
            let v = [f32::NAN, f32::INFINITY, -1.0, 1e30, -0.0, f32::MIN_POSITIVE][rng.below(6)];
            b[at..at + 4].copy_from_slice(&v.to_le_bytes());
        }
        // Truncated.
        4 => {
            b.truncate(rng.below(b.len()));
            resealed = false;
        }
        // A span duplicated in place (every later offset moves), the header's length fixed.
        5 => {
            let from = rng.below(b.len());
            let len = 1 + rng.below(64.min(b.len() - from));
            let span = b[from..from + len].to_vec();
            let at = rng.below(b.len());
            b.splice(at..at, span);
            let n = b.len() as u64;
            b[16..24].copy_from_slice(&n.to_le_bytes());
        }
        // A chunk-table entry's offset or length moved by a little or a lot.
        _ => {
            let count = u32::from_le_bytes(b[24..28].try_into().unwrap()) as usize;
            let e = (HEADER_LEN + rng.below(count) as u64 * ENTRY_LEN) as usize
                + if rng.below(2) == 0 { 8 } else { 16 };
            let v = u64::from_le_bytes(b[e..e + 8].try_into().unwrap());
            let d = [1u64, 7, 8, 4096, 1 << 40][rng.below(5)];
            let v = if rng.below(2) == 0 { v.wrapping_add(d) } else { v.wrapping_sub(d) };
            b[e..e + 8].copy_from_slice(&v.to_le_bytes());
        }
    }
    if resealed {
        reseal(&mut b);
    }
    b
}

/// What each tool does with `file`; errors are fine, the tools must only return.
fn exercise(file: &Path, original: &Path, scratch: &Path, gpu: &Arc<Gpu>) {
    // pis-inspect: --validate, the summary, --extract.
    let _ = pis_format::validate_file(file);
    if let Ok(r) = PisReader::open(file) {
        let summary = pis_eval::inspect::summarize(&r);
        let _ = pis_eval::inspect::render(&summary);
        let point = vec![0; r.container().space.dims.len()];
        let _ = pis_eval::inspect::extract(&r, &point, &scratch.join("extract"));
        let _ = std::fs::remove_dir_all(scratch.join("extract"));
    }
    // pis-reencode, to a lossy codec.
    let out = scratch.join("re.pis");
    let _ = pis_eval::reencode::reencode(&ReencodeRequest {
        input: file.to_path_buf(),
        output: out.clone(),
        codec: CodecId::Wavelet,
        target: Some(pis_pack::Target::Ratio(8.0)),
        gamma: None,
        keep_master: false,
        block: None,
        max_mse: None,
        memory: pis_eval::budget::DEFAULT_BUDGET,
    });
    let _ = std::fs::remove_file(&out);
    // pis-diff against the file it came from.
    let _ = pis_eval::diff::files::diff(&DiffRequest {
        a: original.to_path_buf(),
        b: file.to_path_buf(),
        heatmaps: None,
        min_psnr: None,
        memory: pis_eval::budget::DEFAULT_BUDGET,
    });
    // pis-play: two frames along the diagonal.
    let options = PlayerOptions { workers: 1, ..PlayerOptions::default() };
    if let Ok(mut player) = Player::open(gpu.clone(), file, options.clone()) {
        let req = HeadlessRequest {
            file: file.to_path_buf(),
            at: None,
            path: Some(PathChoice::Diagonal),
            frames: Some(2),
            out: None,
            size: None,
            quiet: true,
            prefetch: 1,
            options,
        };
        let _ = run_frames(&req, gpu, &mut player);
    }
}

/// Peak resident memory of this process (VmHWM), in bytes.
fn peak_rss() -> u64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    status
        .lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<u64>().ok())
        .map_or(0, |kb| kb * 1024)
}

/// The valid files the mutants start from: the bundled sample (surface layers and a shell),
/// the spec's worked example, and the sample re-encoded with each lossy codec and with its
/// lossless master.
fn seeds(dir: &Path) -> Vec<PathBuf> {
    let tiny = repo("samples/tiny.pis");
    let mut out = vec![tiny.clone(), repo("format-spec/examples/minimal.pis")];
    for (name, codec, keep_master) in [
        ("wavelet", CodecId::Wavelet, false),
        ("dct", CodecId::Dct, false),
        ("master", CodecId::Lossless, true),
    ] {
        let path = dir.join(format!("seed-{name}.pis"));
        pis_eval::reencode::reencode(&ReencodeRequest {
            input: tiny.clone(),
            output: path.clone(),
            codec,
            target: (codec != CodecId::Lossless).then_some(pis_pack::Target::Ratio(6.0)),
            gamma: None,
            keep_master,
            block: None,
            max_mse: None,
            memory: pis_eval::budget::DEFAULT_BUDGET,
        })
        .unwrap_or_else(|e| panic!("seed {name}: {}", e.error));
        out.push(path);
    }
    out
}

#[test]
fn damaged_files_end_in_errors_never_in_panics_hangs_or_gigabytes() {
    let count: u64 = std::env::var("PIS_MUTANTS").ok().and_then(|s| s.parse().ok()).unwrap_or(300);
    let dir = tempfile::tempdir().unwrap();
    let seeds = seeds(dir.path());
    let gpu = Arc::new(Gpu::new().expect("a wgpu adapter (lavapipe on machines without a GPU)"));

    // The watchdog: a mutant still running after HANG_S seconds fails the run.
    let started = Arc::new(AtomicU64::new(0));
    let current = Arc::new(AtomicU64::new(u64::MAX));
    let origin = Instant::now();
    {
        let (started, current) = (started.clone(), current.clone());
        std::thread::spawn(move || loop {
            std::thread::sleep(Duration::from_secs(1));
            let k = current.load(Ordering::Relaxed);
            let since = origin.elapsed().as_secs().saturating_sub(started.load(Ordering::Relaxed));
            if k != u64::MAX && since > HANG_S {
                eprintln!("mutant {k} has run for {since} s: a hang");
                std::process::abort();
            }
        });
    }

    let file = dir.path().join("mutant.pis");
    let (mut panics, mut opened, mut slowest) = (Vec::new(), 0u64, (0.0f64, 0u64));
    for k in 0..count {
        let seed = &seeds[(k % seeds.len() as u64) as usize];
        let good = std::fs::read(seed).unwrap();
        let bytes = mutate(&mut Rng(k ^ 0x5eed_0000_0000), &good);
        std::fs::write(&file, &bytes).unwrap();
        opened += PisReader::from_bytes(bytes).is_ok() as u64;
        started.store(origin.elapsed().as_secs(), Ordering::Relaxed);
        current.store(k, Ordering::Relaxed);
        let t = Instant::now();
        if catch_unwind(AssertUnwindSafe(|| exercise(&file, seed, dir.path(), &gpu))).is_err() {
            panics.push(k);
            std::fs::copy(&file, dir.path().join(format!("panic-{k}.pis"))).ok();
        }
        let s = t.elapsed().as_secs_f64();
        if s > slowest.0 {
            slowest = (s, k);
        }
        current.store(u64::MAX, Ordering::Relaxed);
    }
    let rss = peak_rss();
    println!(
        "{count} mutants of {} seeds: {opened} opened as valid files, {} panics, slowest mutant {:.2} s (#{}), peak RSS {:.0} MiB, {:.0} s in all",
        seeds.len(),
        panics.len(),
        slowest.0,
        slowest.1,
        rss as f64 / (1 << 20) as f64,
        origin.elapsed().as_secs_f64()
    );
    assert!(panics.is_empty(), "mutants {panics:?} panicked");
    assert!(rss <= RSS_LIMIT_BYTES, "peak RSS {rss} bytes");
}
