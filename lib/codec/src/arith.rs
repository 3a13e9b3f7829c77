//! Binary adaptive range coder shared by the `wavelet` and `dct` codecs (SPEC.md 11.3).
//!
//! The coder is the one of LZMA with 16-bit probabilities (LZMA has 11): a 32-bit range,
//! probabilities of a 0 in 1/65536 that adapt by 1/32 of the distance to the coded value, normalisation by whole bytes when the range falls
//! below 2²⁴, and carry propagation through a cached byte. The first byte LZMA writes is
//! always 0 and is not stored. An encoder that codes `k` normalisations writes exactly
//! `k + 4` bytes, and a decoder decides bit `i` correctly from any prefix that holds the
//! `4 + (normalisations before bit i)` first bytes: this is what makes the wavelet stream
//! embedded (any truncation decodes every bit whose bytes it kept).

/// Probability bits of a context.
pub const PROB_BITS: u32 = 16;
const PROB_ONE: u32 = 1 << PROB_BITS;
const MOVE_BITS: u32 = 5;
const TOP: u32 = 1 << 24;

/// An adaptive binary context: the probability that the next bit is 0, in 1/65536. Sixteen
/// bits let a context that always sees 0 cost under a thousandth of a bit per use, which
/// the wavelet coder needs for its many insignificant coefficients.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Context(u16);

impl Default for Context {
    fn default() -> Self {
        Context((PROB_ONE / 2) as u16)
    }
}

impl Context {
    fn update(&mut self, bit: bool) {
        if bit {
            self.0 -= self.0 >> MOVE_BITS;
        } else {
            self.0 += ((PROB_ONE - self.0 as u32) >> MOVE_BITS) as u16;
        }
    }
}

/// Range encoder writing into a byte vector.
pub struct Encoder {
    low: u64,
    range: u32,
    cache: u8,
    cache_size: u64,
    out: Vec<u8>,
    norms: u64,
}

impl Default for Encoder {
    fn default() -> Self {
        Self::new()
    }
}

impl Encoder {
    pub fn new() -> Self {
        Encoder { low: 0, range: u32::MAX, cache: 0, cache_size: 1, out: Vec::new(), norms: 0 }
    }

    /// Bytes a decoder needs to decide the *next* bit: 4 + the normalisations so far.
    pub fn bytes_needed_for_next(&self) -> u64 {
        4 + self.norms
    }

    fn shift_low(&mut self) {
        if (self.low as u32) < 0xFF00_0000 || (self.low >> 32) != 0 {
            let carry = (self.low >> 32) as u8;
            let mut temp = self.cache;
            loop {
                self.out.push(temp.wrapping_add(carry));
                temp = 0xFF;
                self.cache_size -= 1;
                if self.cache_size == 0 {
                    break;
                }
            }
            self.cache = (self.low >> 24) as u8;
        }
        self.cache_size += 1;
        self.low = (self.low & 0x00FF_FFFF) << 8;
    }

    fn normalize(&mut self) {
        while self.range < TOP {
            self.range <<= 8;
            self.norms += 1;
            self.shift_low();
        }
    }

    /// Codes `bit` with the adaptive context `ctx`.
    pub fn bit(&mut self, ctx: &mut Context, bit: bool) {
        let bound = (self.range >> PROB_BITS) * ctx.0 as u32;
        if bit {
            self.low += bound as u64;
            self.range -= bound;
        } else {
            self.range = bound;
        }
        ctx.update(bit);
        self.normalize();
    }

    /// Codes `bit` with probability 1/2 (no context).
    pub fn direct(&mut self, bit: bool) {
        self.range >>= 1;
        if bit {
            self.low += self.range as u64;
        }
        self.normalize();
    }

    /// Flushes and returns the stream (without LZMA's leading 0 byte).
    pub fn finish(mut self) -> Vec<u8> {
        for _ in 0..5 {
            self.shift_low();
        }
        debug_assert_eq!(self.out.first(), Some(&0));
        self.out.remove(0);
        self.out
    }
}

/// Range decoder over a byte slice. When it needs a byte past the end it stops: the bit it
/// just decided is still returned, every later call returns `None`.
pub struct Decoder<'a> {
    bytes: &'a [u8],
    pos: usize,
    code: u32,
    range: u32,
    dead: bool,
}

impl<'a> Decoder<'a> {
    pub fn new(bytes: &'a [u8]) -> Self {
        let dead = bytes.len() < 4;
        let code =
            if dead { 0 } else { u32::from_be_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]) };
        Decoder { bytes, pos: 4, code, range: u32::MAX, dead }
    }

    /// True once the decoder has run out of bytes.
    pub fn exhausted(&self) -> bool {
        self.dead
    }

    /// Bytes read so far.
    pub fn position(&self) -> usize {
        self.pos.min(self.bytes.len())
    }

    fn normalize(&mut self) {
        while self.range < TOP {
            match self.bytes.get(self.pos) {
                Some(&b) => {
                    self.range <<= 8;
                    self.code = (self.code << 8) | b as u32;
                    self.pos += 1;
                }
                None => {
                    self.dead = true;
                    return;
                }
            }
        }
    }

    /// Decodes one bit with the adaptive context `ctx`.
    pub fn bit(&mut self, ctx: &mut Context) -> Option<bool> {
        if self.dead {
            return None;
        }
        let bound = (self.range >> PROB_BITS) * ctx.0 as u32;
        let bit = if self.code < bound {
            self.range = bound;
            false
        } else {
            self.code -= bound;
            self.range -= bound;
            true
        };
        ctx.update(bit);
        self.normalize();
        Some(bit)
    }

    /// Decodes one bit coded with [`Encoder::direct`].
    pub fn direct(&mut self) -> Option<bool> {
        if self.dead {
            return None;
        }
        self.range >>= 1;
        let bit = if self.code >= self.range {
            self.code -= self.range;
            true
        } else {
            false
        };
        self.normalize();
        Some(bit)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_prefix_property() {
        let mut seed = 7u32;
        let bits: Vec<bool> = (0..5000)
            .map(|i| {
                seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
                (seed >> 28) < if i % 3 == 0 { 2 } else { 13 }
            })
            .collect();
        let mut enc = Encoder::new();
        let mut ctx = [Context::default(); 3];
        let mut needed = Vec::new();
        for (i, &b) in bits.iter().enumerate() {
            needed.push(enc.bytes_needed_for_next());
            if i % 5 == 4 {
                enc.direct(b);
            } else {
                enc.bit(&mut ctx[i % 3], b);
            }
        }
        let total = enc.bytes_needed_for_next();
        let stream = enc.finish();
        assert_eq!(stream.len() as u64, total);
        for cut in [0, 3, 4, 5, 17, stream.len() / 2, stream.len()] {
            let mut dec = Decoder::new(&stream[..cut]);
            let mut ctx = [Context::default(); 3];
            for (i, &b) in bits.iter().enumerate() {
                let got = if i % 5 == 4 { dec.direct() } else { dec.bit(&mut ctx[i % 3]) };
                if needed[i] <= cut as u64 {
                    assert_eq!(got, Some(b), "bit {i} cut {cut}");
                } else {
                    assert_eq!(got, None, "bit {i} cut {cut}");
                    break;
                }
            }
        }
    }
}
