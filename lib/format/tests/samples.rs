//! The checked-in files are exactly what the code writes today: `samples/tiny.pis`, and the
//! spec's worked example `format-spec/examples/minimal.pis` with its annotated hex dump.
//! Run with `PIS_UPDATE_SAMPLES=1` to rewrite them after a deliberate format change.

use std::path::PathBuf;

use pis_format::samples::{minimal, tiny};
use pis_format::{hexdump, to_bytes, to_bytes_labelled};

fn repo(rel: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..").join(rel)
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
    assert_eq!(hexdump::parse(&dump), bytes, "the dump's hex columns are the file");
    // Every byte is labelled exactly once, in order.
    let mut at = 0;
    for s in &spans {
        assert_eq!(s.start, at, "{s:?}");
        at += s.len;
    }
    assert_eq!(at, bytes.len());
}

#[test]
fn spec_lists_every_validation_rule() {
    let spec = std::fs::read_to_string(repo("format-spec/SPEC.md")).unwrap();
    for (id, message) in pis_format::issue::RULES {
        let row = format!("| {id} | {message} |");
        assert!(spec.lines().any(|l| l == row), "SPEC.md lacks the row {row:?}");
    }
    let rows = spec
        .lines()
        .filter(|l| {
            l.len() > 6
                && l.starts_with("| ")
                && l[2..6].chars().all(|c| c.is_ascii_digit())
                && l[6..].starts_with(" | ")
        })
        .count();
    assert_eq!(
        rows,
        pis_format::issue::RULES.len(),
        "SPEC.md lists rules the reader does not check"
    );
}

#[test]
fn spec_excerpt_is_from_the_example_dump() {
    let spec = std::fs::read_to_string(repo("format-spec/SPEC.md")).unwrap();
    let dump = std::fs::read_to_string(repo("format-spec/examples/minimal.hex")).unwrap();
    let section = spec.split("## 14. Worked example").nth(1).expect("section 14");
    let excerpt = section.split("```").nth(1).expect("an excerpt");
    let lines: Vec<&str> =
        excerpt.lines().filter(|l| !l.trim().is_empty() && l.trim() != "...").collect();
    assert!(lines.len() > 10);
    for l in lines {
        assert!(dump.lines().any(|d| d == l), "excerpt line not in minimal.hex: {l:?}");
    }
}
