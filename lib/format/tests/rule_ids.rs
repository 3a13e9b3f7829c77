//! Every rule id the spec names is one the code defines and reports: each id SPEC.md names
//! in its text is a row of its rule table and of `issue::RULES`, and each named id of
//! `issue.rs` is used by a check of the reader, the writer or the validator. Rules whose
//! field decides the layout of what follows (a layer's dependency mask, 5002, and block
//! count, 6005) are reported as themselves when that field alone is edited in a file, not
//! as the malformed payload that reading on would find; and the limits of section 12
//! count at least 1024 bytes of codestream, so a file whose codestreams are all empty is
//! valid.

use std::collections::BTreeSet;
use std::path::PathBuf;

use pis_format::chunk::reseal;
use pis_format::issue::RULES;
use pis_format::samples::tiny;
use pis_format::*;

fn repo(rel: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..").join(rel)
}

fn read(rel: &str) -> String {
    std::fs::read_to_string(repo(rel)).unwrap_or_else(|e| panic!("{rel}: {e}"))
}

/// The four-digit numbers after "rule" or "rules" (and the ids listed after it, up to the
/// end of the sentence part) in `text`.
fn ids_named_in_prose(text: &str) -> BTreeSet<u16> {
    let mut out = BTreeSet::new();
    for (i, _) in text.match_indices("rule") {
        let rest = &text[i..];
        let end = rest.find([')', ';', '.', ':', '\n']).unwrap_or(rest.len());
        for word in rest[..end].split(|c: char| !c.is_ascii_digit()) {
            if word.len() == 4 {
                out.insert(word.parse().unwrap());
            }
        }
    }
    out
}

#[test]
fn every_rule_the_spec_names_is_defined_and_listed() {
    let spec = read("format-spec/SPEC.md");
    let defined: BTreeSet<u16> = RULES.iter().map(|(id, _)| *id).collect();
    let table: BTreeSet<u16> = spec
        .lines()
        .filter_map(|l| l.strip_prefix("| ")?.get(..4)?.parse().ok())
        .filter(|id| (1000..10000).contains(id))
        .collect();
    assert_eq!(table, defined, "SPEC.md's rule table and issue::RULES differ");
    let named = ids_named_in_prose(&spec);
    assert!(named.len() > 60, "only {} ids found in the prose", named.len());
    let unknown: Vec<&u16> = named.difference(&defined).collect();
    assert!(unknown.is_empty(), "SPEC.md names rules issue.rs does not define: {unknown:?}");
}

/// Every `NAME = ID` of `issue.rs`'s rule list, as `group::NAME`.
fn named_ids() -> Vec<(String, u16)> {
    let src = read("lib/format/src/issue.rs");
    let mut group = String::new();
    let mut out = Vec::new();
    for line in src.lines().map(str::trim) {
        if let Some(g) = line.strip_prefix("pub mod ").and_then(|l| l.strip_suffix(" {")) {
            group = g.to_string();
        } else if let Some((name, rest)) = line.split_once(" = ") {
            let id = rest.split(',').next().and_then(|n| n.parse::<u16>().ok());
            if let (Some(id), true) = (id, name.chars().all(|c| c.is_ascii_uppercase() || c == '_'))
            {
                out.push((format!("{group}::{name}"), id));
            }
        }
    }
    out
}

#[test]
fn every_rule_is_reported_by_some_check() {
    let named = named_ids();
    let ids: BTreeSet<u16> = named.iter().map(|(_, id)| *id).collect();
    assert_eq!(ids, RULES.iter().map(|(id, _)| *id).collect(), "{named:?}");
    let sources: String = std::fs::read_dir(repo("lib/format/src"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "rs") && !p.ends_with("issue.rs"))
        .map(|p| std::fs::read_to_string(p).unwrap())
        .collect();
    // 8007 is kept for readers that do not decode a defined codec; this one decodes them
    // all, and reports it for `CodecError::NotSupported`.
    for (name, id) in &named {
        assert!(sources.contains(name.as_str()), "rule {id} ({name}) is reported by no check");
    }
}

/// `tiny` with the field labelled `label` set to `v` (checksums made valid again).
fn edited(label: &str, v: u32) -> Vec<u8> {
    let (mut bytes, spans) = to_bytes_labelled(&tiny().unwrap()).unwrap();
    let at = spans.iter().find(|s| s.label.starts_with(label)).unwrap().start;
    bytes[at..at + 4].copy_from_slice(&v.to_le_bytes());
    reseal(&mut bytes);
    bytes
}

fn reports_only(bytes: Vec<u8>, id: u16) {
    let v = validate_bytes(bytes.clone());
    let ids: Vec<u16> = v.issues.iter().map(|i| i.id).collect();
    assert_eq!(ids, [id], "{:?}", v.issues);
    let err = PisReader::from_bytes(bytes).err().expect("the reader refuses the file");
    assert_eq!(err.issue().map(|i| i.id), Some(id), "{err}");
}

