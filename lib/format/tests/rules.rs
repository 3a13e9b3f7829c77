//! One crafted bad file per validation rule of SPEC.md. Each case starts from a valid sample,
//! breaks one thing (a field found by its label in the writer's annotated output, or the
//! model itself), keeps checksums consistent unless the rule is about them, and expects the
//! rule's id from `validate_bytes`, and an error from `PisReader` for every error rule.

use std::collections::BTreeSet;

#[path = "rules/cases.rs"]
mod cases;
mod common;

use cases::{light_basis_cases, many_large_level_images};

use common::{reseal, u64_at};
use pis_format::chunk::{ENTRY_LEN, HEADER_LEN};
use pis_format::issue::RULES;
use pis_format::samples::{master_of, minimal, tiny};
use pis_format::*;

/// A valid file with its field labels.
pub(crate) struct File {
    bytes: Vec<u8>,
    spans: Vec<Span>,
}

impl File {
    fn of(c: &Container) -> Self {
        let (bytes, spans) = to_bytes_labelled(c).unwrap();
        File { bytes, spans }
    }

    fn tiny() -> Self {
        Self::of(&tiny().unwrap())
    }

    /// Offset of the first field whose label starts with `label`.
    fn at(&self, label: &str) -> usize {
        self.spans
            .iter()
            .find(|s| s.label.starts_with(label))
            .unwrap_or_else(|| panic!("no field labelled {label:?}"))
            .start
    }

    fn set_u32(&mut self, label: &str, v: u32) -> &mut Self {
        let at = self.at(label);
        self.bytes[at..at + 4].copy_from_slice(&v.to_le_bytes());
        self
    }

    fn set_u8(&mut self, label: &str, v: u8) -> &mut Self {
        let at = self.at(label);
        self.bytes[at] = v;
        self
    }

    fn set_f32(&mut self, label: &str, v: f32) -> &mut Self {
        self.set_u32(label, v.to_bits())
    }

    fn set_u16(&mut self, label: &str, v: u16) -> &mut Self {
        let at = self.at(label);
        self.bytes[at..at + 2].copy_from_slice(&v.to_le_bytes());
        self
    }

    fn set_bytes(&mut self, label: &str, b: &[u8]) -> &mut Self {
        let at = self.at(label);
        self.bytes[at..at + b.len()].copy_from_slice(b);
        self
    }

    /// Recomputes every chunk checksum and the header checksum.
    fn reseal(&mut self) -> Vec<u8> {
        reseal(&mut self.bytes);
        self.bytes.clone()
    }
}

/// Entry offset of chunk `i`'s table entry.
fn entry(i: usize) -> usize {
    (HEADER_LEN + i as u64 * ENTRY_LEN) as usize
}

fn set_file_length(b: &mut [u8]) {
    let n = b.len() as u64;
    b[16..24].copy_from_slice(&n.to_le_bytes());
}

pub(crate) fn unchecked(edit: impl FnOnce(&mut Container)) -> Vec<u8> {
    let mut c = tiny().unwrap();
    edit(&mut c);
    to_bytes_unchecked(&c)
}

/// Every case: (rule id, the crafted file), by the spec's groups of rules.
fn cases() -> Vec<(u16, Vec<u8>)> {
    [
        io_and_header_cases(),
        chunk_table_cases(),
        space_object_cases(),
        layer_pyramid_cases(),
        codestream_provenance_cases(),
        master_cases(),
        light_basis_cases(),
    ]
    .concat()
}

/// Rules 1xxx (I/O) and 2xxx (the file header).
fn io_and_header_cases() -> Vec<(u16, Vec<u8>)> {
    let mut v: Vec<(u16, Vec<u8>)> = Vec::new();
    let good = File::tiny().bytes;
    // 1xxx
    v.push((1002, good[..20].to_vec()));
    v.push((1003, good[..good.len() - 1].to_vec()));
    // 2xxx
    v.push((2001, {
        let mut b = good.clone();
        b[1] = b'X';
        b
    }));
    v.push((2002, {
        let mut b = good.clone();
        b[8] = 2;
        b
    }));
    v.push((2003, {
        let mut b = good.clone();
        b[12] = 1;
        reseal(&mut b);
        b
    }));
    v.push((2004, {
        let mut b = good.clone();
        b[28] ^= 0xff;
        b
    }));
    v.push((2005, {
        let mut b = good.clone();
        b[24..28].copy_from_slice(&1000u32.to_le_bytes());
        b
    }));
    v
}

