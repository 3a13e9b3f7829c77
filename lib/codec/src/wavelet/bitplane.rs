//! The embedded bit-plane coder of the `wavelet` codec (SPEC.md 11.4): set partitioning in the
//! spirit of SPIHT, expressed as significance propagation. Bit-planes are coded from the top
//! down. In each plane a *significance pass* visits each subband in 4×4 tiles: a tile with no
//! significant coefficient yet first codes whether any of its coefficients becomes
//! significant in this plane (one bit for 16 coefficients, the set-partitioning step; context:
//! subband class and whether the parent tile is significant), and only then its coefficients
//! one by one (context: subband class, how many of the four neighbours and whether the parent
//! in the next coarser subband of the same orientation are already significant), each
//! followed by its sign; the last coefficient of a tile that just became significant, after
//! only zeros, is significant without a bit. Then a *refinement pass* codes the next
//! magnitude bit of every coefficient that was significant before this plane.
//!
//! Each coded event (a coefficient becoming significant with its sign, or one refinement bit)
//! is atomic for the decoder: it is applied only when all its bits were decoded, and the
//! arithmetic decoder decides every bit whose bytes it has. So every prefix of the stream
//! decodes to the state after the events that the prefix holds, and the encoder knows, event
//! by event, how many bytes that takes and what error remains.

use crate::arith::{Context, Decoder, Encoder};

/// A subband stored contiguously in scan order.
#[derive(Clone, Debug)]
pub struct Band {
    /// Index of the band's first coefficient in the coefficient array.
    pub offset: usize,
    pub width: usize,
    pub height: usize,
    /// 0 for the coarsest low-pass band, 1 for high-pass bands of level ≥ 3, 2 for level 2,
    /// 3 for level 1 (the finest).
    pub class: usize,
    /// The band of the same orientation one level coarser.
    pub parent: Option<usize>,
}

const SIG_CONTEXTS: usize = 4 * 6;
const TILE_CONTEXTS: usize = 4 * 2;
/// Side of the tiles of the significance pass.
pub const TILE: usize = 4;

/// Index of each band's first tile in the tile state.
fn tile_bases(bands: &[Band]) -> Vec<usize> {
    let mut base = 0;
    bands
        .iter()
        .map(|b| {
            let here = base;
            base += b.width.div_ceil(TILE) * b.height.div_ceil(TILE);
            here
        })
        .collect()
}

/// The tiles of a band's parent: index of its first tile, and its tiles across and down.
#[derive(Clone, Copy)]
struct ParentTiles {
    base: usize,
    across: usize,
    down: usize,
}

impl ParentTiles {
    /// The parent's row of tiles above tile row `ty` of the band: its first tile's index and
    /// its length.
    fn row(&self, ty: usize) -> ParentRow {
        ParentRow {
            first: self.base + (ty / 2).min(self.down - 1) * self.across,
            across: self.across,
        }
    }
}

#[derive(Clone, Copy)]
struct ParentRow {
    first: usize,
    across: usize,
}

fn parent_tiles(bands: &[Band], bases: &[usize], band: &Band) -> Option<ParentTiles> {
    band.parent.map(|p| ParentTiles {
        base: bases[p],
        across: bands[p].width.div_ceil(TILE),
        down: bands[p].height.div_ceil(TILE),
    })
}

/// The largest magnitude in each tile (indexed as the tile state): a tile becomes
/// significant in plane `p` when its maximum has a bit at or above `p`.
fn tile_maxima(bands: &[Band], bases: &[usize], tiles: usize, m: &[u32]) -> Vec<u32> {
    let mut max = vec![0u32; tiles];
    for (band, &base) in bands.iter().zip(bases) {
        let tw = band.width.div_ceil(TILE);
        for y in 0..band.height {
            let row = &m[band.offset + y * band.width..band.offset + (y + 1) * band.width];
            for (x, &v) in row.iter().enumerate() {
                let t = base + (y / TILE) * tw + x / TILE;
                max[t] = max[t].max(v);
            }
        }
    }
    max
}

