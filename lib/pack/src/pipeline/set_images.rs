//! The traced images of a set as the pack holds them: every point's layers in memory, or,
//! for a pack that streams ([`super::memory`]), each object's layers at each point written
//! to the scratch file over the pixels where one of them is not zero, and read back one
//! object and point at a time. Either way an object's layers read the same values, bit for
//! bit: a pixel left out is zero in every layer of the object.

use std::borrow::Cow;
use std::sync::Arc;

use anyhow::{bail, Result};
use pis_trace::layers::LayerImage;
use pis_trace::PointImages;

use super::scratch::{Reader, Scratch, Span, Writer};

/// Every point's images.
pub enum SetImages {
    /// In memory, point by point, every layer the pack reads.
    Held(Vec<PointImages>),
    /// In the scratch file: per point, per object, its layers over their nonzero pixels.
    Spilled { scratch: Arc<Scratch>, width: u32, height: u32, spans: Vec<Vec<Span>> },
}

impl SetImages {
    /// The number of points.
    pub fn points(&self) -> usize {
        match self {
            SetImages::Held(v) => v.len(),
            SetImages::Spilled { spans, .. } => spans.len(),
        }
    }

    /// Point `p`'s images with (at least) the layers of object `o`: the whole point where it
    /// is held, that object's layers alone where spilled.
    pub fn object(&self, p: usize, o: usize) -> Result<Cow<'_, PointImages>> {
        match self {
            SetImages::Held(v) => match v.get(p) {
                Some(i) => Ok(Cow::Borrowed(i)),
                None => bail!("the set has no point {p}"),
            },
            SetImages::Spilled { scratch, width, height, spans } => {
                let Some(&span) = spans.get(p).and_then(|s| s.get(o)) else {
                    bail!("the set has no object {o} at point {p}")
                };
                Ok(Cow::Owned(read_object(&scratch.get(span)?, *width, *height)?))
            }
        }
    }

    /// Point `p`'s images with (at least) the layers of no object (`combined`).
    pub fn shared(&self, p: usize) -> Result<Cow<'_, PointImages>> {
        match self {
            SetImages::Held(_) => self.object(p, 0),
            SetImages::Spilled { spans, .. } => {
                self.object(p, spans.get(p).map_or(0, |s| s.len().saturating_sub(1)))
            }
        }
    }
}

/// Whether layer `name` is one of the layers of object channel `channel`
/// (`object.<channel>.<layer>`).
fn of_object(name: &str, channel: &str) -> bool {
    name.strip_prefix("object.").and_then(|n| n.rsplit_once('.')).is_some_and(|(c, _)| c == channel)
}

/// Writes point `img`'s layers of every object (`channels`, in object order) to `scratch`:
/// one record per object, then one of the layers of no object (`combined`).
pub fn spill_point(scratch: &Scratch, img: &PointImages, channels: &[String]) -> Result<Vec<Span>> {
    let n = (img.width * img.height) as usize;
    let mut spans = channels
        .iter()
        .map(|c| {
            let layers: Vec<&LayerImage> =
                img.layers.iter().filter(|l| of_object(&l.name, c)).collect();
            scratch.put(&object_record(&layers, n))
        })
        .collect::<Result<Vec<_>>>()?;
    let shared: Vec<&LayerImage> =
        img.layers.iter().filter(|l| !channels.iter().any(|c| of_object(&l.name, c))).collect();
    spans.push(scratch.put(&object_record(&shared, n))?);
    Ok(spans)
}

/// An object's layers over the pixels where one of them is not zero (by bits: -0 is kept):
/// the layers' names and channels, the pixels, then each plane at those pixels.
fn object_record(layers: &[&LayerImage], n: usize) -> Vec<u8> {
    let pixels: Vec<u32> = (0..n)
        .filter(|&k| layers.iter().flat_map(|l| &l.planes).any(|p| p[k].to_bits() != 0))
        .map(|k| k as u32)
        .collect();
    let mut w = Writer::default();
    w.u32(layers.len() as u32);
    for l in layers {
        w.str(&l.name);
        w.u32(l.channels.len() as u32);
        l.channels.iter().for_each(|c| w.str(c));
    }
    w.u32s(&pixels);
    for p in layers.iter().flat_map(|l| &l.planes) {
        w.f32s(&pixels.iter().map(|&k| p[k as usize]).collect::<Vec<_>>());
    }
    w.0
}