/// Rules 3xxx: the chunk table and the fields every chunk has.
fn chunk_table_cases() -> Vec<(u16, Vec<u8>)> {
    let mut v: Vec<(u16, Vec<u8>)> = Vec::new();
    let t = || File::tiny();
    let good = File::tiny().bytes;
    let chunks = PisReader::from_bytes(good.clone()).unwrap().chunks().to_vec();
    let prov = chunks.iter().position(|e| &e.fourcc == b"PROV").unwrap();
    // 3xxx
    v.push((3001, {
        let mut b = good.clone();
        b[entry(prov) + 8] += 1;
        reseal(&mut b);
        b
    }));
    v.push((3002, {
        let mut b = good.clone();
        b[entry(prov) + 16..entry(prov) + 24].copy_from_slice(&u64::MAX.to_le_bytes());
        reseal(&mut b);
        b
    }));
    v.push((3003, {
        // Move the last chunk 8 bytes on, leaving a gap.
        let mut b = good.clone();
        let e = entry(prov);
        let (off, len) = (u64_at(&b, e + 8) as usize, u64_at(&b, e + 16) as usize);
        let payload = b[off..off + len].to_vec();
        b.truncate(off);
        b.extend([0; 8]);
        b.extend(payload);
        b[e + 8..e + 16].copy_from_slice(&(off as u64 + 8).to_le_bytes());
        set_file_length(&mut b);
        reseal(&mut b);
        b
    }));
    v.push((3004, {
        let mut b = good.clone();
        let at = t().at("dimension 0 block size");
        b[at] ^= 1;
        b
    }));
    v.push((3005, {
        let f = t();
        let pad = f
            .spans
            .iter()
            .find(|s| s.label.starts_with("padding") && s.len > 0)
            .expect("a padded chunk");
        let mut b = f.bytes.clone();
        b[pad.start] = 7;
        reseal(&mut b);
        b
    }));
    v.push((3006, t().set_u32("reserved", 5).reseal()));
    v.push((3007, {
        let mut b = good.clone();
        b[entry(prov)..entry(prov) + 4].copy_from_slice(b"ZZZZ");
        b[entry(prov) + 4] = 1;
        reseal(&mut b);
        b
    }));
    v.push((3008, {
        let mut b = good.clone();
        b[entry(0)..entry(0) + 4].copy_from_slice(b"ZZZZ");
        b[entry(0) + 4] = 0;
        reseal(&mut b);
        b
    }));
    v.push((3009, {
        let mut b = good.clone();
        b[entry(prov)..entry(prov) + 4].copy_from_slice(b"CAMS");
        b[entry(prov) + 4] = 1;
        reseal(&mut b);
        b
    }));
    v.push((3010, {
        let mut b = good.clone();
        b[entry(prov) + 4] = 1;
        reseal(&mut b);
        b
    }));
    v.push((3011, {
        let mut b = good.clone();
        b.extend([0; 8]);
        set_file_length(&mut b);
        reseal(&mut b);
        b
    }));
    v
}