/// The context of tile `tx` of a row whose parent row is `parent`: the band's class and
/// whether the parent tile is significant.
#[inline]
fn tile_context(class: usize, parent: Option<ParentRow>, tx: usize, tsig: &[bool]) -> usize {
    let parent = parent.is_some_and(|p| tsig[p.first + (tx / 2).min(p.across - 1)]);
    class * 2 + parent as usize
}

#[inline]
fn sig_context(bands: &[Band], band: &Band, x: usize, y: usize, i: usize, sig: &[u8]) -> usize {
    let w = band.width;
    let mut nb = 0;
    if x > 0 && sig[i - 1] != 0 {
        nb += 1;
    }
    if x + 1 < w && sig[i + 1] != 0 {
        nb += 1;
    }
    if y > 0 && sig[i - w] != 0 {
        nb += 1;
    }
    if y + 1 < band.height && sig[i + w] != 0 {
        nb += 1;
    }
    let parent = band.parent.is_some_and(|p| {
        let p = &bands[p];
        let px = (x / 2).min(p.width - 1);
        let py = (y / 2).min(p.height - 1);
        sig[p.offset + py * p.width + px] != 0
    });
    band.class * 6 + nb.min(2) * 2 + parent as usize
}

/// One point of the encoder's trace: after the first `needed` body bytes, the remaining
/// squared error (in units of the step², over scaled coefficients) is `error`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Checkpoint {
    pub needed: u64,
    pub error: f64,
}

/// Encodes magnitudes `a[i] = |c_i| / Δ` (≥ 0) with signs `neg`, bit-planes `top` down to 0.
/// Returns the body and the error after each prefix length where it changes.
pub fn encode(bands: &[Band], a: &[f64], neg: &[bool], top: u32) -> (Vec<u8>, Vec<Checkpoint>) {
    let n = a.len();
    let m: Vec<u32> = a.iter().map(|v| v.floor().min((1u64 << 31) as f64 - 1.0) as u32).collect();
    let mut sig = vec![0u8; n];
    let bases = tile_bases(bands);
    let mut tsig =
        vec![
            false;
            bases.last().map_or(0, |&b| b)
                + bands.last().map_or(0, |b| b.width.div_ceil(TILE) * b.height.div_ceil(TILE))
        ];
    let mut tctx = [Context::default(); TILE_CONTEXTS];
    let mut enc = Encoder::new();
    let mut sctx = [Context::default(); SIG_CONTEXTS];
    let mut rctx = [Context::default(); 2];
    let tile_max = tile_maxima(bands, &bases, tsig.len(), &m);
    let (mut significant, mut fresh): (Vec<usize>, Vec<usize>) = (Vec::new(), Vec::new());
    let mut error: f64 = a.iter().map(|v| v * v).sum();
    let mut trace = vec![Checkpoint { needed: 0, error }];
    let record = |needed: u64, error: f64, trace: &mut Vec<Checkpoint>| match trace.last_mut() {
        Some(last) if last.needed == needed => last.error = error,
        _ => trace.push(Checkpoint { needed, error }),
    };
    for p in (0..=top).rev() {
        let half = 0.5 * (1u64 << p) as f64;
        for (b, band) in bands.iter().enumerate() {
            let (w, tw) = (band.width, band.width.div_ceil(TILE));
            let parent = parent_tiles(bands, &bases, band);
            for ty in 0..band.height.div_ceil(TILE) {
                let parent_row = parent.map(|p| p.row(ty));
                for tx in 0..tw {
                    let t = bases[b] + ty * tw + tx;
                    let (x0, y0) = (tx * TILE, ty * TILE);
                    let (x1, y1) = ((x0 + TILE).min(w), (y0 + TILE).min(band.height));
                    let mut new_tile = false;
                    if !tsig[t] {
                        let any = tile_max[t] >> p != 0;
                        let c = tile_context(band.class, parent_row, tx, &tsig);
                        enc.bit(&mut tctx[c], any);
                        if !any {
                            continue;
                        }
                        tsig[t] = true;
                        new_tile = true;
                    }
                    let last = (y1 - 1, x1 - 1);
                    let mut only_zeros = true;
                    for y in y0..y1 {
                        for x in x0..x1 {
                            let i = band.offset + y * w + x;
                            if sig[i] != 0 {
                                continue;
                            }
                            let bit = (m[i] >> p) & 1 == 1;
                            if !(new_tile && only_zeros && (y, x) == last) {
                                let c = sig_context(bands, band, x, y, i, &sig);
                                enc.bit(&mut sctx[c], bit);
                            }
                            if bit {
                                only_zeros = false;
                                let needed = enc.bytes_needed_for_next();
                                enc.direct(neg[i]);
                                sig[i] = p as u8 + 1;
                                fresh.push(i);
                                let rec = 3.0 * half;
                                error += (a[i] - rec).powi(2) - a[i] * a[i];
                                record(needed, error, &mut trace);
                            }
                        }
                    }
                }
            }
        }
        for &i in &significant {
            let bit = (m[i] >> p) & 1 == 1;
            let needed = enc.bytes_needed_for_next();
            enc.bit(&mut rctx[(sig[i] as u32 == p + 2) as usize], bit);
            let old = (m[i] >> (p + 1) << (p + 1)) as f64 + 2.0 * half;
            let new = (m[i] >> p << p) as f64 + half;
            error += (a[i] - new).powi(2) - (a[i] - old).powi(2);
            record(needed, error, &mut trace);
        }
        merge_fresh(&mut significant, &mut fresh);
    }
    let total = enc.bytes_needed_for_next();
    let body = enc.finish();
    debug_assert_eq!(body.len() as u64, total);
    (body, trace)
}

