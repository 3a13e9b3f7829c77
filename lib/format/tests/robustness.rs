//! The reader against damaged files: every flipped byte and every truncation is caught, and
//! thousands of random mutations (with and without resealed checksums, so they also reach
//! the payload parsers) give errors, never a panic, and never an allocation much larger than
//! the file.

mod common;

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use common::reseal;
use pis_format::samples::{minimal, tiny};
use pis_format::*;

/// Records the largest single allocation while `TRACK` is set.
struct Tracking;

static TRACK: AtomicBool = AtomicBool::new(false);
static LARGEST: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Tracking {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if TRACK.load(Ordering::Relaxed) {
            LARGEST.fetch_max(layout.size(), Ordering::Relaxed);
        }
        unsafe { System.alloc(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if TRACK.load(Ordering::Relaxed) {
            LARGEST.fetch_max(new_size, Ordering::Relaxed);
        }
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static ALLOC: Tracking = Tracking;

/// Opens `bytes` and, if that works, decodes every layer at every point. Returns whether
/// every step succeeded.
fn read_everything(bytes: &[u8]) -> bool {
    let Ok(r) = PisReader::from_bytes(bytes.to_vec()) else {
        return false;
    };
    let c = r.container();
    let mut ok = true;
    for p in 0..c.space.point_count() {
        let point = c.space.point(p);
        for (oi, o) in c.objects.iter().enumerate() {
            for li in 0..o.layers.len() {
                ok &= r.texture(oi, li, &point).is_ok();
            }
        }
    }
    ok
}

/// A small deterministic generator (xorshift64*).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
}

fn mutate(rng: &mut Rng, good: &[u8]) -> Vec<u8> {
    let mut b = good.to_vec();
    let kind = rng.below(5);
    match kind {
        // Overwrite a few bytes with random or boundary values.
        0 | 1 => {
            for _ in 0..1 + rng.below(8) {
                let at = rng.below(b.len());
                b[at] = match rng.below(4) {
                    0 => 0,
                    1 => 0xff,
                    2 => b[at].wrapping_add(1),
                    _ => rng.next() as u8,
                };
            }
        }
        // A 32-bit field set to a large or zero value.
        2 => {
            let at = rng.below(b.len() - 4) & !3;
            let v: u32 = [0, 1, 0x7fff_ffff, 0xffff_ffff, 1 << 20][rng.below(5)];
            b[at..at + 4].copy_from_slice(&v.to_le_bytes());
        }
        // Delete a range.
        3 => {
            let at = rng.below(b.len());
            let n = 1 + rng.below(64).min(b.len() - at - 1);
            b.drain(at..at + n);
        }
        // Duplicate a range.
        _ => {
            let at = rng.below(b.len());
            let n = 1 + rng.below(64).min(b.len() - at - 1);
            let chunk = b[at..at + n].to_vec();
            let to = rng.below(b.len());
            b.splice(to..to, chunk);
        }
    }
    // Most in-place changes get valid checksums, so that they reach the payload parsers.
    if kind <= 2 && rng.below(4) != 0 || rng.below(4) == 0 {
        reseal(&mut b);
        let n = b.len() as u64;
        if b.len() >= 24 {
            b[16..24].copy_from_slice(&n.to_le_bytes());
            reseal(&mut b);
        }
    }
    b
}

#[test]
fn damaged_files_give_errors_never_panics() {
    for good in [to_bytes(&tiny().unwrap()).unwrap(), to_bytes(&minimal().unwrap()).unwrap()] {
        assert!(read_everything(&good));

        // Every single flipped byte is caught by validation, and by the reader at the latest
        // when the damaged codestream is read.
        for at in 0..good.len() {
            let mut b = good.clone();
            b[at] ^= 0x5a;
            assert!(!validate_bytes(b.clone()).is_valid(), "flip at {at} not detected");
            assert!(!read_everything(&b), "flip at {at} read back without error");
        }

        // Every truncation is an error.
        for len in 0..good.len() {
            let report = validate_bytes(good[..len].to_vec());
            assert!(!report.is_valid(), "truncation to {len} not detected");
            let err =
                PisReader::from_bytes(good[..len].to_vec()).err().expect("truncated file opened");
            assert!(
                matches!(err.issue().map(|i| i.id), Some(1002 | 1003)),
                "truncation to {len}: {err}"
            );
        }

        // Random mutations: errors or valid files, no panic, bounded allocations.
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
        LARGEST.store(0, Ordering::Relaxed);
        TRACK.store(true, Ordering::Relaxed);
        let mut deep = 0;
        for _ in 0..3000 {
            let b = mutate(&mut rng, &good);
            let report = validate_bytes(b.clone());
            deep += report.issues.iter().any(|i| i.id >= 4000) as usize;
            let _ = read_everything(&b);
        }
        TRACK.store(false, Ordering::Relaxed);
        // Resealed mutations must get past the checksums into the payload rules.
        assert!(deep > 300, "only {deep} mutations reached the payload parsers");
        let largest = LARGEST.load(Ordering::Relaxed);
        // A level image decodes to at most MAX_EXPANSION × the file's codestream bytes, fewer
        // than its length (rule 6009); decoders may need a few times that as working memory.
        // Anything beyond would be an allocation sized by an unchecked field.
        assert!(
            largest as u64 <= 4 * pis_format::checks::MAX_EXPANSION * good.len() as u64,
            "largest allocation {largest} bytes for a {}-byte file",
            good.len()
        );
    }
}

/// A valid file padded with an unknown optional chunk of 1 MiB once raised the decoded-size
/// bound (then 1024 × the file's length) to 1 GiB per level image, so that a few hundred
/// bytes of codestream could declare textures a player allocated gigabytes for. The bound
/// is now measured on the codestream bytes the level images read: padding changes nothing.
#[test]
fn padding_a_file_does_not_raise_its_decoded_size_bound() {
    let mut c = tiny().unwrap();
    let b = &mut c.objects[0].layers[0].blocks[0];
    (b.width, b.height) = (1024, 1024);
    let declared = to_bytes_unchecked(&c);
    let padded = common::append_chunk(&declared, *b"ZZZZ", 0, &vec![0; 1 << 20]);
    assert_eq!(
        PisReader::from_bytes(declared).err().and_then(|e| e.issue().map(|i| i.id)),
        Some(6009)
    );
    let report = validate_bytes(padded.clone());
    assert!(report.issues.iter().any(|i| i.id == 6009), "{:?}", report.issues);
    assert!(
        !report.issues.iter().any(|i| (1000..4000).contains(&i.id)),
        "the padded file's structure is valid: {:?}",
        report.issues
    );
    assert_eq!(
        PisReader::from_bytes(padded).err().and_then(|e| e.issue().map(|i| i.id)),
        Some(6009)
    );
    // The same padding on the valid file is skipped, as an unknown optional chunk must be.
    let good =
        common::append_chunk(&to_bytes(&tiny().unwrap()).unwrap(), *b"ZZZZ", 0, &vec![0; 1 << 20]);
    assert!(validate_bytes(good.clone()).is_valid());
    assert!(read_everything(&good));
}