/// Rules 4xxx (the parameter space) and 5xxx (cameras, objects and meshes).
fn space_object_cases() -> Vec<(u16, Vec<u8>)> {
    let mut v: Vec<(u16, Vec<u8>)> = Vec::new();
    let t = || File::tiny();
    // 4xxx
    v.push((4000, t().set_u32("dimension count", 3).reseal()));
    v.push((4001, t().set_u32("dimension count", 9).reseal()));
    v.push((4002, t().set_bytes("dimension 1 name =", &[0xff]).reseal()));
    v.push((4003, t().set_u8("dimension 0 kind", 9).reseal()));
    v.push((4004, unchecked(|c| c.space.dims[1].values.clear())));
    v.push((4005, t().set_u32("dimension 0 block size", 0).reseal()));
    v.push((4006, t().set_f32("dimension 0 sample values", f32::NAN).reseal()));
    v.push((
        4007,
        unchecked(|c| {
            c.space.dims[0].values = (0..5000).map(|i| i as f32).collect();
            c.space.dims[1].values = (0..5000).map(|i| i as f32).collect();
        }),
    ));
    // 5xxx
    v.push((5000, t().set_u32("camera count", 3).reseal()));
    v.push((
        5001,
        unchecked(|c| {
            c.cameras.cameras.pop();
        }),
    ));
    v.push((5002, t().set_u32("dependency mask", 0b100).reseal()));
    v.push((5003, t().set_f32("camera 0 yfov", 0.0).reseal()));
    v.push((5004, t().set_u32("image width", 0).reseal()));
    v.push((5100, t().set_u32("object count", 2).reseal()));
    v.push((5101, t().set_u32("object count", 0).reseal()));
    v.push((5102, t().set_bytes("object 0 name =", &[0xc3]).reseal()));
    v.push((5103, t().set_u8("object 0 role", 7).reseal()));
    v.push((5104, {
        let mut f = t();
        let at = f.at("object 0 ior");
        f.bytes[at..at + 4].copy_from_slice(&0.5f32.to_le_bytes());
        f.reseal()
    }));
    v.push((5105, t().set_u32("object 0 block origin offset, dimension 0", 2).reseal()));
    v.push((5106, t().set_f32("object 0 world_from_object 0", f32::INFINITY).reseal()));
    v.push((5200, t().set_u32("vertex count", 1000).reseal()));
    v.push((5201, t().set_u32("object index", 4).reseal()));
    v.push((5202, {
        let mut c = tiny().unwrap();
        let mut second = c.objects[0].clone();
        second.name = "second".into();
        c.objects.push(second);
        let mut b = to_bytes(&c).unwrap();
        // The second MESH chunk becomes an unknown optional chunk: object 1 has no mesh.
        let r = PisReader::from_bytes(b.clone()).unwrap();
        let i = r.chunks().iter().rposition(|e| &e.fourcc == b"MESH").unwrap();
        b[entry(i)..entry(i) + 4].copy_from_slice(b"XMSH");
        b[entry(i) + 4] = 0;
        reseal(&mut b);
        b
    }));
    v.push((
        5203,
        unchecked(|c| {
            c.objects[0].mesh.indices.pop();
        }),
    ));
    v.push((5204, t().set_u32("indices", 9999).reseal()));
    v.push((5205, t().set_f32("positions", f32::NAN).reseal()));
    v.push((
        5206,
        unchecked(|c| {
            c.objects[0].mesh.hull_triangles = c.objects[0].mesh.indices.len() as u32;
        }),
    ));
    v.push((
        5207,
        unchecked(|c| {
            let m = &mut c.objects[0].mesh;
            m.positions.clear();
            m.normals = Some(vec![]);
            m.texcoords = Some(vec![]);
        }),
    ));
    v
}

