//! A solved layer's textures, one per sample key: held in memory, or, for a pack that
//! streams ([`super::memory`]), written to the scratch file once solved and read back one
//! sample at a time by the pyramids, the prediction and the master.

use std::borrow::Cow;
use std::collections::BTreeMap;
use std::sync::Arc;

use anyhow::{anyhow, Result};

use super::scratch::{Reader, Scratch, Span, Writer};

/// A layer's textures by sample key (sample index per masked dimension, in dimension order).
pub struct Textures {
    store: Store,
}

enum Store {
    Held(BTreeMap<Vec<u32>, Vec<f32>>),
    Spilled { scratch: Arc<Scratch>, spans: BTreeMap<Vec<u32>, Span> },
}

impl From<BTreeMap<Vec<u32>, Vec<f32>>> for Textures {
    fn from(textures: BTreeMap<Vec<u32>, Vec<f32>>) -> Self {
        Textures { store: Store::Held(textures) }
    }
}

impl Textures {
    /// No textures yet: held, or spilled to `scratch` as they are inserted.
    pub fn new(scratch: Option<&Arc<Scratch>>) -> Self {
        let store = match scratch {
            None => Store::Held(BTreeMap::new()),
            Some(s) => Store::Spilled { scratch: s.clone(), spans: BTreeMap::new() },
        };
        Textures { store }
    }

    /// Adds (or replaces) the texture of sample `key`.
    pub fn insert(&mut self, key: Vec<u32>, x: Vec<f32>) -> Result<()> {
        match &mut self.store {
            Store::Held(t) => {
                t.insert(key, x);
            }
            Store::Spilled { scratch, spans } => {
                let mut w = Writer::default();
                w.f32s(&x);
                spans.insert(key, scratch.put(&w.0)?);
            }
        }
        Ok(())
    }

    /// The number of samples.
    pub fn len(&self) -> usize {
        match &self.store {
            Store::Held(t) => t.len(),
            Store::Spilled { spans, .. } => spans.len(),
        }
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The sample keys, in increasing order.
    pub fn keys(&self) -> Box<dyn Iterator<Item = &Vec<u32>> + '_> {
        match &self.store {
            Store::Held(t) => Box::new(t.keys()),
            Store::Spilled { spans, .. } => Box::new(spans.keys()),
        }
    }

    pub fn contains_key(&self, key: &[u32]) -> bool {
        match &self.store {
            Store::Held(t) => t.contains_key(key),
            Store::Spilled { spans, .. } => spans.contains_key(key),
        }
    }

    /// The texture of sample `key`.
    pub fn get(&self, key: &[u32]) -> Result<Cow<'_, [f32]>> {
        match &self.store {
            Store::Held(t) => t
                .get(key)
                .map(|x| Cow::Borrowed(x.as_slice()))
                .ok_or_else(|| anyhow!("no texture for sample {key:?}")),
            Store::Spilled { scratch, spans } => {
                let span =
                    *spans.get(key).ok_or_else(|| anyhow!("no texture for sample {key:?}"))?;
                let bytes = scratch.get(span)?;
                let mut r = Reader::new(&bytes);
                let x = r.f32s()?;
                r.done()?;
                Ok(Cow::Owned(x))
            }
        }
    }

    /// Every sample with its texture, in key order.
    pub fn iter(&self) -> impl Iterator<Item = Result<(&Vec<u32>, Cow<'_, [f32]>)>> + '_ {
        self.keys().map(move |k| Ok((k, self.get(k)?)))
    }

    /// Moves the textures to `scratch`.
    pub fn spill(&mut self, scratch: &Arc<Scratch>) -> Result<()> {
        if let Store::Held(t) = &mut self.store {
            let held = std::mem::take(t);
            *self = Textures::new(Some(scratch));
            for (k, x) in held {
                self.insert(k, x)?;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spilled_textures_read_back_bit_for_bit_in_key_order() {
        let held: BTreeMap<Vec<u32>, Vec<f32>> =
            [(vec![1, 0], vec![0.5, -0.0, f32::MIN_POSITIVE]), (vec![0, 2], vec![1.0; 5])]
                .into_iter()
                .collect();
        let dir = tempfile::tempdir().unwrap();
        let scratch = Arc::new(Scratch::create(&dir.path().join("s")).unwrap());
        let mut t = Textures::from(held.clone());
        t.spill(&scratch).unwrap();
        assert!(
            !scratch.is_empty()
                && t.len() == 2
                && t.contains_key(&[0, 2])
                && !t.contains_key(&[2, 0])
        );
        let back: Vec<(Vec<u32>, Vec<f32>)> = t
            .iter()
            .map(|r| r.map(|(k, x)| (k.clone(), x.into_owned())))
            .collect::<Result<_>>()
            .unwrap();
        let want: Vec<(Vec<u32>, Vec<f32>)> = held.into_iter().collect();
        assert_eq!(back.len(), want.len());
        for ((ka, a), (kb, b)) in back.iter().zip(&want) {
            assert_eq!(ka, kb);
            assert!(a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits()));
        }
        assert!(t.get(&[9]).is_err());
        let mut inserted = Textures::new(Some(&scratch));
        inserted.insert(vec![3], vec![2.0, 0.25]).unwrap();
        assert_eq!(inserted.get(&[3]).unwrap().as_ref(), &[2.0, 0.25]);
    }
}
