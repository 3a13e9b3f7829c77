//! Video codecs through the `ffmpeg` command: x265 (HEVC) and libaom (AV1), 8-bit 4:2:0
//! (yuv420p, BT.601 limited range: ffmpeg's default conversion from and back to RGB),
//! encoded at a constant rate factor that is searched to meet a byte budget.
//!
//! Frames go in as 8-bit sRGB display values (rgb24), sides padded by repeating the last
//! row or column to even sizes of at least 16 (4:2:0 and x265's smallest picture), and come back cropped. Byte counts are
//! those of the elementary stream (raw HEVC Annex B, AV1 low-overhead OBUs): no container,
//! and x265 writes no SEI with its settings (`info=0`).

use std::io::{Read, Write};
use std::process::{Command, Stdio};

use anyhow::{anyhow, bail, Context, Result};
use rayon::prelude::*;

/// A video encoder ffmpeg provides.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VideoCodec {
    /// HEVC with libx265 (`-x265-params crf=…`, medium preset).
    X265,
    /// AV1 with libaom (`-crf … -b:v 0`, cpu-used 6).
    Av1,
}

impl VideoCodec {
    pub fn name(self) -> &'static str {
        match self {
            VideoCodec::X265 => "x265",
            VideoCodec::Av1 => "av1",
        }
    }

    /// ffmpeg's encoder.
    pub fn encoder(self) -> &'static str {
        match self {
            VideoCodec::X265 => "libx265",
            VideoCodec::Av1 => "libaom-av1",
        }
    }

    fn format(self) -> &'static str {
        match self {
            VideoCodec::X265 => "hevc",
            VideoCodec::Av1 => "obu",
        }
    }

    /// The constant-rate-factor range (best quality first) and whether it is integral.
    fn quality_range(self) -> (f64, f64, bool) {
        match self {
            VideoCodec::X265 => (0.0, 51.0, false),
            VideoCodec::Av1 => (0.0, 63.0, true),
        }
    }

    /// The settings, for reports.
    pub fn settings(self) -> &'static str {
        match self {
            VideoCodec::X265 => "libx265 medium preset, CRF searched, 8-bit yuv420p",
            VideoCodec::Av1 => "libaom-av1 cpu-used 6, CRF searched (-b:v 0), 8-bit yuv420p",
        }
    }
}

/// A sequence of frames: 8-bit sRGB display values, rgb24, row-major, top row first.
#[derive(Clone, Debug)]
pub struct Frames {
    pub width: u32,
    pub height: u32,
    pub count: usize,
    pub rgb: Vec<u8>,
}

impl Frames {
    fn frame_len(&self) -> usize {
        self.width as usize * self.height as usize * 3
    }

    /// Bytes of the raw frames (3 per pixel).
    pub fn raw_bytes(&self) -> usize {
        self.rgb.len()
    }

    /// The frames at the coded size (last row and column repeated).
    fn padded(&self) -> (u32, u32, Vec<u8>) {
        let (w, h) = coded_size(self.width, self.height);
        if (w, h) == (self.width, self.height) {
            return (w, h, self.rgb.clone());
        }
        let mut out = Vec::with_capacity(w as usize * h as usize * 3 * self.count);
        for f in 0..self.count {
            let frame = &self.rgb[f * self.frame_len()..(f + 1) * self.frame_len()];
            for y in 0..h {
                let sy = y.min(self.height - 1) as usize;
                let row = &frame[sy * self.width as usize * 3..(sy + 1) * self.width as usize * 3];
                out.extend_from_slice(row);
                for _ in self.width..w {
                    out.extend_from_slice(&row[row.len() - 3..]);
                }
            }
        }
        (w, h, out)
    }
}

/// The size frames are coded at: even sides (4:2:0) of at least 16 pixels (x265's smallest
/// picture).
pub fn coded_size(width: u32, height: u32) -> (u32, u32) {
    let side = |v: u32| (v + v % 2).max(16);
    (side(width), side(height))
}

/// Checks that ffmpeg runs and has `codec`'s encoder; the error says what is missing.
pub fn available(codec: VideoCodec) -> Result<()> {
    let out = Command::new("ffmpeg")
        .args(["-hide_banner", "-encoders"])
        .output()
        .map_err(|e| anyhow!("ffmpeg is not installed or not on PATH ({e})"))?;
    let list = String::from_utf8_lossy(&out.stdout);
    if !list.lines().any(|l| l.split_whitespace().nth(1) == Some(codec.encoder())) {
        bail!("this ffmpeg has no {} encoder", codec.encoder());
    }
    Ok(())
}

/// Runs ffmpeg with `args`, `input` on stdin, and returns stdout.
fn ffmpeg(args: &[String], input: Vec<u8>) -> Result<Vec<u8>> {
    let mut child = Command::new("ffmpeg")
        .args(["-hide_banner", "-loglevel", "error"])
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .context("starting ffmpeg")?;
    let mut stdin = child.stdin.take().ok_or_else(|| anyhow!("ffmpeg stdin"))?;
    let writer = std::thread::spawn(move || stdin.write_all(&input));
    let mut stdout = Vec::new();
    child.stdout.take().ok_or_else(|| anyhow!("ffmpeg stdout"))?.read_to_end(&mut stdout)?;
    let mut stderr = String::new();
    child.stderr.take().ok_or_else(|| anyhow!("ffmpeg stderr"))?.read_to_string(&mut stderr)?;
    let status = child.wait()?;
    let _ = writer.join();
    if !status.success() {
        bail!("ffmpeg {} failed ({status}): {}", args.join(" "), stderr.trim());
    }
    Ok(stdout)
}