/// Rules 6xxx (layers and blocks) and 7xxx (pyramids).
fn layer_pyramid_cases() -> Vec<(u16, Vec<u8>)> {
    let mut v: Vec<(u16, Vec<u8>)> = Vec::new();
    let t = || File::tiny();
    // 6xxx
    v.push((6000, t().set_u32("layer count", 3).reseal()));
    v.push((6001, t().set_u32("layer 0 object index", 3).reseal()));
    v.push((6002, t().set_u8("layer 0 kind", 20).reseal()));
    v.push((6003, t().set_u8("layer 0 channels", 4).reseal()));
    v.push((6004, t().set_f32("layer 0 gamma", -1.0).reseal()));
    v.push((
        6005,
        unchecked(|c| {
            c.objects[0].layers[1].blocks.pop();
        }),
    ));
    v.push((6006, t().set_u32("layer 1 block 0 width", 5).reseal()));
    v.push((6007, t().set_f32("layer 1 block 0 shell parameters", -4.0).reseal()));
    // A texture that wraps along s with a side of 3 texels: the validator once passed it and
    // the player refused it ("repeat addressing ... needs a power-of-two used texture size").
    v.push((
        6007,
        unchecked(|c| {
            let b = &mut c.objects[0].layers[0].blocks[0];
            b.width = 3;
            b.placement = Placement::Surface {
                affine: [1.0, 0.0, 0.0, 1.0, 0.0, 0.0],
                repeat: [true, false],
                cut: [None, None],
            };
        }),
    ));
    v.push((
        6008,
        unchecked(|c| {
            let l = c.objects[0].layers[0].clone();
            c.objects[0].layers.push(l);
        }),
    ));
    v.push((
        6007,
        unchecked(|c| {
            c.objects[0].layers[0].blocks[0].placement = Placement::Surface {
                affine: [1.0, 0.0, 0.0, 1.0, 0.0, 0.0],
                repeat: [false; 2],
                cut: [Some(1.5), None],
            };
        }),
    ));
    v.push((3006, t().set_f32("layer 0 block 0 branch cuts u, v", 0.5).reseal()));
    // A shell block's flags hold the lookups per pixel side less one: 0 to 2.
    v.push((3006, {
        let mut f = t();
        let at = f
            .spans
            .iter()
            .find(|s| s.label.contains("flags (lookups per pixel side"))
            .expect("a shell block")
            .start;
        f.bytes[at..at + 2].copy_from_slice(&3u16.to_le_bytes());
        f.reseal()
    }));
    v.push((
        6009,
        t().set_u32("layer 0 block 0 width", 16384)
            .set_u32("layer 0 block 0 height", 16384)
            .reseal(),
    ));
    v.push((6010, many_large_level_images()));
    // 7xxx
    v.push((7001, t().set_u32("layer 0 block 0 level count", 0).reseal()));
    v.push((
        7002,
        unchecked(|c| {
            let lv = &mut c.objects[0].layers[0].blocks[0].levels;
            lv[0] = lv[1].clone();
        }),
    ));
    v.push((
        7003,
        unchecked(|c| {
            let lv = &mut c.objects[0].layers[0].blocks[0].levels;
            let top = lv[0].clone();
            lv.push(top);
        }),
    ));
    v.push((
        7004,
        unchecked(|c| {
            c.objects[0].layers[0].blocks[0].levels.pop();
        }),
    ));
    v.push((7005, {
        // The worked example's texture, which has dependency mask 0, given a second level.
        let mut c = minimal().unwrap();
        let levels = &mut c.objects[0].layers[0].blocks[0].levels;
        levels.push(levels[0].clone());
        to_bytes_unchecked(&c)
    }));
    v
}

/// Rules 8xxx (codestreams) and 90xx (the provenance).
fn codestream_provenance_cases() -> Vec<(u16, Vec<u8>)> {
    let mut v: Vec<(u16, Vec<u8>)> = Vec::new();
    let t = || File::tiny();
    // 8xxx
    v.push((8001, t().set_u32("layer 0 block 0 level 0 image 0 chunk index", 0).reseal()));
    v.push((8002, t().set_u32("layer 0 block 0 level 0 image 0 offset", 1 << 20).reseal()));
    v.push((8003, {
        let mut f = t();
        let at = f.at("codestream");
        f.bytes[at + 3] ^= 0x10;
        f.reseal()
    }));
    v.push((8004, t().set_u16("layer 0 block 0 level 0 image 0 codec", 77).reseal()));
    v.push((8005, t().set_u16("layer 0 block 0 level 0 image 0 codec", 0).reseal()));
    v.push((8006, {
        // A raw texel becomes NaN, with the codestream's own checksum updated.
        let mut f = File::of(&minimal().unwrap());
        let at = f.at("codestream");
        f.bytes[at..at + 4].copy_from_slice(&f32::NAN.to_le_bytes());
        let span = f.spans.iter().find(|s| s.label.starts_with("codestream")).unwrap().clone();
        let crc = crc32fast::hash(&f.bytes[span.start..span.start + span.len]);
        f.set_u32("layer 0 block 0 level 0 image 0 crc32", crc);
        f.reseal()
    }));
    v.push((
        8008,
        unchecked(|c| {
            // A lossless codestream with a byte after its DEFLATE stream.
            c.objects[0].layers[0].blocks[0].levels[0].images[0].bytes.push(0);
        }),
    ));
    // 8007 (reserved codec) has no case: every codec id of version 1 is decodable by this
    // build. A raw codestream relabelled as `wavelet` is now checked, and is corrupt.
    v.push((8005, t().set_u16("layer 0 block 0 level 0 image 0 codec", 2).reseal()));
    v.push((9000, t().set_u32("tool length", 1 << 30).reseal()));
    v.push((
        9001,
        unchecked(|c| {
            let p = c.provenance.as_mut().unwrap();
            p.settings.push(("filter".into(), "anisotropic".into()));
            p.settings.push(("anisotropy".into(), "32".into()));
        }),
    ));
    v.push((
        9002,
        unchecked(|c| {
            let p = c.provenance.as_mut().unwrap();
            p.settings.push(("display_filter".into(), "gaussian".into()));
            p.settings.push(("display_filter_sigma_px".into(), "0.5".into()));
            p.settings.push(("display_filter_radius_px".into(), "-1.5".into()));
        }),
    ));
    v.push((
        9003,
        unchecked(|c| {
            let p = c.provenance.as_mut().unwrap();
            p.settings.push(("codec".into(), "raw".into()));
        }),
    ));
    v.push((
        9004,
        unchecked(|c| {
            let p = c.provenance.as_mut().unwrap();
            p.settings.push(("transmission_tint.nobody".into(), "1,1,1".into()));
        }),
    ));
    v.push((
        9005,
        unchecked(|c| {
            let p = c.provenance.as_mut().unwrap();
            p.settings.push(("lens_model.nobody".into(), "greedy".into()));
        }),
    ));
    v
}

