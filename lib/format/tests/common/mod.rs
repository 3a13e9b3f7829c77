//! Helpers shared by the integration tests.
#![allow(dead_code)]

use pis_format::chunk::{header_crc, ENTRY_LEN, HEADER_LEN};

pub fn u32_at(b: &[u8], at: usize) -> u32 {
    u32::from_le_bytes(b[at..at + 4].try_into().unwrap())
}

pub fn u64_at(b: &[u8], at: usize) -> u64 {
    u64::from_le_bytes(b[at..at + 8].try_into().unwrap())
}

/// Recomputes every chunk checksum and the header checksum (as far as the table is there).
pub fn reseal(b: &mut [u8]) {
    if b.len() < HEADER_LEN as usize {
        return;
    }
    let count = (u32_at(b, 24) as usize).min((b.len() - HEADER_LEN as usize) / ENTRY_LEN as usize);
    for i in 0..count {
        let e = (HEADER_LEN + i as u64 * ENTRY_LEN) as usize;
        let (off, len) = (u64_at(b, e + 8) as usize, u64_at(b, e + 16) as usize);
        if off.checked_add(len).is_some_and(|end| end <= b.len()) {
            let crc = crc32fast::hash(&b[off..off + len]);
            b[e + 24..e + 28].copy_from_slice(&crc.to_le_bytes());
        }
    }
    let table_end = (HEADER_LEN + u32_at(b, 24) as u64 * ENTRY_LEN).min(b.len() as u64) as usize;
    let crc = header_crc(&b[..28], &b[32..table_end]);
    b[28..32].copy_from_slice(&crc.to_le_bytes());
}
