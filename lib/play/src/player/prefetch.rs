//! Decoding ahead of the motion (thesis 4.7's cache, fed by a prediction): the level images of
//! the parameter samples the caller says come next are decoded on the workers while the frame
//! draws, and enter the level-image cache when the next frame collects them, with the cache's
//! lifetimes from then. A frame that needs an image still being decoded waits for that image
//! only. Work queued for a prediction that has changed is dropped before it starts (a started
//! decode finishes and is cached: it may still serve).

use std::collections::{HashMap, HashSet};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{mpsc, Arc, Mutex};

use pis_format::PisReader;

use crate::cache::{LevelCache, LevelKey};
use crate::decode::{decode_level, Decoder, LevelJob};
use crate::error::PlayError;

/// A level image to decode ahead: its key, its pyramid level counted from the leaves, the job.
pub(super) type AheadJob = (LevelKey, u32, LevelJob);

/// What a worker sends back.
enum Done {
    Decoded {
        key: LevelKey,
        height: u32,
        values: Result<Vec<f32>, PlayError>,
    },
    /// No longer predicted when a worker came to it.
    Dropped(LevelKey),
}

/// The work decoded ahead: in flight, and finished but not yet drawn.
pub(super) struct Prefetch {
    tx: mpsc::Sender<Done>,
    rx: mpsc::Receiver<Done>,
    /// Keys in flight and their decoded bytes.
    in_flight: HashMap<LevelKey, u64>,
    /// Keys the current prediction wants (a queued job whose key is not here is dropped).
    wanted: Arc<Mutex<HashSet<LevelKey>>>,
    /// Decoded ahead and in the cache, not yet drawn.
    ready: HashSet<LevelKey>,
    /// Level images dropped before they started (for the report).
    dropped: Arc<AtomicU64>,
}

impl Prefetch {
    pub(super) fn new() -> Prefetch {
        let (tx, rx) = mpsc::channel();
        Prefetch {
            tx,
            rx,
            in_flight: HashMap::new(),
            wanted: Arc::new(Mutex::new(HashSet::new())),
            ready: HashSet::new(),
            dropped: Arc::new(AtomicU64::new(0)),
        }
    }

    /// Whether `key` is being decoded ahead.
    pub(super) fn in_flight(&self, key: &LevelKey) -> bool {
        self.in_flight.contains_key(key)
    }

    /// Bytes being decoded ahead.
    pub(super) fn in_flight_bytes(&self) -> u64 {
        self.in_flight.values().sum()
    }

    /// Level images dropped so far because the prediction changed before they started.
    pub(super) fn dropped(&self) -> u64 {
        self.dropped.load(Ordering::Relaxed)
    }

    /// A new prediction: `predicted` is every level image it needs that is not cached; the
    /// queued work for others is dropped, and `jobs` (those of `predicted` not in flight)
    /// are queued on the workers.
    pub(super) fn start(
        &mut self,
        decoder: &Decoder,
        reader: &Arc<PisReader>,
        predicted: HashSet<LevelKey>,
        jobs: Vec<AheadJob>,
    ) {
        *self.wanted.lock().unwrap_or_else(|e| e.into_inner()) = predicted;
        for (key, height, job) in jobs {
            let bytes = pis_codec::value_count(&job.planes).unwrap_or(0) as u64 * 4;
            self.in_flight.insert(key, bytes);
            let (tx, reader, wanted) = (self.tx.clone(), reader.clone(), self.wanted.clone());
            let dropped = self.dropped.clone();
            decoder.spawn(move || {
                let still = wanted.lock().unwrap_or_else(|e| e.into_inner()).contains(&key);
                let done = if still {
                    Done::Decoded { key, height, values: decode_level(&reader, &job) }
                } else {
                    dropped.fetch_add(1, Ordering::Relaxed);
                    Done::Dropped(key)
                };
                // The player may be gone; its work with it.
                let _ = tx.send(done);
            });
        }
    }

    /// Moves finished work into `cache`, and waits until none of `needed` is in flight
    /// (those are wanted from now, so none is dropped). Returns whether it waited.
    pub(super) fn collect(&mut self, cache: &mut LevelCache, needed: &[LevelKey]) -> bool {
        let pending: Vec<LevelKey> =
            needed.iter().filter(|k| self.in_flight.contains_key(k)).copied().collect();
        self.wanted.lock().unwrap_or_else(|e| e.into_inner()).extend(pending.iter().copied());
        while let Ok(done) = self.rx.try_recv() {
            self.finish(done, cache);
        }
        let mut waited = false;
        while needed.iter().any(|k| self.in_flight.contains_key(k)) {
            waited = true;
            match self.rx.recv() {
                Ok(done) => self.finish(done, cache),
                Err(_) => break,
            }
        }
        waited
    }

    /// Whether `key` was decoded ahead and not drawn before (counted once).
    pub(super) fn take_ready(&mut self, key: &LevelKey) -> bool {
        self.ready.remove(key)
    }

    /// Forgets keys decoded ahead that the cache no longer holds.
    pub(super) fn end_frame(&mut self, cache: &LevelCache) {
        self.ready.retain(|k| cache.contains(k));
    }

    fn finish(&mut self, done: Done, cache: &mut LevelCache) {
        match done {
            Done::Decoded { key, height, values: Ok(values) } => {
                self.in_flight.remove(&key);
                cache.insert(key, height, Arc::new(values));
                self.ready.insert(key);
            }
            // A failed decode is decoded again by the frame that needs it, which reports
            // the error.
            Done::Decoded { key, .. } | Done::Dropped(key) => {
                self.in_flight.remove(&key);
            }
        }
    }
}