/// The decoder's state of each coefficient, working memory that [`decode`] sizes and
/// clears: `sig`, the plane + 1 in which it became significant (0: not yet); for the
/// significant ones only (the others hold stale values), `mag`, the magnitude bits known so
/// far with the sign in bit 31, and `low`, the lowest bit-plane known.
#[derive(Default)]
pub struct CoefficientState {
    sig: Vec<u8>,
    mag: Vec<u32>,
    low: Vec<u8>,
}

impl CoefficientState {
    /// Bytes held.
    pub fn bytes(&self) -> usize {
        self.sig.capacity() + 4 * self.mag.capacity() + self.low.capacity()
    }

    fn reset(&mut self, n: usize) {
        self.sig.clear();
        self.sig.resize(n, 0);
        // Read only where `sig` says significant, which writes them first.
        if self.mag.len() < n {
            self.mag.resize(n, 0);
            self.low.resize(n, 0);
        }
    }

    /// The reconstructed magnitude of significant coefficient `i` in units of the step,
    /// signed: the middle of the interval that the decoded bits leave.
    pub fn value(&self, i: usize) -> f64 {
        let m = self.mag[i] & 0x7FFF_FFFF;
        let v = m as f64 + 0.5 * (1u64 << self.low[i]) as f64;
        if self.mag[i] >> 31 == 1 {
            -v
        } else {
            v
        }
    }
}

/// Largest coefficient count [`decode`] takes: indices are kept as `u32`.
pub const MAX_COEFFICIENTS: usize = u32::MAX as usize;

/// The decoded stream: the indices of the significant coefficients in index order (every
/// other one is 0), their values in the [`CoefficientState`]. Their count is bounded by the
/// body, each costing at least its sign's one bit.
pub struct Decoded {
    pub significant: Vec<u32>,
    /// Body bytes the range decoder read: the whole body when it ended (a truncated stream)
    /// or when the stream is exact; fewer when bytes follow the coded data.
    pub used: usize,
}

