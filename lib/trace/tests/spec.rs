//! format-spec/RAYSET.md and the code describe the same layers and record layout.

use pis_scene::ObjectRole;
use pis_trace::records::{HIT_BYTES, RECORD_HEADER_BYTES};
use pis_trace::LayerKind;

fn spec() -> String {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../format-spec/RAYSET.md");
    std::fs::read_to_string(path).expect("format-spec/RAYSET.md is readable")
}

/// The lines of the section whose heading starts with `heading`.
fn section<'a>(text: &'a str, heading: &str) -> Vec<&'a str> {
    let mut lines = text.lines().skip_while(|l| !l.starts_with(heading));
    let first = lines.next().expect("section exists");
    let level = first.chars().take_while(|&c| c == '#').count();
    lines
        .take_while(|l| {
            !(l.starts_with('#') && l.chars().take_while(|&c| c == '#').count() <= level)
        })
        .collect()
}

/// Backquoted words of a table cell.
fn quoted(cell: &str) -> Vec<String> {
    cell.split('`').skip(1).step_by(2).map(str::to_string).collect()
}

#[test]
fn layer_table_lists_every_layer_with_its_channels() {
    let text = spec();
    let mut seen = Vec::new();
    for line in section(&text, "### 5.3") {
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        if cells.len() < 4 || !cells[1].starts_with('`') {
            continue;
        }
        for name in quoted(cells[1]) {
            let kind = LayerKind::from_name(&name)
                .unwrap_or_else(|| panic!("spec layer {name} unknown to the code"));
            if cells[2] != "as above" {
                let channels: Vec<&str> = cells[2].split_whitespace().collect();
                assert_eq!(channels, kind.channels(), "channels of {name}");
            }
            seen.push(kind);
        }
    }
    for role in ObjectRole::ALL {
        for k in LayerKind::for_role(role, 4) {
            assert!(seen.contains(k), "layer {} missing from RAYSET.md 5.3", k.name());
        }
    }
}

#[test]
fn role_table_matches_the_code() {
    let text = spec();
    let mut rows = 0;
    for line in section(&text, "### 5.2") {
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        let (role, terms) = match cells.get(1) {
            Some(&"diffuse") => (ObjectRole::Diffuse, 2),
            Some(&"reflective") => (ObjectRole::Reflective, 2),
            Some(&"refractive") => (ObjectRole::Refractive, 2),
            Some(&"refractive, tree model of 3 or 4 terms") => (ObjectRole::Refractive, 4),
            _ => continue,
        };
        let names: Vec<&str> = LayerKind::for_role(role, terms).iter().map(|k| k.name()).collect();
        // The tree's row lists what it adds to the greedy model's layers.
        let listed = if terms > 2 { &names[9..] } else { &names[..] };
        assert_eq!(quoted(cells[2]), listed, "layers of {role:?} ({terms} terms)");
        rows += 1;
    }
    assert_eq!(rows, 4);
}

#[test]
fn record_sizes_match_the_spec() {
    let text = spec();
    assert!(text.contains(&format!(
        "Record {{                        // {RECORD_HEADER_BYTES} bytes + {HIT_BYTES} per hit"
    )));
    assert!(text.contains(&format!("Hit {{                           // {HIT_BYTES} bytes")));
}
