//! The lossless master (SPEC.md 6.7): written after every other chunk, ignored when a file is
//! opened and its textures decoded, read on request with every rule checked; a damaged master
//! is reported clearly and never panics the reader.

mod common;

use common::reseal;
use pis_format::samples::{master_of, tiny};
use pis_format::*;

fn files() -> (Container, Vec<Master>, Vec<u8>, Vec<u8>) {
    let c = tiny().unwrap();
    let m = master_of(&c).unwrap();
    let plain = to_bytes(&c).unwrap();
    let with = to_bytes_with_masters(&c, &m).unwrap();
    (c, m, plain, with)
}

/// Every texture of every layer at every point, with the codestream reads they cost.
fn all_textures(r: &PisReader) -> (Vec<Vec<f32>>, ReadStats) {
    let c = r.container();
    let mut out = Vec::new();
    for (oi, o) in c.objects.iter().enumerate() {
        for li in 0..o.layers.len() {
            for p in 0..c.space.point_count() {
                out.push(r.texture(oi, li, &c.space.point(p)).unwrap().data);
            }
        }
    }
    (out, r.stats())
}

#[test]
fn a_master_round_trips_and_changes_nothing_a_player_reads() {
    let (c, masters, plain, with) = files();
    assert_eq!(to_bytes_with_masters(&c, &[]).unwrap(), plain, "no master: the file as before");
    let (a, b) =
        (PisReader::from_bytes(plain).unwrap(), PisReader::from_bytes(with.clone()).unwrap());
    assert!(!a.has_master() && a.masters().unwrap().is_empty() && a.master_bytes() == 0);
    assert!(b.has_master());
    assert_eq!(a.container().objects, b.container().objects);
    assert_eq!(b.master_bytes(), masters.iter().map(Master::payload_len).sum::<u64>());
    // The same textures for the same codestream reads: the master is never touched.
    assert_eq!(all_textures(&a), all_textures(&b));
    let read = b.masters().unwrap();
    assert_eq!(read, masters);
    for m in &read {
        let o = &c.objects[m.object as usize];
        for (li, l) in o.layers.iter().enumerate() {
            for s in 0..c.space.table_len(l.depends_on) {
                let point = master::sample_point(&c, l, s);
                let want = b.texture(m.object as usize, li, &point).unwrap().data;
                let got = m.texture(b.container(), li, s as usize).unwrap();
                assert!(
                    got.iter().zip(&want).all(|(x, y)| x.to_bits() == y.to_bits())
                        && got.len() == want.len()
                );
            }
        }
    }
    let v = validate_bytes(with);
    assert!(v.is_valid(), "{:?}", v.issues);
}

#[test]
fn a_corrupted_master_is_reported_and_textures_still_decode() {
    let (_, _, plain, mut with) = files();
    let r = PisReader::from_bytes(with.clone()).unwrap();
    let (i, e) = r
        .chunks()
        .iter()
        .enumerate()
        .find(|(_, e)| &e.fourcc == b"MSTR")
        .map(|(i, e)| (i, e.clone()))
        .unwrap();
    with[(e.offset + e.length / 2) as usize] ^= 0x5a;
    // Opened and played as before.
    let damaged =
        PisReader::from_bytes(with.clone()).expect("a damaged master does not stop a player");
    assert_eq!(all_textures(&damaged).0, all_textures(&PisReader::from_bytes(plain).unwrap()).0);
    let err = damaged.masters().unwrap_err();
    let issue = err.issue().expect("an invalid-file error");
    assert_eq!((issue.id, issue.chunk.clone()), (3004, Some(("MSTR".to_string(), i))));
    assert!(
        err.to_string().contains("chunk checksum mismatch") && err.to_string().contains("'MSTR'"),
        "{err}"
    );
    let v = validate_bytes(with);
    assert!(
        v.issues.iter().any(|x| x.id == 3004 && x.chunk == Some(("MSTR".to_string(), i))),
        "{:?}",
        v.issues
    );
}

#[test]
fn damaged_masters_never_panic() {
    let (c, _, _, with) = files();
    let r = PisReader::from_bytes(with.clone()).unwrap();
    let e = r.chunks().iter().find(|e| &e.fourcc == b"MSTR").unwrap().clone();
    let (start, len) = (e.offset as usize, e.length as usize);
    let mut rejected = 0;
    for k in (0..len).step_by(7).chain([0, 1, 8, 16, 24, 28, 32]) {
        for v in [0xffu8, 0x80, 0x01] {
            let mut b = with.clone();
            b[start + k] ^= v;
            reseal(&mut b);
            let r = PisReader::from_bytes(b).expect("opening ignores the master");
            match r.masters() {
                Err(_) => rejected += 1,
                Ok(ms) => {
                    for m in &ms {
                        for (li, l) in m.layers.iter().enumerate() {
                            for s in 0..l.samples.len() {
                                let _ = m.texture(&c, li, s);
                            }
                        }
                    }
                }
            }
        }
    }
    assert!(rejected > 0);
}

#[test]
fn screen_weights_round_trip_with_the_master() {
    let c = tiny().unwrap();
    let plain = master_of(&c).unwrap();
    // Textures as the plain master holds them; weights 0, 1, 2, ... per finest texel.
    let masters: Vec<Master> = plain
        .iter()
        .map(|m| {
            let o = &c.objects[m.object as usize];
            let textures: Vec<Vec<Vec<f32>>> = (0..o.layers.len())
                .map(|l| {
                    (0..m.layers[l].samples.len()).map(|s| m.texture(&c, l, s).unwrap()).collect()
                })
                .collect();
            let weights: Vec<Vec<Vec<f32>>> = (0..o.layers.len())
                .map(|l| {
                    (0..m.layers[l].samples.len())
                        .map(|s| {
                            let layout = master::sample_layout(&c, o, l, s as u64).unwrap();
                            (0..layout.width * layout.height)
                                .map(|k| (k % 7) as f32 * 0.5)
                                .collect()
                        })
                        .collect()
                })
                .collect();
            Master::encode(&c, m.object as usize, m.area, &textures, Some(&weights)).unwrap()
        })
        .collect();
    let r = PisReader::from_bytes(to_bytes_with_masters(&c, &masters).unwrap()).unwrap();
    let back = r.masters().unwrap();
    assert_eq!(back, masters);
    for m in &back {
        let o = &c.objects[m.object as usize];
        for l in 0..o.layers.len() {
            for s in 0..m.layers[l].samples.len() {
                let w = m.weights(&c, l, s).unwrap().expect("weights");
                let layout = master::sample_layout(&c, o, l, s as u64).unwrap();
                assert_eq!(w.len(), (layout.width * layout.height) as usize);
                assert!(w.iter().enumerate().all(|(k, v)| *v == (k % 7) as f32 * 0.5));
                assert_eq!(
                    m.texture(&c, l, s).unwrap(),
                    plain[m.object as usize].texture(&c, l, s).unwrap()
                );
            }
        }
    }
    // the plain master carries none
    assert!(plain[0].weights(&c, 0, 0).unwrap().is_none());
}