fn read_object(bytes: &[u8], width: u32, height: u32) -> Result<PointImages> {
    let n = width as usize * height as usize;
    let mut r = Reader::new(bytes);
    let count = r.u32()? as usize;
    let mut layers = Vec::new();
    for _ in 0..count.min(bytes.len()) {
        let name = r.str()?;
        let c = r.u32()? as usize;
        let channels = (0..c.min(bytes.len())).map(|_| r.str()).collect::<Result<Vec<_>>>()?;
        layers.push(LayerImage { name, channels, width, height, planes: Vec::new() });
    }
    let pixels = r.u32s()?;
    if pixels.iter().any(|&k| k as usize >= n) {
        bail!("a scratch image names a pixel outside {width}x{height}");
    }
    for l in &mut layers {
        for _ in 0..l.channels.len() {
            let values = r.f32s()?;
            if values.len() != pixels.len() {
                bail!("a scratch image has {} values for {} pixels", values.len(), pixels.len());
            }
            let mut plane = vec![0.0f32; n];
            pixels.iter().zip(&values).for_each(|(&k, &v)| plane[k as usize] = v);
            l.planes.push(plane);
        }
    }
    r.done()?;
    Ok(PointImages { width, height, layers })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn layer(name: &str, channels: &[&str], values: impl Fn(usize, usize) -> f32) -> LayerImage {
        let mut l = LayerImage::new(name.to_string(), channels, 4, 3);
        for (c, p) in l.planes.iter_mut().enumerate() {
            p.iter_mut().enumerate().for_each(|(k, v)| *v = values(c, k));
        }
        l
    }

    #[test]
    fn a_spilled_object_reads_its_layers_bit_for_bit() {
        let img = PointImages {
            width: 4,
            height: 3,
            layers: vec![
                layer("combined", &["R", "G", "B"], |c, k| (c + k) as f32),
                layer("object.a.coverage", &["A"], |_, k| if k % 3 == 0 { 1.0 } else { 0.0 }),
                layer("object.a.diffuse", &["R", "G", "B"], |c, k| {
                    if k % 3 == 0 {
                        0.1 * (c + 1) as f32
                    } else if k == 4 {
                        -0.0
                    } else {
                        0.0
                    }
                }),
                layer("object.a.b.diffuse", &["R", "G", "B"], |c, k| (c * k) as f32 * 0.5),
            ],
        };
        let dir = tempfile::tempdir().unwrap();
        let scratch = Arc::new(Scratch::create(&dir.path().join("s")).unwrap());
        let channels = vec!["a".to_string(), "a.b".to_string(), "none".to_string()];
        let spans = spill_point(&scratch, &img, &channels).unwrap();
        let held = SetImages::Held(vec![img.clone()]);
        let spilled = SetImages::Spilled { scratch, width: 4, height: 3, spans: vec![spans] };
        assert_eq!(spilled.points(), 1);
        for (o, c) in channels.iter().enumerate() {
            let (h, s) = (held.object(0, o).unwrap(), spilled.object(0, o).unwrap());
            let names: Vec<&str> = s.layers.iter().map(|l| l.name.as_str()).collect();
            let want: Vec<&str> = img
                .layers
                .iter()
                .filter(|l| of_object(&l.name, c))
                .map(|l| l.name.as_str())
                .collect();
            assert_eq!(names, want, "object {c}: its layers only");
            for l in &s.layers {
                let hl = h.layer(&l.name).unwrap();
                assert_eq!(l.channels, hl.channels);
                for (a, b) in l.planes.iter().flatten().zip(hl.planes.iter().flatten()) {
                    assert_eq!(a.to_bits(), b.to_bits(), "{}", l.name);
                }
            }
        }
        let shared = spilled.shared(0).unwrap();
        assert_eq!(shared.layers.len(), 1);
        assert!(
            shared.layers[0]
                .planes
                .iter()
                .flatten()
                .zip(img.layers[0].planes.iter().flatten())
                .all(|(a, b)| a.to_bits() == b.to_bits()),
            "combined comes back whole"
        );
        assert!(held.shared(0).unwrap().layer("combined").is_some());
        assert!(spilled.object(1, 0).is_err() && spilled.object(0, 4).is_err());
    }
}