/// Merges `fresh` (what became significant in one plane, in tile order) into `sorted`
/// (index order), keeping index order: the order in which the refinement pass's scan of
/// every coefficient meets the significant ones.
fn merge_fresh<T: Copy + Ord>(sorted: &mut Vec<T>, fresh: &mut Vec<T>) {
    if fresh.is_empty() {
        return;
    }
    fresh.sort_unstable();
    let old = std::mem::take(sorted);
    sorted.reserve(old.len() + fresh.len());
    let (mut a, mut b) = (old.into_iter().peekable(), fresh.drain(..).peekable());
    while let (Some(x), Some(y)) = (a.peek(), b.peek()) {
        let next = if x < y { a.next() } else { b.next() };
        sorted.extend(next);
    }
    sorted.extend(a);
    sorted.extend(b);
}

/// Decodes as much of `body` as it holds (any prefix of an encoder's output is valid). The
/// refinement pass visits only the coefficients already significant, in index order, as
/// the encoder's scan of every coefficient meets them.
/// `n` is at most [`MAX_COEFFICIENTS`].
pub fn decode(
    bands: &[Band],
    n: usize,
    top: u32,
    body: &[u8],
    state: &mut CoefficientState,
) -> Decoded {
    assert!(n <= MAX_COEFFICIENTS, "{n} coefficients");
    state.reset(n);
    let CoefficientState { sig, mag, low } = state;
    let mut significant: Vec<u32> = Vec::new();
    let mut fresh: Vec<u32> = Vec::new();
    let bases = tile_bases(bands);
    let mut tsig =
        vec![
            false;
            bases.last().map_or(0, |&b| b)
                + bands.last().map_or(0, |b| b.width.div_ceil(TILE) * b.height.div_ceil(TILE))
        ];
    let mut tctx = [Context::default(); TILE_CONTEXTS];
    let mut dec = Decoder::new(body);
    let mut sctx = [Context::default(); SIG_CONTEXTS];
    let mut rctx = [Context::default(); 2];
    'planes: for p in (0..=top).rev() {
        for (b, band) in bands.iter().enumerate() {
            let (w, tw) = (band.width, band.width.div_ceil(TILE));
            let parent = parent_tiles(bands, &bases, band);
            for ty in 0..band.height.div_ceil(TILE) {
                let parent_row = parent.map(|p| p.row(ty));
                for tx in 0..tw {
                    let t = bases[b] + ty * tw + tx;
                    let (x0, y0) = (tx * TILE, ty * TILE);
                    let (x1, y1) = ((x0 + TILE).min(w), (y0 + TILE).min(band.height));
                    let mut new_tile = false;
                    if !tsig[t] {
                        let c = tile_context(band.class, parent_row, tx, &tsig);
                        match dec.bit(&mut tctx[c]) {
                            None => break 'planes,
                            Some(false) => continue,
                            Some(true) => {
                                tsig[t] = true;
                                new_tile = true;
                            }
                        }
                    }
                    let last = (y1 - 1, x1 - 1);
                    let mut only_zeros = true;
                    for y in y0..y1 {
                        for x in x0..x1 {
                            let i = band.offset + y * w + x;
                            if sig[i] != 0 {
                                continue;
                            }
                            let bit = if new_tile && only_zeros && (y, x) == last {
                                true
                            } else {
                                let c = sig_context(bands, band, x, y, i, sig);
                                match dec.bit(&mut sctx[c]) {
                                    None => break 'planes,
                                    Some(bit) => bit,
                                }
                            };
                            if bit {
                                only_zeros = false;
                                let Some(negative) = dec.direct() else {
                                    break 'planes;
                                };
                                sig[i] = p as u8 + 1;
                                mag[i] = (1 << p) | ((negative as u32) << 31);
                                low[i] = p as u8;
                                fresh.push(i as u32);
                            }
                        }
                    }
                }
            }
        }
        for &i in &significant {
            let i = i as usize;
            let first = sig[i] as u32 == p + 2;
            let Some(bit) = dec.bit(&mut rctx[first as usize]) else {
                break 'planes;
            };
            mag[i] |= (bit as u32) << p;
            low[i] = p as u8;
        }
        merge_fresh(&mut significant, &mut fresh);
    }
    merge_fresh(&mut significant, &mut fresh);
    Decoded { significant, used: dec.position() }
}