/// Rules 91xx: the lossless master.
fn master_cases() -> Vec<(u16, Vec<u8>)> {
    let mut v: Vec<(u16, Vec<u8>)> = Vec::new();
    // 91xx: the lossless master.
    let c = tiny().unwrap();
    let masters = master_of(&c).unwrap();
    let with_master = || {
        let (bytes, spans) = to_bytes_labelled_with_masters(&c, &masters).unwrap();
        File { bytes, spans }
    };
    let edited = |edit: &dyn Fn(&mut Vec<Master>)| {
        let mut m = masters.clone();
        edit(&mut m);
        to_bytes_unchecked_with_masters(&c, &m)
    };
    v.push((9100, with_master().set_u32("master layer 0 sample count", 1 << 30).reseal()));
    v.push((9101, with_master().set_u32("master object index", 7).reseal()));
    v.push((
        9102,
        edited(&|m| {
            m[0].layers[0].samples.pop();
        }),
    ));
    v.push((
        9102,
        edited(&|m| {
            m[0].layers.pop();
        }),
    ));
    v.push((9103, with_master().set_u8("master layer 0 codec", 2).reseal()));
    v.push((9104, edited(&|m| m[0].area = f64::NAN)));
    v.push((9105, edited(&|m| m[0].layers[0].samples[0].truncate(5))));
    v.push((
        9106,
        edited(&|m| {
            // A raw master texture holding a NaN.
            let n = master::sample_layout(&c, &c.objects[0], 0, 0)
                .unwrap()
                .planes()
                .iter()
                .map(|p| (p.width * p.height * p.channels) as usize)
                .sum::<usize>();
            let mut values = vec![0.5f32; n];
            values[3] = f32::NAN;
            m[0].layers[0].codec = CodecId::Raw;
            m[0].layers[0].samples[0] = values.iter().flat_map(|x| x.to_le_bytes()).collect();
        }),
    ));
    v.push((9107, {
        let mut two = c.clone();
        let mut second = two.objects[0].clone();
        second.name = "second".into();
        two.objects.push(second);
        to_bytes_unchecked_with_masters(&two, &masters)
    }));
    v.push((9100, with_master().set_u8("master layer 0 flags", 0x80).reseal()));
    v.push((
        9108,
        edited(&|m| {
            // Raw screen weights, one per finest texel, one of them negative.
            let l = master::sample_layout(&c, &c.objects[0], 0, 0).unwrap();
            let mut values = vec![1.0f32; (l.width * l.height) as usize];
            values[2] = -1.0;
            let layer = &mut m[0].layers[0];
            layer.codec = CodecId::Raw;
            layer.samples = layer
                .samples
                .iter()
                .map(|_| {
                    let n = l
                        .planes()
                        .iter()
                        .map(|p| (p.width * p.height * p.channels) as usize)
                        .sum::<usize>();
                    vec![0.5f32; n].iter().flat_map(|x| x.to_le_bytes()).collect()
                })
                .collect();
            layer.weights = layer
                .samples
                .iter()
                .map(|_| values.iter().flat_map(|x| x.to_le_bytes()).collect())
                .collect();
        }),
    ));
    v.push((
        9108,
        edited(&|m| {
            // Screen weights of the wrong size.
            let layer = &mut m[0].layers[0];
            layer.codec = CodecId::Raw;
            let l = master::sample_layout(&c, &c.objects[0], 0, 0).unwrap();
            let n = l
                .planes()
                .iter()
                .map(|p| (p.width * p.height * p.channels) as usize)
                .sum::<usize>();
            layer.samples = layer
                .samples
                .iter()
                .map(|_| vec![0.5f32; n].iter().flat_map(|x| x.to_le_bytes()).collect())
                .collect();
            layer.weights = layer
                .samples
                .iter()
                .map(|_| [1.0f32; 3].iter().flat_map(|x| x.to_le_bytes()).collect())
                .collect();
        }),
    ));
    v
}

