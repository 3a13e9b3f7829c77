use super::*;

fn planes() -> Vec<PlaneShape> {
    vec![
        PlaneShape::new(5, 3, 3),
        PlaneShape::new(3, 2, 4),
        PlaneShape::new(1, 1, 1),
    ]
}

fn values(n: usize) -> Vec<f32> {
    // Smooth data with a few special bit patterns that a lossy path would not keep.
    let mut v: Vec<f32> = (0..n)
        .map(|i| (i as f32 * 0.37).sin() * 3.0 + 0.25)
        .collect();
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
    let v: Vec<f32> = (0..64 * 64 * 3)
        .map(|i| ((i / 3) % 64) as f32 / 64.0)
        .collect();
    let bytes = encode(CodecId::Lossless, &p, &v).unwrap();
    assert!(
        bytes.len() * 4 < v.len() * 4,
        "{} bytes for {} values",
        bytes.len(),
        v.len()
    );
}

#[test]
fn raw_round_trips_and_checks_length() {
    let p = planes();
    let v = values(value_count(&p).unwrap());
    let bytes = encode(CodecId::Raw, &p, &v).unwrap();
    assert_eq!(bytes.len(), v.len() * 4);
    assert_eq!(decode(CodecId::Raw, &p, &bytes).unwrap(), v);
    assert!(matches!(
        decode(CodecId::Raw, &p, &bytes[1..]),
        Err(CodecError::DecodedLength { .. })
    ));
}

#[test]
fn lossless_rejects_damaged_streams() {
    let p = planes();
    let v = values(value_count(&p).unwrap());
    let bytes = encode(CodecId::Lossless, &p, &v).unwrap();
    for cut in 0..bytes.len() {
        assert!(
            decode(CodecId::Lossless, &p, &bytes[..cut]).is_err(),
            "truncated at {cut}"
        );
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
        Err(CodecError::Length {
            expected: 2,
            found: 1
        })
    );
}

#[test]
fn reserved_codecs_say_not_supported() {
    for c in [CodecId::Wavelet, CodecId::Dct] {
        assert_eq!(decode(c, &planes(), &[]), Err(CodecError::NotSupported(c)));
        assert!(!c.is_supported());
    }
    for c in CodecId::ALL {
        assert_eq!(CodecId::from_code(c.code()), Some(c));
    }
    assert_eq!(CodecId::from_code(99), None);
}