/// A layer mask naming a dimension the space lacks was reported as a malformed `LAYR`
/// (6000) or an unknown codec (8004): its levels' sample counts were read as if the
/// dimension existed.
#[test]
fn a_layer_mask_naming_a_missing_dimension_is_rule_5002() {
    // tiny: 2 dimensions; layer 0 depends on the light (mask 0b10), layer 1 on the view.
    for mask in [0b100, 0b110, 0b101, 0x8000_0000] {
        reports_only(edited("layer 0 dependency mask", mask), 5002);
        reports_only(edited("layer 1 dependency mask", mask), 5002);
    }
}

/// A block count other than the layer's grid was reported as a malformed `LAYR` (6000), a
/// reserved field (3006) or a level count (7001): the blocks were read as counted.
#[test]
fn a_block_count_other_than_the_grid_is_rule_6005() {
    // tiny: layer 0 has one block, layer 1 two.
    for count in [0, 3, 1000, u32::MAX] {
        reports_only(edited("layer 0 block count", count), 6005);
        reports_only(edited("layer 1 block count", count), 6005);
    }
    reports_only(edited("layer 0 block count", 2), 6005);
    reports_only(edited("layer 1 block count", 1), 6005);
}

/// Object 0 and a copy of it, written with no `MESH` chunk at all, or with the copy's alone
/// turned into an unknown optional chunk.
fn without_meshes(all: bool) -> Vec<u8> {
    let mut c = tiny().unwrap();
    let mut second = c.objects[0].clone();
    second.name = "second".into();
    c.objects.push(second);
    let mut b = to_bytes(&c).unwrap();
    let chunks = PisReader::from_bytes(b.clone()).unwrap().chunks().to_vec();
    let meshes: Vec<usize> = (0..chunks.len()).filter(|&i| &chunks[i].fourcc == b"MESH").collect();
    for &i in if all { &meshes[..] } else { &meshes[1..] } {
        let e = 32 + 32 * i;
        b[e..e + 4].copy_from_slice(b"xMSH");
        b[e + 4] = 0;
    }
    reseal(&mut b);
    b
}

/// SPEC.md 5 and 6.5: a file without any `MESH` breaks 3008 and, per object, 5202; a file
/// with some `MESH` chunks, 5202 for each object that has none.
#[test]
fn a_missing_mesh_breaks_3008_only_when_no_mesh_is_left() {
    let ids = |b: Vec<u8>| validate_bytes(b).issues.iter().map(|i| i.id).collect::<Vec<u16>>();
    assert_eq!(ids(without_meshes(true)), [3008, 5202, 5202]);
    assert_eq!(ids(without_meshes(false)), [5202]);
}

/// `tiny` with every level image an empty `wavelet` codestream (SPEC.md 11.2: all zeros)
/// and the diffuse texture `w` × `h` texels.
fn empty_codestreams(w: u32, h: u32) -> Container {
    let mut c = tiny().unwrap();
    for l in &mut c.objects[0].layers {
        for b in &mut l.blocks {
            for r in b.levels.iter_mut().flat_map(|l| &mut l.images) {
                *r = Codestream { codec: CodecId::Wavelet, bytes: Vec::new() };
            }
        }
    }
    let b = &mut c.objects[0].layers[0].blocks[0];
    (b.width, b.height) = (w, h);
    c
}

/// Codestreams that are all empty (C = 0) were refused at write: every level image broke
/// "8192 × C". Section 12 counts C as at least 1024 bytes: level images of up to 8 MiB.
#[test]
fn a_file_whose_codestreams_are_all_empty_is_valid() {
    let c = empty_codestreams(32, 24);
    let bytes = to_bytes(&c).expect("written");
    let v = validate_bytes(bytes.clone());
    assert!(v.issues.is_empty(), "{:?}", v.issues);
    let r = PisReader::from_bytes(bytes).unwrap();
    let t = r.texture(0, 0, &[0, 0]).unwrap();
    assert!(t.data.iter().all(|&x| x == 0.0));
    // 1024 × 682 RGB texels are 8,380,416 bytes, within 8192 × 1024; 1024 × 683 are not.
    let at_limit = empty_codestreams(1024, 682);
    assert!(validate_bytes(to_bytes(&at_limit).expect("written")).issues.is_empty());
    let over = empty_codestreams(1024, 683);
    assert!(matches!(to_bytes(&over), Err(Error::InvalidModel(i)) if i.id == 6009));
    let ids: Vec<u16> =
        validate_bytes(to_bytes_unchecked(&over)).issues.iter().map(|i| i.id).collect();
    assert_eq!(ids, [6009]);
}
