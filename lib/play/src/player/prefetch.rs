//! Decoding ahead of the motion (thesis 4.7's cache, fed by a prediction): the textures of
//! the frames the caller says come next are prepared on the workers while the frame draws —
//! their level images decoded, and where the workers rebuild textures, the textures rebuilt
//! too — and enter the level-image cache (with its lifetimes from then) when the next frame
//! collects them. A frame that needs an image still being decoded waits for that work only.
//! Work queued for a texture no longer predicted is dropped before it starts (started work
//! finishes and is cached: it may still serve).

use std::collections::{HashMap, HashSet};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{mpsc, Arc, Mutex};

use pis_format::PisReader;

use super::assemble::assemble_job;
use super::plan::TextureKey;
use crate::cache::{LevelCache, LevelKey};
use crate::decode::TextureImage;
use crate::decode::{assemble, assemble_cube, decode_level, CubeImage, Decoder, LevelJob};
use crate::error::PlayError;

/// A level image to decode: its key, its pyramid level counted from the leaves, the job.
pub(super) type AheadJob = (LevelKey, u32, LevelJob);

/// A texture rebuilt on the workers, ready to upload.
pub(super) enum Rebuilt {
    Surface(TextureImage),
    Cube(CubeImage),
}

/// One texture to prepare ahead.
pub(super) struct AheadTexture {
    pub(super) key: TextureKey,
    /// The level images it decodes itself (no other texture of the prediction does).
    pub(super) decode: Vec<AheadJob>,
    /// Every level image on its path, top first, with its values where cached.
    pub(super) levels: Vec<(LevelKey, Option<Arc<Vec<f32>>>)>,
    /// Rebuild it on the workers, `drop_levels` finest levels dropped, once its level
    /// images are at hand (else only decode).
    pub(super) rebuild: Option<u32>,
}

/// A level image decoded ahead: its key, height, values.
type Decoded = (LevelKey, u32, Result<Arc<Vec<f32>>, PlayError>);

/// What a worker sends back.
enum Done {
    Prepared {
        key: TextureKey,
        levels: Vec<Decoded>,
        image: Option<Rebuilt>,
    },
    /// No longer predicted when a worker came to it: the texture, its level images.
    Dropped(TextureKey, Vec<LevelKey>),
}

/// The work prepared ahead: in flight, and finished but not yet drawn.
pub(super) struct Prefetch {
    tx: mpsc::Sender<Done>,
    rx: mpsc::Receiver<Done>,
    /// Level images in flight: the texture whose job decodes them, their bytes.
    in_flight: HashMap<LevelKey, (TextureKey, u64)>,
    /// Textures the current prediction wants (a queued job for another is dropped).
    wanted: Arc<Mutex<HashSet<TextureKey>>>,
    /// Decoded ahead and in the cache, not yet drawn.
    ready: HashSet<LevelKey>,
    /// Rebuilt ahead, not yet drawn.
    images: HashMap<TextureKey, Rebuilt>,
    /// Textures whose rebuild is queued or running.
    rebuilding: HashSet<TextureKey>,
    /// Level images dropped before they started (for the report).
    dropped: Arc<AtomicU64>,
}

/// A job's work: its level images decoded, then its texture rebuilt where asked and every
/// level image is at hand.
fn prepare(reader: &PisReader, t: AheadTexture) -> Done {
    let levels: Vec<Decoded> = t
        .decode
        .iter()
        .map(|(key, height, job)| (*key, *height, decode_level(reader, job).map(Arc::new)))
        .collect();
    let image = t.rebuild.and_then(|drop_levels| {
        let values: Option<Vec<Arc<Vec<f32>>>> = t
            .levels
            .iter()
            .map(|(key, cached)| {
                cached.clone().or_else(|| {
                    levels.iter().find(|d| d.0 == *key).and_then(|d| d.2.as_ref().ok().cloned())
                })
            })
            .collect();
        let job = assemble_job(reader, values?, &t.key, drop_levels);
        Some(match job.layer.mapping {
            pis_format::Mapping::Shell => Rebuilt::Cube(assemble_cube(&job)),
            _ => Rebuilt::Surface(assemble(&job)),
        })
    });
    Done::Prepared { key: t.key, levels, image }
}

fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
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
            images: HashMap::new(),
            rebuilding: HashSet::new(),
            dropped: Arc::new(AtomicU64::new(0)),
        }
    }

    /// Whether texture `key` is being rebuilt ahead (queued or running).
    pub(super) fn rebuilding(&self, key: &TextureKey) -> bool {
        self.rebuilding.contains(key)
    }

    /// Whether `key` is being decoded ahead.
    pub(super) fn in_flight(&self, key: &LevelKey) -> bool {
        self.in_flight.contains_key(key)
    }

    /// Whether texture `key` was rebuilt ahead and waits to be drawn.
    pub(super) fn has_image(&self, key: &TextureKey) -> bool {
        self.images.contains_key(key)
    }

    /// Bytes being decoded ahead.
    pub(super) fn in_flight_bytes(&self) -> u64 {
        self.in_flight.values().map(|v| v.1).sum()
    }

    /// Level images dropped so far because the prediction changed before they started.
    pub(super) fn dropped(&self) -> u64 {
        self.dropped.load(Ordering::Relaxed)
    }

    /// A new prediction: the textures it wants (queued work for others is dropped), and the
    /// `jobs` that prepare those not yet prepared, queued on the workers.
    pub(super) fn start(
        &mut self,
        decoder: &Decoder,
        reader: &Arc<PisReader>,
        predicted: HashSet<TextureKey>,
        jobs: Vec<AheadTexture>,
    ) {
        *lock(&self.wanted) = predicted;
        for t in jobs {
            if t.rebuild.is_some() {
                self.rebuilding.insert(t.key.clone());
            }
            for (key, _, job) in &t.decode {
                let bytes = pis_codec::value_count(&job.planes).unwrap_or(0) as u64 * 4;
                self.in_flight.insert(*key, (t.key.clone(), bytes));
            }
            let (tx, reader, wanted) = (self.tx.clone(), reader.clone(), self.wanted.clone());
            let dropped = self.dropped.clone();
            decoder.spawn(move || {
                let done = if lock(&wanted).contains(&t.key) {
                    prepare(&reader, t)
                } else {
                    dropped.fetch_add(t.decode.len() as u64, Ordering::Relaxed);
                    Done::Dropped(t.key, t.decode.into_iter().map(|j| j.0).collect())
                };
                // The player may be gone; its work with it.
                let _ = tx.send(done);
            });
        }
    }

    /// Moves finished work into `cache` (and the rebuilt textures aside), and waits until
    /// none of the `needed` level images is in flight and none of the `textures` is being
    /// rebuilt (the textures whose jobs prepare them are wanted from now, so none is
    /// dropped). Returns whether it waited.
    pub(super) fn collect(
        &mut self,
        cache: &mut LevelCache,
        needed: &[LevelKey],
        textures: &[&TextureKey],
    ) -> bool {
        let owners = needed.iter().filter_map(|k| self.in_flight.get(k)).map(|v| v.0.clone());
        let rebuilding = textures.iter().filter(|k| self.rebuilding.contains(**k));
        let owners: Vec<TextureKey> = owners.chain(rebuilding.map(|k| (*k).clone())).collect();
        lock(&self.wanted).extend(owners);
        while let Ok(done) = self.rx.try_recv() {
            self.finish(done, cache);
        }
        let mut waited = false;
        while needed.iter().any(|k| self.in_flight.contains_key(k))
            || textures.iter().any(|k| self.rebuilding.contains(*k))
        {
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

    /// Texture `key` as rebuilt ahead, if it was.
    pub(super) fn take_image(&mut self, key: &TextureKey) -> Option<Rebuilt> {
        self.images.remove(key)
    }

    /// Forgets level images decoded ahead that the cache no longer holds, and textures
    /// rebuilt ahead that the prediction no longer wants.
    pub(super) fn end_frame(&mut self, cache: &LevelCache) {
        self.ready.retain(|k| cache.contains(k));
        let wanted = lock(&self.wanted);
        self.images.retain(|k, _| wanted.contains(k));
    }

    fn finish(&mut self, done: Done, cache: &mut LevelCache) {
        match done {
            Done::Prepared { key, levels, image } => {
                self.rebuilding.remove(&key);
                for (level, height, values) in levels {
                    self.in_flight.remove(&level);
                    // A failed decode is decoded again by the frame that needs it, which
                    // reports the error.
                    if let Ok(values) = values {
                        cache.insert(level, height, values);
                        self.ready.insert(level);
                    }
                }
                if let Some(image) = image {
                    self.images.insert(key, image);
                }
            }
            Done::Dropped(key, levels) => {
                self.rebuilding.remove(&key);
                for level in levels {
                    self.in_flight.remove(&level);
                }
            }
        }
    }
}
