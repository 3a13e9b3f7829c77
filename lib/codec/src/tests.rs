use super::*;

fn planes() -> Vec<PlaneShape> {
    vec![PlaneShape::new(5, 3, 3), PlaneShape::new(3, 2, 4), PlaneShape::new(1, 1, 1)]
}

fn values(n: usize) -> Vec<f32> {
    // Smooth data with a few special bit patterns that a lossy path would not keep.
    let mut v: Vec<f32> = (0..n).map(|i| (i as f32 * 0.37).sin() * 3.0 + 0.25).collect();
    v[1] = -0.0;
    v[4] = f32::MIN_POSITIVE / 8.0; // subnormal
    v[7] = 1.0e30;
    v
}

#[test]
fn lossless_round_trips_every_bit() {
    let p = planes();
    let v = values(value_count(&p).unwrap());
    let bytes = encode(CodecId::Lossless, &p, &v).unwrap();
    let back = decode(CodecId::Lossless, &p, &bytes).unwrap();
    let a: Vec<u32> = v.iter().map(|x| x.to_bits()).collect();
    let b: Vec<u32> = back.iter().map(|x| x.to_bits()).collect();
    assert_eq!(a, b);
}

#[test]
fn lossless_compresses_smooth_data() {
    let p = [PlaneShape::new(64, 64, 3)];
    let v: Vec<f32> = (0..64 * 64 * 3).map(|i| ((i / 3) % 64) as f32 / 64.0).collect();
    let bytes = encode(CodecId::Lossless, &p, &v).unwrap();
    assert!(bytes.len() * 4 < v.len() * 4, "{} bytes for {} values", bytes.len(), v.len());
}

#[test]
fn raw_round_trips_and_checks_length() {
    let p = planes();
    let v = values(value_count(&p).unwrap());
    let bytes = encode(CodecId::Raw, &p, &v).unwrap();
    assert_eq!(bytes.len(), v.len() * 4);
    assert_eq!(decode(CodecId::Raw, &p, &bytes).unwrap(), v);
    assert!(matches!(decode(CodecId::Raw, &p, &bytes[1..]), Err(CodecError::DecodedLength { .. })));
}

#[test]
fn lossless_rejects_damaged_streams() {
    let p = planes();
    let v = values(value_count(&p).unwrap());
    let bytes = encode(CodecId::Lossless, &p, &v).unwrap();
    for cut in 0..bytes.len() {
        assert!(decode(CodecId::Lossless, &p, &bytes[..cut]).is_err(), "truncated at {cut}");
    }
    // A stream for other shapes decodes to the wrong length.
    let small = [PlaneShape::new(2, 2, 1)];
    assert!(matches!(
        decode(CodecId::Lossless, &small, &bytes),
        Err(CodecError::DecodedLength { .. })
    ));
}

#[test]
fn forged_huge_shape_does_not_allocate_its_size() {
    // 16384² × 4 channels would be 4 GiB; the stream holds 10 bytes, so decoding fails
    // after inflating what is there.
    let p = [PlaneShape::new(16384, 16384, 4)];
    let stream = encode(CodecId::Lossless, &[PlaneShape::new(1, 1, 1)], &[1.0]).unwrap();
    assert!(decode(CodecId::Lossless, &p, &stream).is_err());
    assert!(decode(CodecId::Raw, &p, &stream).is_err());
}

#[test]
fn shapes_are_checked() {
    assert!(value_count(&[PlaneShape::new(0, 4, 3)]).is_err());
    assert!(value_count(&[PlaneShape::new(4, 4, 5)]).is_err());
    assert!(value_count(&[PlaneShape::new(u32::MAX, u32::MAX, 4); 8]).is_err());
    assert_eq!(
        encode(CodecId::Raw, &[PlaneShape::new(2, 1, 1)], &[1.0]),
        Err(CodecError::Length { expected: 2, found: 1 })
    );
}

#[test]
fn every_codec_is_registered_under_its_id() {
    for c in CodecId::ALL {
        assert!(c.is_supported());
        assert_eq!(codec(c).map(|k| k.id()), Some(c));
        assert_eq!(CodecId::from_code(c.code()), Some(c));
    }
    assert_eq!(CodecId::from_code(99), None);
}

