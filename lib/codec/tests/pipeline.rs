//! A block of textures through the whole library: adaptive pyramid, one wavelet encode per
//! level image, equal-slope allocation of a byte budget, truncation, decoding and the
//! SPEC.md 8.4 reconstruction. The allocation's predicted error must match what decoding
//! gives.

use pis_codec::allocate::{allocate, Item, Target, DEFAULT_ALPHA};
use pis_codec::pyramid::{adaptive, l1_cost, level_image_index, Pyramid, PyramidFilter};
use pis_codec::wavelet;
use pis_codec::{decode, encode_with, mse, psnr, CodecId, PlaneShape, Rate};

const W: u32 = 32;
const H: u32 = 24;

/// A texture lit from a light that moves along dimension 0 and seen from a view that moves
/// along dimension 1 (a highlight that slides), as a parameterized texture would be.
fn sample(a: u32, b: u32) -> Vec<f32> {
    let mut v = Vec::new();
    for y in 0..H {
        for x in 0..W {
            let (u, t) = (x as f32 / W as f32, y as f32 / H as f32);
            let diffuse = 0.3 + 0.2 * (5.0 * u + 0.1 * a as f32).sin() * (3.0 * t).cos();
            let hx = 0.2 + 0.08 * b as f32;
            let spec = 0.6 * (-((u - hx).powi(2) + (t - 0.5).powi(2)) * 60.0).exp();
            for c in 0..3 {
                v.push(diffuse * (0.9 + 0.05 * c as f32) + spec);
            }
        }
    }
    v
}

fn unflatten(i: usize, extent: &[u32]) -> Vec<u32> {
    vec![(i / extent[1] as usize) as u32, (i % extent[1] as usize) as u32]
}

/// Packs the block at `ratio`:1 with `codec` and returns (measured PSNR, predicted PSNR,
/// bytes spent, budget, the pyramid).
fn pack(codec: CodecId, ratio: usize) -> (f64, f64, usize, usize, Pyramid) {
    let extent = [8u32, 8];
    let samples: Vec<Vec<f32>> = (0..64)
        .map(|i| {
            let l = unflatten(i, &extent);
            sample(l[0], l[1])
        })
        .collect();
    let planes = [PlaneShape::new(W, H, 3)];
    let (pyramid, _) = adaptive(&extent, &samples, PyramidFilter::Gaussian, l1_cost).unwrap();

    // Per level image: its curve (wavelet: one encode, decoded at 16 cuts; dct: measured at
    // several qualities) and its weight in the block's MSE.
    let mut encoded = Vec::new();
    let mut items = Vec::new();
    for level in &pyramid.levels {
        let covered = 64 / level.images.len().max(1);
        for img in &level.images {
            let curve = if codec == CodecId::Wavelet {
                let e = wavelet::encode_full(&planes, img, 5, 16).unwrap();
                let c = e.measured_curve(&planes, img, 16).unwrap();
                encoded.push(Some(e));
                c
            } else {
                encoded.push(None);
                pis_codec::codec(codec).unwrap().rd_curve(&planes, img).unwrap()
            };
            items.push(Item { curve, object: 0, weight: covered as f64 / 64.0 });
        }
    }
    let raw: usize = samples.iter().map(|s| s.len() * 4).sum();
    let budget = raw / ratio;
    let alloc = allocate(&items, &[1.0], Target::Bytes(budget), Some(DEFAULT_ALPHA)).unwrap();
    assert!(alloc.total_bytes <= budget);

    // Encode what the allocation grants, decode, and rebuild every finest sample.
    let mut k = 0;
    let mut spent = 0;
    let mut decoded = pyramid.clone();
    for level in &mut decoded.levels {
        for img in &mut level.images {
            let stream = match &encoded[k] {
                Some(e) => e.truncated(alloc.bytes[k], &planes).to_vec(),
                None => encode_with(codec, &planes, img, Rate::Bytes(alloc.bytes[k])).unwrap(),
            };
            spent += stream.len();
            *img = decode(codec, &planes, &stream).unwrap();
            k += 1;
        }
    }
    assert!(spent <= budget);
    let mut err = 0.0;
    for (i, s) in samples.iter().enumerate() {
        err += mse(s, &decoded.sample(&unflatten(i, &extent)));
    }
    err /= 64.0;
    (psnr(err, 1.0), psnr(alloc.screen_mse, 1.0), spent, budget, pyramid)
}

#[test]
fn pyramid_allocation_and_decoding_agree() {
    for codec in [CodecId::Wavelet, CodecId::Dct] {
        for ratio in [100, 200] {
            let (measured, predicted, spent, budget, pyramid) = pack(codec, ratio);
            eprintln!(
                "{codec} {ratio}:1 levels {:?}: {spent} bytes of {budget}, measured {measured:.2} dB, predicted {predicted:.2} dB",
                pyramid.levels.iter().map(|l| l.counts.clone()).collect::<Vec<_>>(),
            );
            assert!(
                (measured - predicted).abs() < 1.5,
                "{codec}: measured {measured:.2} dB, predicted {predicted:.2} dB"
            );
            assert!(measured > 30.0, "{codec}: {measured:.2} dB at {ratio}:1");
            check_levels(&pyramid);
        }
    }
}

fn check_levels(p: &Pyramid) {
    assert_eq!(p.levels[0].images.len(), 1);
    let finest = p.levels.last().unwrap();
    assert_eq!(finest.counts, p.extent);
    for level in &p.levels {
        let n: u32 = level.counts.iter().product();
        assert_eq!(level.images.len(), n as usize);
        assert_eq!(level_image_index(&level.counts, &[7, 7], &p.extent), n as usize - 1);
    }
}