/// Encodes `frames` at constant rate factor `crf`; returns the elementary stream.
pub fn encode(frames: &Frames, codec: VideoCodec, crf: f64) -> Result<Vec<u8>> {
    let (w, h, rgb) = frames.padded();
    let mut args: Vec<String> = [
        "-f",
        "rawvideo",
        "-pix_fmt",
        "rgb24",
        "-s",
        &format!("{w}x{h}"),
        "-r",
        "25",
        "-i",
        "-",
        "-c:v",
        codec.encoder(),
        "-pix_fmt",
        "yuv420p",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    match codec {
        VideoCodec::X265 => {
            args.extend(["-x265-params".into(), format!("crf={crf:.2}:info=0:log-level=error")])
        }
        VideoCodec::Av1 => args.extend(
            [
                "-crf",
                &format!("{}", crf.round() as i64),
                "-b:v",
                "0",
                "-cpu-used",
                "6",
                "-row-mt",
                "1",
            ]
            .iter()
            .map(|s| s.to_string()),
        ),
    }
    args.extend(["-f".to_string(), codec.format().to_string(), "-".to_string()]);
    ffmpeg(&args, rgb)
}

/// Decodes an elementary stream of `codec` back to rgb24 frames of `width`×`height`.
pub fn decode(
    stream: &[u8],
    codec: VideoCodec,
    width: u32,
    height: u32,
    count: usize,
) -> Result<Frames> {
    let args: Vec<String> =
        ["-f", codec.format(), "-i", "-", "-f", "rawvideo", "-pix_fmt", "rgb24", "-"]
            .iter()
            .map(|s| s.to_string())
            .collect();
    let out = ffmpeg(&args, stream.to_vec())?;
    let (pw, ph) = coded_size(width, height);
    let frame = pw as usize * ph as usize * 3;
    if out.len() != frame * count {
        bail!("{} decoded {} bytes, expected {count} frames of {pw}x{ph}", codec.name(), out.len());
    }
    let mut rgb = Vec::with_capacity(width as usize * height as usize * 3 * count);
    for f in 0..count {
        for y in 0..height as usize {
            let start = f * frame + y * pw as usize * 3;
            rgb.extend_from_slice(&out[start..start + width as usize * 3]);
        }
    }
    Ok(Frames { width, height, count, rgb })
}

/// Videos encoded at one rate factor chosen to meet a byte budget.
#[derive(Clone, Debug)]
pub struct Matched {
    pub crf: f64,
    pub streams: Vec<Vec<u8>>,
    /// Total bytes of every stream.
    pub bytes: usize,
    pub budget: usize,
    /// False when even the coarsest rate factor spends more than the budget.
    pub reached: bool,
    pub encodes: usize,
}

fn encode_all(videos: &[Frames], codec: VideoCodec, crf: f64) -> Result<Vec<Vec<u8>>> {
    videos.par_iter().map(|v| encode(v, codec, crf)).collect()
}

/// Encodes every video at one common rate factor (one quality for all: equal slopes, as
/// an encoder's own rate control would aim for), the finest rate factor whose total bytes
/// stay within `budget`, found by bisection (x265: to 0.05 CRF or within 5 % below the
/// budget; AV1: the integer CRF).
pub fn encode_to_budget(videos: &[Frames], codec: VideoCodec, budget: usize) -> Result<Matched> {
    let (mut lo, mut hi, integral) = codec.quality_range();
    let total = |s: &[Vec<u8>]| s.iter().map(Vec::len).sum::<usize>();
    let mut encodes = 0;
    let coarsest = encode_all(videos, codec, hi)?;
    encodes += 1;
    if total(&coarsest) > budget {
        return Ok(Matched {
            crf: hi,
            bytes: total(&coarsest),
            streams: coarsest,
            budget,
            reached: false,
            encodes,
        });
    }
    let mut best = (hi, coarsest);
    loop {
        let done = if integral { hi - lo <= 1.0 } else { hi - lo <= 0.05 };
        if done {
            break;
        }
        let mid = if integral { ((lo + hi) / 2.0).floor() } else { (lo + hi) / 2.0 };
        let s = encode_all(videos, codec, mid)?;
        encodes += 1;
        let bytes = total(&s);
        if bytes <= budget {
            hi = mid;
            let close = bytes as f64 >= 0.95 * budget as f64;
            best = (mid, s);
            if close {
                break;
            }
        } else {
            lo = mid;
        }
    }
    if integral && lo == 0.0 && best.0 == 1.0 {
        let s = encode_all(videos, codec, 0.0)?;
        encodes += 1;
        if total(&s) <= budget {
            best = (0.0, s);
        }
    }
    let bytes = total(&best.1);
    Ok(Matched { crf: best.0, streams: best.1, bytes, budget, reached: true, encodes })
}