/// `--codec` takes every codec by its name, and a wrong name's error lists them.
#[test]
fn every_codec_parses_by_its_name() {
    for c in CodecId::ALL {
        assert_eq!(c.name().parse::<CodecId>(), Ok(c));
    }
    let err = "jpeg".parse::<CodecId>().unwrap_err().to_string();
    assert_eq!(err, r#"unknown codec "jpeg" (raw, lossless, wavelet, dct)"#);
}

/// A smooth float texture with noise, signed (like a pyramid residual) when `offset` is 0.
fn texture(w: u32, h: u32, c: u32, offset: f32) -> Vec<f32> {
    let mut seed = 0x9E37_79B9_u32;
    let mut v = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let (u, t) = (x as f32 / w as f32, y as f32 / h as f32);
            let base = 0.4 * (6.0 * u).sin() * (4.0 * t).cos();
            for k in 0..c {
                seed ^= seed << 13;
                seed ^= seed >> 17;
                seed ^= seed << 5;
                let noise = (seed % 1000) as f32 / 1000.0 * 0.02 - 0.01;
                v.push(offset + base * (0.8 + 0.1 * k as f32) + noise);
            }
        }
    }
    v
}

#[test]
fn lossy_codecs_round_trip_closely() {
    for (w, h, c, offset) in
        [(64, 48, 3, 0.5), (37, 21, 4, 0.0), (5, 3, 1, -2.0), (1, 1, 3, 1.0), (9, 1, 3, 0.0)]
    {
        let p = [PlaneShape::new(w, h, c)];
        let v = texture(w, h, c, offset);
        for id in [CodecId::Wavelet, CodecId::Dct] {
            let bytes = encode_with(id, &p, &v, Rate::Quality(100)).unwrap();
            let back = decode(id, &p, &bytes).unwrap();
            let e = mse(&v, &back);
            assert!(e < 1e-5, "{id} {w}x{h}x{c}: mse {e}");
        }
    }
}

#[test]
fn lossy_codecs_handle_several_planes() {
    let p = planes();
    let v = values(value_count(&p).unwrap())
        .into_iter()
        .map(|x| x.clamp(-4.0, 4.0))
        .collect::<Vec<_>>();
    for id in [CodecId::Wavelet, CodecId::Dct] {
        let bytes = encode_with(id, &p, &v, Rate::Quality(100)).unwrap();
        let back = decode(id, &p, &bytes).unwrap();
        assert!(mse(&v, &back) < 1e-3, "{id}: {}", mse(&v, &back));
    }
}

#[test]
fn lossy_codecs_refuse_non_finite_input() {
    let p = [PlaneShape::new(2, 1, 1)];
    for id in [CodecId::Wavelet, CodecId::Dct] {
        assert!(matches!(encode(id, &p, &[1.0, f32::NAN]), Err(CodecError::Input(_))));
    }
}

#[test]
fn wavelet_every_truncation_decodes_to_lower_quality() {
    let p = [PlaneShape::new(23, 17, 3)];
    let v = texture(23, 17, 3, 0.3);
    let e = wavelet::encode_full(&p, &v, 5, 12).unwrap();
    let hl = wavelet::header_len(&p);
    let mut last = f64::INFINITY;
    for cut in (0..=e.bytes.len()).filter(|&c| c == 0 || c >= hl) {
        let back = decode(CodecId::Wavelet, &p, &e.bytes[..cut]).unwrap();
        assert_eq!(back.len(), v.len());
        let m = mse(&v, &back);
        // Not strictly monotone byte by byte (a refinement can overshoot), but the trend is.
        assert!(m <= last * 1.5 + 1e-9, "cut {cut}: {m} after {last}");
        last = last.min(m);
        let predicted = e.curve.mse_at(cut);
        assert!(
            m < 2.0 * predicted + 1e-7 && predicted < 2.0 * m + 1e-7,
            "cut {cut}: measured {m}, curve {predicted}"
        );
    }
    for cut in 1..hl {
        assert!(decode(CodecId::Wavelet, &p, &e.bytes[..cut]).is_err());
    }
}

#[test]
fn wavelet_byte_budget_is_hit_exactly() {
    let p = [PlaneShape::new(64, 64, 3)];
    let v = texture(64, 64, 3, 0.5);
    let full = encode(CodecId::Wavelet, &p, &v).unwrap();
    for budget in [0, 40, 100, 1000, 3000] {
        let s = encode_with(CodecId::Wavelet, &p, &v, Rate::Bytes(budget)).unwrap();
        assert_eq!(s.len(), budget.min(full.len()));
        assert_eq!(&full[..s.len()], &s[..]);
    }
}

