//! Helpers shared by the integration tests.
#![allow(dead_code)]

use pis_format::chunk::{ENTRY_LEN, HEADER_LEN};

pub fn u32_at(b: &[u8], at: usize) -> u32 {
    u32::from_le_bytes(b[at..at + 4].try_into().unwrap())
}

pub fn u64_at(b: &[u8], at: usize) -> u64 {
    u64::from_le_bytes(b[at..at + 8].try_into().unwrap())
}

pub use pis_format::chunk::reseal;

/// `b` with one more chunk, `fourcc` with `flags`, appended after the others (the chunk
/// table grows by one entry, so every payload moves; checksums and lengths made valid).
pub fn append_chunk(b: &[u8], fourcc: [u8; 4], flags: u32, payload: &[u8]) -> Vec<u8> {
    let count = u32_at(b, 24) as usize;
    let entry = |i: usize| (HEADER_LEN + i as u64 * ENTRY_LEN) as usize;
    let mut entries: Vec<([u8; 4], u32, Vec<u8>)> = (0..count)
        .map(|i| {
            let e = entry(i);
            let (off, len) = (u64_at(b, e + 8) as usize, u64_at(b, e + 16) as usize);
            (b[e..e + 4].try_into().unwrap(), u32_at(b, e + 4), b[off..off + len].to_vec())
        })
        .collect();
    entries.push((fourcc, flags, payload.to_vec()));
    let mut out = b[..HEADER_LEN as usize].to_vec();
    out[24..28].copy_from_slice(&(entries.len() as u32).to_le_bytes());
    let mut at = entry(entries.len());
    let mut table = Vec::new();
    let mut body = Vec::new();
    for (f, fl, p) in &entries {
        at = at.next_multiple_of(8);
        body.resize(at - entry(entries.len()), 0);
        table.extend_from_slice(f);
        table.extend_from_slice(&fl.to_le_bytes());
        table.extend_from_slice(&(at as u64).to_le_bytes());
        table.extend_from_slice(&(p.len() as u64).to_le_bytes());
        table.extend_from_slice(&[0; 8]);
        body.extend_from_slice(p);
        at += p.len();
    }
    out.extend(table);
    out.extend(body);
    let len = out.len() as u64;
    out[16..24].copy_from_slice(&len.to_le_bytes());
    reseal(&mut out);
    out
}
