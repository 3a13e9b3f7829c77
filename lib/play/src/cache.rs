//! The cache of decoded level images (thesis 4.7). Each entry is one image of one Laplacian
//! pyramid level of one parameter block. An entry at pyramid level l (0 at the leaves, the
//! finest level, rising towards the top) lives L = a·b^l frames since it was last used: when
//! the count of frames since its last use exceeds L, it is reclaimed. Images near the top of
//! a pyramid serve many samples and are likely to be used again, so they live longer. On top
//! of the lifetimes, a memory budget: when the cached bytes exceed it at the end of a frame,
//! least recently used entries go first (the frame being drawn keeps what it needs until it
//! is drawn).

use std::collections::HashMap;
use std::sync::Arc;

/// One level image: object, layer, parameter block, pyramid level (file order: 0 is the
/// top), image within the level.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct LevelKey {
    pub object: u32,
    pub layer: u32,
    pub block: u32,
    pub level: u32,
    pub image: u32,
}

struct Entry {
    values: Arc<Vec<f32>>,
    /// Pyramid level counted from the leaves (thesis l).
    height: u32,
    last_used: u64,
}

/// What the cache did since it was created.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CacheCounters {
    pub hits: u64,
    pub misses: u64,
    pub expired: u64,
    pub evicted_for_budget: u64,
}

/// Decoded level images with the lifetime rule and a memory budget.
pub struct LevelCache {
    entries: HashMap<LevelKey, Entry>,
    bytes: u64,
    budget: u64,
    a: u64,
    b: u64,
    frame: u64,
    counters: CacheCounters,
}

impl LevelCache {
    pub fn new(budget_bytes: u64, a: u32, b: u32) -> LevelCache {
        LevelCache {
            entries: HashMap::new(),
            bytes: 0,
            budget: budget_bytes,
            a: a as u64,
            b: b as u64,
            frame: 0,
            counters: CacheCounters::default(),
        }
    }

    /// Lifetime in frames of an entry at pyramid level `height` (leaves 0): a·b^height,
    /// saturating.
    pub fn lifetime(&self, height: u32) -> u64 {
        self.a.saturating_mul(self.b.saturating_pow(height))
    }

    /// The frame now being drawn (starts at 0).
    pub fn frame(&self) -> u64 {
        self.frame
    }

    /// Looks an image up for the current frame; a hit resets its count of unused frames.
    pub fn get(&mut self, key: &LevelKey) -> Option<Arc<Vec<f32>>> {
        match self.entries.get_mut(key) {
            Some(e) => {
                e.last_used = self.frame;
                self.counters.hits += 1;
                Some(e.values.clone())
            }
            None => {
                self.counters.misses += 1;
                None
            }
        }
    }

    /// The image of `key` if cached, with no effect on its lifetime or the counters.
    pub fn peek(&self, key: &LevelKey) -> Option<Arc<Vec<f32>>> {
        self.entries.get(key).map(|e| e.values.clone())
    }

    /// Whether `key` is cached (no effect on its lifetime or the counters).
    pub fn contains(&self, key: &LevelKey) -> bool {
        self.entries.contains_key(key)
    }

    /// Adds a decoded image used by the current frame; `height` is its pyramid level counted
    /// from the leaves.
    pub fn insert(&mut self, key: LevelKey, height: u32, values: Arc<Vec<f32>>) {
        let size = (values.len() * 4) as u64;
        if let Some(old) = self.entries.insert(key, Entry { values, height, last_used: self.frame })
        {
            self.bytes -= (old.values.len() * 4) as u64;
        }
        self.bytes += size;
    }