#[test]
fn wavelet_curve_decreases_and_matches_the_codec() {
    let p = [PlaneShape::new(64, 64, 3)];
    let v = texture(64, 64, 3, 0.5);
    let curve = codec(CodecId::Wavelet).unwrap().rd_curve(&p, &v).unwrap();
    assert!(curve.points.len() > 10);
    assert!(curve.points.windows(2).all(|w| w[0].bytes < w[1].bytes && w[0].mse > w[1].mse));
    let full = encode(CodecId::Wavelet, &p, &v).unwrap();
    for pt in &curve.points {
        let back = decode(CodecId::Wavelet, &p, &full[..pt.bytes]).unwrap();
        assert_eq!(mse(&v, &back), pt.mse);
    }
}

#[test]
fn dct_budget_and_quality_order() {
    let p = [PlaneShape::new(40, 24, 3)];
    let v = texture(40, 24, 3, 0.5);
    let mut prev = (0usize, f64::INFINITY);
    for q in [10, 50, 90] {
        let s = encode_with(CodecId::Dct, &p, &v, Rate::Quality(q)).unwrap();
        let m = mse(&v, &decode(CodecId::Dct, &p, &s).unwrap());
        assert!(s.len() > prev.0 && m < prev.1, "q {q}: {} bytes, mse {m}", s.len());
        prev = (s.len(), m);
    }
    let s = encode_with(CodecId::Dct, &p, &v, Rate::Bytes(300)).unwrap();
    assert!(s.len() <= 300 && !s.is_empty());
    assert!(encode_with(CodecId::Dct, &p, &v, Rate::Bytes(5)).unwrap().is_empty());
    let curve = codec(CodecId::Dct).unwrap().rd_curve(&p, &v).unwrap();
    assert!(curve.points.len() > 5);
}

#[test]
fn dct_rejects_truncation() {
    let p = [PlaneShape::new(20, 12, 3)];
    let v = texture(20, 12, 3, 0.0);
    let s = encode(CodecId::Dct, &p, &v).unwrap();
    for cut in 1..s.len() {
        assert!(decode(CodecId::Dct, &p, &s[..cut]).is_err(), "cut {cut}");
    }
}

#[test]
fn lossy_decoders_survive_random_corruption() {
    let p = [PlaneShape::new(19, 13, 3), PlaneShape::new(10, 7, 3)];
    let v = texture(19, 13, 3, 0.2).into_iter().chain(texture(10, 7, 3, 0.0)).collect::<Vec<_>>();
    let mut seed = 12345u32;
    let mut rnd = move || {
        seed ^= seed << 13;
        seed ^= seed >> 17;
        seed ^= seed << 5;
        seed
    };
    for id in [CodecId::Wavelet, CodecId::Dct] {
        let good = encode(id, &p, &v).unwrap();
        for _ in 0..300 {
            let mut s = good.clone();
            for _ in 0..1 + rnd() % 4 {
                let i = rnd() as usize % s.len();
                s[i] ^= 1 << (rnd() % 8);
            }
            if rnd() % 4 == 0 {
                let keep = rnd() as usize % s.len();
                s.truncate(keep);
            }
            if let Ok(img) = decode(id, &p, &s) {
                assert_eq!(img.len(), v.len());
                assert!(img.iter().all(|x| x.is_finite()));
            }
        }
        // Pure noise.
        for len in [0usize, 3, 20, 200] {
            let s: Vec<u8> = (0..len).map(|_| rnd() as u8).collect();
            let _ = decode(id, &p, &s);
        }
    }
}

#[test]
fn lossy_decoders_with_forged_huge_shape_fail_or_stay_bounded() {
    // A stream for a tiny image given a 4 GiB shape: the DCT decoder runs out of bytes
    // after a few blocks, before allocating the whole image.
    let small = [PlaneShape::new(2, 2, 3)];
    let s = encode(CodecId::Dct, &small, &[0.5; 12]).unwrap();
    let huge = [PlaneShape::new(16384, 16384, 4)];
    assert!(decode(CodecId::Dct, &huge, &s).is_err());
}