#[test]
fn every_rule_is_detected_by_its_crafted_file() {
    for (id, bytes) in cases() {
        let report = validate_bytes(bytes.clone());
        let ids: Vec<u16> = report.issues.iter().map(|i| i.id).collect();
        assert!(ids.contains(&id), "rule {id}: expected it among {:?}", report.issues);
        let is_error = report.issues.iter().any(|i| i.id == id && i.severity == Severity::Error);
        assert_eq!(report.is_valid(), !is_error, "rule {id}: {:?}", report.issues);
        if is_error && (9100..9200).contains(&id) {
            // Opening ignores the master (a player never reads it); reading it fails.
            let r = PisReader::from_bytes(bytes).unwrap_or_else(|e| panic!("rule {id}: {e}"));
            let failed = match r.masters() {
                Err(e) => e.issue().is_some_and(|i| i.id == id),
                Ok(ms) => ms.iter().any(|m| {
                    m.layers.iter().enumerate().any(|(l, ml)| {
                        (0..ml.samples.len()).any(|s| {
                            m.texture(r.container(), l, s)
                                .err()
                                .and_then(|e| e.issue().map(|i| i.id))
                                == Some(id)
                                || m.weights(r.container(), l, s)
                                    .err()
                                    .and_then(|e| e.issue().map(|i| i.id))
                                    == Some(id)
                        })
                    })
                }),
            };
            assert!(failed, "rule {id}: the master was read");
        } else if is_error && ![8003, 8005, 8006, 8008].contains(&id) {
            // Open-time rules fail `open`; codestream rules fail when the texture is read.
            let err = PisReader::from_bytes(bytes)
                .err()
                .unwrap_or_else(|| panic!("rule {id}: reader accepted the file"));
            assert!(
                err.to_string().contains(&format!("error-{}", err.issue().map_or(0, |i| i.id))),
                "{err}"
            );
        } else if is_error {
            let r = PisReader::from_bytes(bytes).unwrap();
            let failed = (0..r.container().objects[0].layers.len()).any(|l| {
                let point = vec![0; r.container().space.dims.len()];
                r.texture(0, l, &point).is_err()
            });
            assert!(failed, "rule {id}: textures decoded");
        }
    }
}

#[test]
fn every_rule_has_a_case() {
    let covered: BTreeSet<u16> = cases().iter().map(|(id, _)| *id).collect();
    // 1001 (unreadable file) is covered by `missing_file_is_an_io_issue`; 8007 (a codec
    // this reader cannot decode) applies to no codec id in this build.
    let all: BTreeSet<u16> =
        RULES.iter().map(|(id, _)| *id).filter(|&id| id != 1001 && id != 8007).collect();
    assert_eq!(covered, all);
}

#[test]
fn missing_file_is_an_io_issue() {
    let report = validate_file("/no/such/file.pis".as_ref());
    assert_eq!(report.issues[0].id, 1001);
    assert!(matches!(PisReader::open("/no/such/file.pis".as_ref()), Err(Error::Io { .. })));
}

#[test]
fn the_samples_are_valid() {
    for c in [tiny().unwrap(), minimal().unwrap()] {
        let report = validate_bytes(to_bytes(&c).unwrap());
        assert!(report.issues.is_empty(), "{:?}", report.issues);
        assert!(report.chunk_crc_ok.iter().all(|&ok| ok == Some(true)));
    }
}

