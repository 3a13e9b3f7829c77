//! The checked-in files are exactly what the code writes today: `samples/tiny.pis`, and the
//! spec's worked example `format-spec/examples/minimal.pis` with its annotated hex dump.
//! Run with `PIS_UPDATE_SAMPLES=1` to rewrite them after a deliberate format change.

use std::path::PathBuf;

use pis_format::samples::{minimal, tiny};
use pis_format::{hexdump, to_bytes, to_bytes_labelled};

fn repo(rel: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(rel)
}

fn updating() -> bool {
    std::env::var_os("PIS_UPDATE_SAMPLES").is_some()
}

fn check_file(rel: &str, expected: &[u8]) {
    let path = repo(rel);
    if updating() {
        std::fs::write(&path, expected).unwrap();
    }
    let found = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert!(found == expected, "{rel} differs from what the writer produces; rerun with PIS_UPDATE_SAMPLES=1 if the change is deliberate");
}

#[test]
fn tiny_sample_matches_the_writer() {
    check_file("samples/tiny.pis", &to_bytes(&tiny().unwrap()).unwrap());
}

#[test]
fn spec_example_matches_the_writer() {
    let (bytes, spans) = to_bytes_labelled(&minimal().unwrap()).unwrap();
    check_file("format-spec/examples/minimal.pis", &bytes);
    let dump = hexdump::annotate(&bytes, &spans);
    check_file("format-spec/examples/minimal.hex", dump.as_bytes());
    assert_eq!(
        hexdump::parse(&dump),
        bytes,
        "the dump's hex columns are the file"
    );
    // Every byte is labelled exactly once, in order.
    let mut at = 0;
    for s in &spans {
        assert_eq!(s.start, at, "{s:?}");
        at += s.len;
    }
    assert_eq!(at, bytes.len());
}
