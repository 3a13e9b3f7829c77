//! Encode and decode throughput of the level-image codecs on a 512×512 RGB float texture
//! (smooth shading plus fine noise, like an inferred texture), the lossless ratio, and the
//! rate–distortion of the lossy codecs (PSNR for a peak of 1.0) with their decode speed at
//! each rate. Run: cargo bench -p pis-codec

use std::time::Instant;

use pis_codec::{decode, encode, encode_with, mse, psnr, wavelet, CodecId, PlaneShape, Rate};

fn texture(w: u32, h: u32) -> Vec<f32> {
    let mut seed = 0x1234_5678_u32;
    let mut v = Vec::with_capacity((w * h * 3) as usize);
    for y in 0..h {
        for x in 0..w {
            let (u, t) = (x as f32 / w as f32, y as f32 / h as f32);
            let base = 0.5 + 0.4 * (6.0 * u).sin() * (4.0 * t).cos();
            for c in 0..3 {
                seed ^= seed << 13;
                seed ^= seed >> 17;
                seed ^= seed << 5;
                let noise = (seed % 1000) as f32 / 1000.0 * 0.01;
                v.push(base * (0.8 + 0.1 * c as f32) + noise);
            }
        }
    }
    v
}

/// Sharp edges without noise: 13-texel checker squares (not aligned with 8×8 blocks) over a
/// radial gradient, as a
/// textured surface with a highlight might give.
fn edges(w: u32, h: u32) -> Vec<f32> {
    let mut v = Vec::with_capacity((w * h * 3) as usize);
    for y in 0..h {
        for x in 0..w {
            let check = if ((x + 5) / 13 + (y + 3) / 13) % 2 == 0 { 0.2 } else { 0.7 };
            let (dx, dy) = (x as f32 / w as f32 - 0.4, y as f32 / h as f32 - 0.6);
            let glow = 0.5 * (-(dx * dx + dy * dy) * 20.0).exp();
            for c in 0..3 {
                v.push(check * (0.7 + 0.15 * c as f32) + glow);
            }
        }
    }
    v
}

fn main() {
    let (w, h) = (512, 512);
    let planes = [PlaneShape::new(w, h, 3)];
    let values = texture(w, h);
    let mb = (values.len() * 4) as f64 / 1e6;
    println!("codec       ratio   encode MB/s   decode MB/s   (512x512 RGB f32, {mb:.2} MB)");
    for codec in CodecId::ALL {
        let reps = if codec == CodecId::Raw { 50 } else { 5 };
        let t = Instant::now();
        let mut bytes = Vec::new();
        for _ in 0..reps {
            bytes = encode(codec, &planes, &values).expect("encode");
        }
        let enc = t.elapsed().as_secs_f64() / reps as f64;
        let t = Instant::now();
        for _ in 0..reps {
            let back = decode(codec, &planes, &bytes).expect("decode");
            assert_eq!(back.len(), values.len());
        }
        let dec = t.elapsed().as_secs_f64() / reps as f64;
        println!(
            "{:<10} {:>6.2} {:>13.0} {:>13.0}",
            codec.name(),
            (values.len() * 4) as f64 / bytes.len() as f64,
            mb / enc,
            mb / dec
        );
    }

    for (name, values) in [("smooth + noise", values), ("edges", edges(w, h))] {
        println!();
        println!("rate-distortion on '{name}' (decode MB/s of decoded f32 at that rate; PSNR for peak 1.0)");
        println!("target ratio   wavelet bytes  PSNR dB  dec MB/s    dct bytes  PSNR dB  dec MB/s");
        let full =
            wavelet::encode_full(&planes, &values, wavelet::DEFAULT_LEVELS, wavelet::DEFAULT_BITS)
                .expect("encode");
        for ratio in [16usize, 48, 96, 192, 384, 768] {
            let budget = values.len() * 4 / ratio;
            let w = full.truncated(budget, &planes);
            let (wp, ws) = measure(CodecId::Wavelet, &planes, &values, w, mb);
            let d =
                encode_with(CodecId::Dct, &planes, &values, Rate::Bytes(budget)).expect("encode");
            let (dp, ds) = measure(CodecId::Dct, &planes, &values, &d, mb);
            println!(
                "{ratio:>12} {:>14} {wp:>8.2} {ws:>9.0} {:>12} {dp:>8.2} {ds:>9.0}",
                w.len(),
                d.len()
            );
        }
    }
}

/// PSNR and decode speed of one codestream.
fn measure(
    codec: CodecId,
    planes: &[PlaneShape],
    values: &[f32],
    bytes: &[u8],
    mb: f64,
) -> (f64, f64) {
    if bytes.is_empty() {
        return (f64::NAN, f64::NAN);
    }
    let reps = 5;
    let t = Instant::now();
    let mut back = Vec::new();
    for _ in 0..reps {
        back = decode(codec, planes, bytes).expect("decode");
    }
    let secs = t.elapsed().as_secs_f64() / reps as f64;
    (psnr(mse(values, &back), 1.0), mb / secs)
}