/// The ids `validate_bytes` reports for `bytes`.
fn reported(bytes: Vec<u8>) -> Vec<u16> {
    validate_bytes(bytes).issues.iter().map(|i| i.id).collect()
}

fn assert_reports(bytes: Vec<u8>, ids: &[u16]) {
    let found = reported(bytes.clone());
    for id in ids {
        assert!(found.contains(id), "expected {ids:?} among {:?}", validate_bytes(bytes).issues);
    }
}

#[test]
fn validation_reports_every_independent_broken_rule() {
    // A bad camera field and an object that does not parse (unknown role).
    assert_reports(
        File::tiny().set_f32("camera 0 yfov", 0.0).set_u8("object 0 role", 7).reseal(),
        &[5003, 5103],
    );
    // A camera and an object field, both checked on the model.
    assert_reports(
        File::tiny().set_f32("camera 0 yfov", 0.0).set_f32("object 0 ior", 0.5).reseal(),
        &[5003, 5104],
    );
    // Two bad chunks: CAMS fails its checksum, OBJS holds an invalid value.
    let mut f = File::tiny();
    f.set_f32("object 0 ior", 0.5).reseal();
    let at = f.at("image width");
    f.bytes[at] ^= 1;
    assert_reports(f.bytes.clone(), &[3004, 5104]);
    // Two broken rules in one payload that stays readable: a reserved field and a sample value.
    assert_reports(
        File::tiny().set_u32("reserved", 5).set_f32("dimension 0 sample values", f32::NAN).reseal(),
        &[3006, 4006],
    );
    // A broken header rule does not hide the chunks' rules.
    let mut b = File::tiny().set_f32("object 0 ior", 0.5).reseal();
    b[12] = 1;
    reseal(&mut b);
    assert_reports(b, &[2003, 5104]);
    // A bad camera does not stop the codestreams from being checked.
    let mut f = File::tiny();
    f.set_f32("camera 0 yfov", 0.0);
    let at = f.at("codestream");
    f.bytes[at + 3] ^= 0x10;
    assert_reports(f.reseal(), &[5003, 8003]);
    // A provenance that does not parse and a mesh that breaks a rule do not stop the
    // codestreams from being checked.
    let mut f = File::tiny();
    f.set_u32("tool length", 1 << 30).set_f32("positions", f32::NAN);
    let at = f.at("codestream");
    f.bytes[at + 3] ^= 0x10;
    assert_reports(f.reseal(), &[9000, 5205, 8003]);
    // Two objects without their meshes, and a transform of a third that is not rigid.
    let mut c = tiny().unwrap();
    for name in ["second", "third"] {
        let mut o = c.objects[0].clone();
        o.name = name.into();
        c.objects.push(o);
    }
    c.objects[2].transforms.transforms[0][0] = 2.0;
    let mut b = to_bytes_unchecked(&c);
    let r: Vec<usize> = validate_bytes(b.clone())
        .chunks
        .iter()
        .enumerate()
        .filter(|(_, e)| &e.fourcc == b"MESH")
        .map(|(i, _)| i)
        .collect();
    for &i in &r[1..] {
        b[entry(i)..entry(i) + 4].copy_from_slice(b"XMSH");
        b[entry(i) + 4] = 0;
    }
    reseal(&mut b);
    let ids = reported(b);
    assert_eq!(ids.iter().filter(|&&id| id == 5202).count(), 2, "{ids:?}");
    assert!(ids.contains(&5106), "{ids:?}");
}

#[test]
fn a_rule_that_builds_on_a_broken_structure_is_skipped() {
    // OBJS does not parse: the layers, which name objects, are not checked, and no
    // codestream is decoded; the camera rules still are.
    let ids = reported(
        File::tiny().set_u8("object 0 role", 7).set_u32("layer 0 object index", 3).reseal(),
    );
    assert!(ids.contains(&5103) && !ids.contains(&6001), "{ids:?}");
    // A parameter space that breaks a rule: the tables measured on it are not checked.
    let ids = reported(File::tiny().set_u32("dimension 0 block size", 0).reseal());
    assert!(ids.contains(&4005) && !ids.contains(&5105), "{ids:?}");
}