#[test]
fn wavelet_truncations_of_mixed_planes_decode() {
    // Planes of 3, 4 and 1 channels (colour transform on some).
    let p = planes();
    let v: Vec<f32> =
        values(value_count(&p).unwrap()).into_iter().map(|x| x.clamp(-4.0, 4.0)).collect();
    let e = wavelet::encode_full(&p, &v, 5, 14).unwrap();
    let hl = wavelet::header_len(&p);
    assert_eq!(hl, 8);
    let full = mse(&v, &decode(CodecId::Wavelet, &p, &e.bytes).unwrap());
    let mut worst_prefix = 0.0f64;
    for cut in hl..=e.bytes.len() {
        let back = decode(CodecId::Wavelet, &p, &e.bytes[..cut]).unwrap();
        assert_eq!(back.len(), v.len());
        worst_prefix = worst_prefix.max(mse(&v, &back));
    }
    assert!(full < 1e-4 && full < worst_prefix, "{full} {worst_prefix}");
}

#[test]
fn zero_images_cost_nothing() {
    let p = [PlaneShape::new(9, 7, 3)];
    let zeros = vec![0.0; 9 * 7 * 3];
    let s = encode(CodecId::Wavelet, &p, &zeros).unwrap();
    assert!(s.is_empty());
    for id in [CodecId::Wavelet, CodecId::Dct] {
        assert_eq!(decode(id, &p, &[]).unwrap(), zeros);
    }
}

#[test]
fn constant_and_offset_images_keep_their_level() {
    let p = [PlaneShape::new(13, 11, 3)];
    let n = 13 * 11 * 3;
    let constant = vec![0.5f32; n];
    let offset: Vec<f32> = (0..n).map(|i| 1000.0 + (i % 7) as f32 * 1e-3).collect();
    // Large DC jumps between blocks: the top rows at +3·10⁴, the rest at −3·10⁴.
    let mixed: Vec<f32> = (0..n).map(|i| if i < n / 3 { 3.0e4 } else { -3.0e4 }).collect();
    for (k, v) in [constant, offset, mixed].into_iter().enumerate() {
        for id in [CodecId::Wavelet, CodecId::Dct] {
            let s = encode_with(id, &p, &v, Rate::Quality(100)).unwrap();
            let back = decode(id, &p, &s).unwrap();
            let peak = v.iter().fold(0.0f32, |m, x| m.max(x.abs())) as f64;
            let rel = mse(&v, &back).sqrt() / peak;
            assert!(rel < 1e-3, "{id} case {k}: relative error {rel}");
            // At the default rate the level (the mean) survives.
            let back = decode(id, &p, &encode(id, &p, &v).unwrap()).unwrap();
            let mean = |x: &[f32]| x.iter().map(|v| *v as f64).sum::<f64>() / x.len() as f64;
            assert!((mean(&v) - mean(&back)).abs() < 1e-2 * peak, "{id} case {k}");
        }
    }
}

#[test]
fn weighted_curves_count_only_the_error_that_is_weighted() {
    // A textured plane whose left half weighs 2 and right half 0: the weighted curve's MSE
    // at every truncation point equals the left half's plain error, and uniform weights of 1
    // give the plain curve.
    let (w, h) = (32u32, 16u32);
    let p = [PlaneShape::new(w, h, 3)];
    let v: Vec<f32> = (0..(w * h * 3) as usize)
        .map(|i| {
            let (x, y) = ((i / 3) as u32 % w, (i / 3) as u32 / w);
            ((x * 7 + y * 3) % 11) as f32 / 11.0 + 0.2 * (i % 3) as f32
        })
        .collect();
    let left: Vec<f32> =
        (0..v.len()).map(|i| if ((i / 3) as u32 % w) < w / 2 { 2.0 } else { 0.0 }).collect();
    let ones = vec![1.0f32; v.len()];
    for id in [CodecId::Wavelet, CodecId::Dct] {
        let c = codec(id).unwrap();
        let plain = c.rd_curve(&p, &v).unwrap();
        let same = c.rd_curve_weighted(&p, &v, Some(&ones)).unwrap();
        assert_eq!(plain.points.len(), same.points.len(), "{id}");
        for (a, b) in plain.points.iter().zip(&same.points) {
            assert_eq!(a.bytes, b.bytes);
            assert!((a.mse - b.mse).abs() <= 1e-12 * a.mse.max(1.0), "{id}: {a:?} {b:?}");
        }
        let weighted = c.rd_curve_weighted(&p, &v, Some(&left)).unwrap();
        let half: Vec<f32> = left.iter().map(|w| w / 2.0).collect();
        let halved = c.rd_curve_weighted(&p, &v, Some(&half)).unwrap();
        let zero = c.rd_curve_weighted(&p, &v, Some(&vec![0.0; v.len()])).unwrap();
        let mut lower = 0;
        for ((a, b), (hp, z)) in
            plain.points.iter().zip(&weighted.points).zip(halved.points.iter().zip(&zero.points))
        {
            // the same truncation points; the error is linear in the weights
            assert_eq!((a.bytes, b.bytes), (hp.bytes, z.bytes), "{id}");
            assert!(
                (b.mse - 2.0 * hp.mse).abs() <= 1e-9 * b.mse.max(1e-9),
                "{id}: {} vs 2 × {}",
                b.mse,
                hp.mse
            );
            assert_eq!(z.mse, 0.0, "{id}");
            // weights 1 on the left half and 0 on the right: never above the plain error
            assert!(hp.mse <= a.mse * (1.0 + 1e-12), "{id}");
            if hp.mse < a.mse {
                lower += 1;
            }
        }
        assert!(lower > 0, "{id}: weighting out half the image lowers the error somewhere");
    }
    // weights of the wrong length or negative are an input error
    let c = codec(CodecId::Wavelet).unwrap();
    assert!(c.rd_curve_weighted(&p, &v, Some(&ones[1..])).is_err());
    let mut neg = ones.clone();
    neg[5] = -1.0;
    assert!(c.rd_curve_weighted(&p, &v, Some(&neg)).is_err());
}

