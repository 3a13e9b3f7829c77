//! A block of textures through the whole library: adaptive pyramid, one wavelet encode per
//! level image, equal-slope allocation of a byte budget, truncation, decoding and the
//! SPEC.md 8.4 reconstruction. The allocation's predicted error must match what decoding
//! gives.

use pis_codec::allocate::{allocate, Item, Target, DEFAULT_ALPHA};
use pis_codec::pyramid::{adaptive, l1_cost, level_image_index, Pyramid, PyramidFilter};
use pis_codec::wavelet;
use pis_codec::{decode, mse, psnr, CodecId, PlaneShape, RdCurve};

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
    vec![
        (i / extent[1] as usize) as u32,
        (i % extent[1] as usize) as u32,
    ]
}

#[test]
fn pyramid_allocation_and_decoding_agree() {
    let extent = [8u32, 8];
    let samples: Vec<Vec<f32>> = (0..64)
        .map(|i| {
            let l = unflatten(i, &extent);
            sample(l[0], l[1])
        })
        .collect();
    let planes = [PlaneShape::new(W, H, 3)];
    let (pyramid, _) = adaptive(&extent, &samples, PyramidFilter::Gaussian, l1_cost).unwrap();

    // One encode per level image; its measured curve; its weight in the block's MSE.
    let mut encoded = Vec::new();
    let mut items = Vec::new();
    for level in &pyramid.levels {
        let covered = 64 / level.images.len().max(1);
        for img in &level.images {
            let e = wavelet::encode_full(&planes, img, 5, 16).unwrap();
            let curve: RdCurve = e.measured_curve(&planes, img, 16).unwrap();
            items.push(Item {
                curve,
                object: 0,
                weight: covered as f64 / 64.0,
            });
            encoded.push(e);
        }
    }
    let raw: usize = samples.iter().map(|s| s.len() * 4).sum();
    let budget = raw / 200;
    let alloc = allocate(&items, &[1.0], Target::Bytes(budget), Some(DEFAULT_ALPHA)).unwrap();
    assert!(alloc.total_bytes <= budget);

    // Decode what the allocation keeps and rebuild every finest sample.
    let mut k = 0;
    let mut decoded = pyramid.clone();
    for level in &mut decoded.levels {
        for img in &mut level.images {
            let stream = encoded[k].truncated(alloc.bytes[k], &planes);
            *img = decode(CodecId::Wavelet, &planes, stream).unwrap();
            k += 1;
        }
    }
    let mut err = 0.0;
    for (i, s) in samples.iter().enumerate() {
        err += mse(s, &decoded.sample(&unflatten(i, &extent)));
    }
    err /= 64.0;
    let (measured, predicted) = (psnr(err, 1.0), psnr(alloc.screen_mse, 1.0));
    assert!(
        (measured - predicted).abs() < 1.5,
        "measured {measured:.2} dB, predicted {predicted:.2} dB"
    );
    eprintln!(
        "levels {:?}: {} bytes of {budget}, measured {measured:.2} dB, predicted {predicted:.2} dB",
        pyramid
            .levels
            .iter()
            .map(|l| l.counts.clone())
            .collect::<Vec<_>>(),
        alloc.total_bytes
    );
    assert!(measured > 30.0, "{measured:.2} dB at 200:1");
    check_levels(&pyramid);
}

fn check_levels(p: &Pyramid) {
    assert_eq!(p.levels[0].images.len(), 1);
    let finest = p.levels.last().unwrap();
    assert_eq!(finest.counts, p.extent);
    for level in &p.levels {
        let n: u32 = level.counts.iter().product();
        assert_eq!(level.images.len(), n as usize);
        assert_eq!(
            level_image_index(&level.counts, &[7, 7], &p.extent),
            n as usize - 1
        );
    }
}