    /// Ends the current frame: reclaims every entry unused for more than its lifetime, then
    /// least recently used entries while the cache exceeds its budget; the next frame begins.
    pub fn end_frame(&mut self) {
        let now = self.frame;
        let before = self.entries.len();
        let mut freed = 0u64;
        let (a, b) = (self.a, self.b);
        self.entries.retain(|_, e| {
            let life = a.saturating_mul(b.saturating_pow(e.height));
            let keep = now - e.last_used <= life;
            if !keep {
                freed += (e.values.len() * 4) as u64;
            }
            keep
        });
        self.bytes -= freed;
        self.counters.expired += (before - self.entries.len()) as u64;
        if self.bytes > self.budget {
            let mut order: Vec<(u64, u32, LevelKey)> =
                self.entries.iter().map(|(k, e)| (e.last_used, e.height, *k)).collect();
            // Oldest first; among equally old, leaves (shortest lifetimes) first.
            order.sort();
            for (_, _, k) in order {
                if self.bytes <= self.budget {
                    break;
                }
                if let Some(e) = self.entries.remove(&k) {
                    self.bytes -= (e.values.len() * 4) as u64;
                    self.counters.evicted_for_budget += 1;
                }
            }
        }
        self.frame += 1;
    }

    /// The memory budget in bytes.
    pub fn budget(&self) -> u64 {
        self.budget
    }

    pub fn bytes(&self) -> u64 {
        self.bytes
    }

    pub fn len(&self) -> usize {
        self.entries.len()
    }

    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    pub fn counters(&self) -> CacheCounters {
        self.counters
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn key(level: u32, image: u32) -> LevelKey {
        LevelKey { object: 0, layer: 0, block: 0, level, image }
    }

    fn img(n: usize) -> Arc<Vec<f32>> {
        Arc::new(vec![0.5; n])
    }

    #[test]
    fn entries_live_a_times_b_to_the_level_frames_since_last_use() {
        let (a, b) = (3, 2);
        let mut c = LevelCache::new(u64::MAX, a, b);
        // Heights 0, 1, 2: lifetimes 3, 6, 12 frames.
        for h in 0..3 {
            c.insert(key(h, 0), h, img(4));
        }
        assert_eq!([c.lifetime(0), c.lifetime(1), c.lifetime(2)], [3, 6, 12]);
        c.end_frame(); // frame 0 used them
        let alive = |c: &LevelCache| (0..3).map(|h| c.contains(&key(h, 0))).collect::<Vec<_>>();
        // Frames 1..=3 unused: the leaf entry has gone 3 frames unused, still alive.
        for _ in 1..=3 {
            c.end_frame();
        }
        assert_eq!(alive(&c), [true, true, true]);
        c.end_frame(); // frame 4: 4 > 3 unused frames
        assert_eq!(alive(&c), [false, true, true]);
        for _ in 5..=6 {
            c.end_frame();
        }
        assert_eq!(alive(&c), [false, true, true]);
        c.end_frame(); // frame 7: 7 > 6
        assert_eq!(alive(&c), [false, false, true]);
        // A use (in frame 8) resets the count: alive through 12 unused frames (9..=20).
        assert!(c.get(&key(2, 0)).is_some());
        for _ in 8..=20 {
            c.end_frame();
        }
        assert_eq!(alive(&c), [false, false, true]);
        c.end_frame();
        assert_eq!(alive(&c), [false, false, false]);
        assert_eq!(c.bytes(), 0);
        assert_eq!(c.counters().expired, 3);
    }

    #[test]
    fn budget_evicts_least_recently_used_first() {
        // 16 bytes per image, budget for 3.
        let mut c = LevelCache::new(48, 20, 4);
        c.insert(key(0, 0), 0, img(4));
        c.end_frame();
        c.insert(key(0, 1), 0, img(4));
        c.end_frame();
        c.insert(key(0, 2), 0, img(4));
        assert!(c.get(&key(0, 0)).is_some()); // key 0 now most recent
        c.insert(key(0, 3), 0, img(4));
        assert_eq!(c.bytes(), 64);
        c.end_frame();
        assert_eq!(c.bytes(), 48);
        assert!(!c.contains(&key(0, 1)), "the least recently used entry goes");
        assert!(c.contains(&key(0, 0)) && c.contains(&key(0, 2)) && c.contains(&key(0, 3)));
        assert_eq!(c.counters().evicted_for_budget, 1);
        assert_eq!((c.counters().hits, c.counters().misses), (1, 0));
        assert!(c.get(&key(0, 1)).is_none());
        assert_eq!(c.counters().misses, 1);
    }
}