#[test]
fn bytes_after_a_codestreams_data_are_rejected() {
    let p = [PlaneShape::new(19, 13, 3), PlaneShape::new(10, 7, 3)];
    let v: Vec<f32> = texture(19, 13, 3, 0.2).into_iter().chain(texture(10, 7, 3, -0.1)).collect();
    for codec in [CodecId::Lossless, CodecId::Wavelet, CodecId::Dct] {
        let s = encode(codec, &p, &v).unwrap();
        assert!(decode(codec, &p, &s).is_ok(), "{codec}");
        for extra in [&[0u8][..], &[0x5a, 0, 0, 0, 0, 0, 0, 0]] {
            let mut longer = s.clone();
            longer.extend_from_slice(extra);
            assert_eq!(
                decode(codec, &p, &longer),
                Err(CodecError::TrailingBytes { extra: extra.len(), length: longer.len() }),
                "{codec} with {} bytes after its data",
                extra.len()
            );
        }
    }
    // Raw: the length is exactly 4 bytes per value.
    let s = encode(CodecId::Raw, &p, &v).unwrap();
    assert!(decode(CodecId::Raw, &p, &[s.as_slice(), &[0]].concat()).is_err());
    // Wavelet with top bit-plane 255 (every coefficient 0) has no body.
    let zero_header = [wavelet::VERSION, 5, 1, 255, 0, 0, 128, 63];
    assert_eq!(decode(CodecId::Wavelet, &p, &zero_header), Ok(vec![0.0; v.len()]));
    assert!(matches!(
        decode(CodecId::Wavelet, &p, &[&zero_header[..], &[7]].concat()),
        Err(CodecError::TrailingBytes { extra: 1, .. })
    ));
}

#[test]
fn every_prefix_of_a_wavelet_stream_is_read_to_its_end() {
    // A truncated embedded stream has no trailing bytes: the decoder reads all it holds.
    let p = [PlaneShape::new(13, 9, 4)];
    let v = texture(13, 9, 4, 0.3);
    let s = encode(CodecId::Wavelet, &p, &v).unwrap();
    for cut in wavelet::HEADER_LEN..=s.len() {
        assert!(decode(CodecId::Wavelet, &p, &s[..cut]).is_ok(), "cut {cut}");
    }
}

#[test]
fn a_wavelet_codestream_of_more_values_than_its_indices_hold_is_refused_before_allocating() {
    let huge = [PlaneShape::new(65_536, 65_536, 1)];
    let bytes = encode(CodecId::Wavelet, &planes(), &values(70)).unwrap();
    let err = decode(CodecId::Wavelet, &huge, &bytes).unwrap_err();
    assert!(err.to_string().contains("4294967296 values in one codestream"), "{err}");
    assert!(decode(CodecId::Wavelet, &huge, &[]).is_err());
}
