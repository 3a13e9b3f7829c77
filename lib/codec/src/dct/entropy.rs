//! Entropy coding of quantized 8×8 blocks with the adaptive binary range coder
//! (SPEC.md 11.5): the DC difference from the previous block of the same array, then the AC
//! coefficients in zig-zag order as significance flags with an end-of-block flag, signs as
//! direct bits, magnitudes as adaptive Exp-Golomb codes.

use crate::arith::{Context, Decoder, Encoder};

/// Longest Exp-Golomb prefix a decoder accepts.
const MAX_PREFIX: usize = 31;

/// All the adaptive contexts of one codestream.
pub struct Contexts {
    dc_zero: Context,
    dc_mag: [Context; MAX_PREFIX + 1],
    more: [Context; 64],
    zero: [Context; 64],
    ac_mag: [[Context; MAX_PREFIX + 1]; 3],
}

impl Default for Contexts {
    fn default() -> Self {
        Contexts {
            dc_zero: Context::default(),
            dc_mag: [Context::default(); MAX_PREFIX + 1],
            more: [Context::default(); 64],
            zero: [Context::default(); 64],
            ac_mag: [[Context::default(); MAX_PREFIX + 1]; 3],
        }
    }
}

fn band(k: usize) -> usize {
    match k {
        0..=2 => 0,
        3..=9 => 1,
        _ => 2,
    }
}

/// Exp-Golomb code of `v`: with `v + 1 = 2^p + r`, `p` one-bits (contexts by position)
/// and a zero, then the `p` bits of `r`, most significant first, as direct bits.
#[allow(clippy::needless_range_loop)]
fn put_uint(enc: &mut Encoder, ctx: &mut [Context; MAX_PREFIX + 1], v: u32) {
    let x = v as u64 + 1;
    let p = 63 - x.leading_zeros() as usize;
    for i in 0..p {
        enc.bit(&mut ctx[i], true);
    }
    enc.bit(&mut ctx[p], false);
    for i in (0..p).rev() {
        enc.direct((x >> i) & 1 == 1);
    }
}

fn get_uint(dec: &mut Decoder, ctx: &mut [Context; MAX_PREFIX + 1]) -> Option<u32> {
    let mut p = 0;
    while dec.bit(&mut ctx[p])? {
        p += 1;
        if p >= MAX_PREFIX {
            return None;
        }
    }
    let mut x: u64 = 1;
    for _ in 0..p {
        x = (x << 1) | dec.direct()? as u64;
    }
    u32::try_from(x - 1).ok()
}

/// Codes one block of quantized coefficients (zig-zag order) given the previous DC.
#[allow(clippy::needless_range_loop)]
pub fn put_block(enc: &mut Encoder, ctx: &mut Contexts, q: &[i32; 64], prev_dc: i32) {
    let d = q[0].wrapping_sub(prev_dc);
    enc.bit(&mut ctx.dc_zero, d != 0);
    if d != 0 {
        enc.direct(d < 0);
        put_uint(enc, &mut ctx.dc_mag, d.unsigned_abs() - 1);
    }
    let last = (1..64).rev().find(|&k| q[k] != 0).unwrap_or(0);
    let mut ask_more = true;
    for k in 1..64 {
        if ask_more {
            enc.bit(&mut ctx.more[k], k <= last);
            if k > last {
                break;
            }
        }
        let v = q[k];
        enc.bit(&mut ctx.zero[k], v != 0);
        if v != 0 {
            enc.direct(v < 0);
            put_uint(enc, &mut ctx.ac_mag[band(k)], v.unsigned_abs() - 1);
        }
        // After a zero the remaining coefficients are known to hold a non-zero one.
        ask_more = v != 0;
    }
}

/// Decodes one block (zig-zag order); `None` when the stream ends or is corrupt.
pub fn get_block(dec: &mut Decoder, ctx: &mut Contexts, prev_dc: i32) -> Option<[i32; 64]> {
    let mut q = [0i32; 64];
    let mut d: i64 = 0;
    if dec.bit(&mut ctx.dc_zero)? {
        let neg = dec.direct()?;
        let m = get_uint(dec, &mut ctx.dc_mag)? as i64 + 1;
        d = if neg { -m } else { m };
    }
    q[0] = i32::try_from(prev_dc as i64 + d).ok()?;
    let mut ask_more = true;
    let mut k = 1;
    while k < 64 {
        if ask_more && !dec.bit(&mut ctx.more[k])? {
            break;
        }
        let nonzero = dec.bit(&mut ctx.zero[k])?;
        if nonzero {
            let neg = dec.direct()?;
            let m = get_uint(dec, &mut ctx.ac_mag[band(k)])? as i64 + 1;
            q[k] = i32::try_from(if neg { -m } else { m }).ok()?;
        } else if k == 63 {
            // The flags promised a non-zero coefficient at or after k.
            return None;
        }
        ask_more = nonzero;
        k += 1;
    }
    Some(q)
}
