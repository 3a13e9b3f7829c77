//! The stats panel's figures: frame rate over the last second of wall-clock time, per-frame
//! times smoothed exponentially, and upload throughput over a sliding window.

use std::collections::VecDeque;

/// One frame's figures as the window measured them.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FrameSample {
    /// Wall-clock seconds since the meter started, when the frame was presented.
    pub at_s: f64,
    /// Time the player spent on the frame.
    pub frame_ms: f64,
    /// Decoding part of it (waiting for the workers).
    pub decode_ms: f64,
    /// Uploading textures and level images, and the GPU's rebuilds from level images.
    pub upload_ms: f64,
    pub rebuild_ms: f64,
    /// Bytes uploaded to the GPU for the frame.
    pub upload_bytes: u64,
    /// Bytes in the decode cache after the frame.
    pub cache_bytes: u64,
    /// Whether the frame waited on decoding (`FrameStats::decode_waits` > 0).
    pub waited: bool,
}

/// What the panel shows.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Shown {
    pub fps: f64,
    pub frame_ms: f64,
    pub decode_ms: f64,
    pub upload_ms: f64,
    pub rebuild_ms: f64,
    /// The longest frame of the window (ms).
    pub worst_ms: f64,
    pub cache_mb: f64,
    pub upload_mb_s: f64,
    /// Frames of the window that waited on decoding, and frames in it.
    pub waited: (usize, usize),
}

/// Smooths per-frame figures for display.
#[derive(Clone, Debug)]
pub struct StatsMeter {
    /// Length of the window that fps and upload throughput are measured over.
    window_s: f64,
    /// Weight of the newest frame in the exponential averages.
    alpha: f64,
    recent: VecDeque<FrameSample>,
    shown: Shown,
    frames: u64,
}

impl StatsMeter {
    /// A meter over a `window_s`-second window whose averages forget with weight `alpha`.
    pub fn new(window_s: f64, alpha: f64) -> StatsMeter {
        StatsMeter {
            window_s,
            alpha: alpha.clamp(0.0, 1.0),
            recent: VecDeque::new(),
            shown: Shown::default(),
            frames: 0,
        }
    }

    pub fn add(&mut self, s: FrameSample) {
        let ema = |old: f64, new: f64| {
            if self.frames == 0 {
                new
            } else {
                old + self.alpha * (new - old)
            }
        };
        self.shown.frame_ms = ema(self.shown.frame_ms, s.frame_ms);
        self.shown.decode_ms = ema(self.shown.decode_ms, s.decode_ms);
        self.shown.upload_ms = ema(self.shown.upload_ms, s.upload_ms);
        self.shown.rebuild_ms = ema(self.shown.rebuild_ms, s.rebuild_ms);
        self.shown.cache_mb = s.cache_bytes as f64 / 1e6;
        self.frames += 1;
        self.recent.push_back(s);
        while self.recent.front().is_some_and(|f| s.at_s - f.at_s > self.window_s) {
            self.recent.pop_front();
        }
        // n frames presented over the time between the first and the last: n - 1 intervals.
        let (first, n) = (self.recent.front().map_or(s.at_s, |f| f.at_s), self.recent.len());
        self.shown.waited = (self.recent.iter().filter(|f| f.waited).count(), n);
        self.shown.worst_ms = self.recent.iter().map(|f| f.frame_ms).fold(0.0, f64::max);
        let span = s.at_s - first;
        if n >= 2 && span > 0.0 {
            self.shown.fps = (n - 1) as f64 / span;
            let bytes: u64 = self.recent.iter().skip(1).map(|f| f.upload_bytes).sum();
            self.shown.upload_mb_s = bytes as f64 / 1e6 / span;
        }
    }

    pub fn shown(&self) -> Shown {
        self.shown
    }

    /// Frames added so far.
    pub fn frames(&self) -> u64 {
        self.frames
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(at_s: f64, frame_ms: f64, upload_bytes: u64) -> FrameSample {
        FrameSample {
            at_s,
            frame_ms,
            decode_ms: frame_ms / 2.0,
            upload_ms: frame_ms / 4.0,
            rebuild_ms: frame_ms / 8.0,
            upload_bytes,
            cache_bytes: 3_000_000,
            waited: false,
        }
    }

    #[test]
    fn fps_and_throughput_over_the_window() {
        let mut m = StatsMeter::new(1.0, 0.1);
        for i in 0..=40 {
            m.add(frame(i as f64 * 0.05, 10.0, 500_000));
        }
        let s = m.shown();
        assert!((s.fps - 20.0).abs() < 1e-9, "{s:?}");
        assert!((s.upload_mb_s - 10.0).abs() < 1e-9, "{s:?}");
        assert_eq!(s.cache_mb, 3.0);
    }

    #[test]
    fn frames_that_waited_are_counted_over_the_window() {
        let mut m = StatsMeter::new(1.0, 0.1);
        for i in 0..30 {
            m.add(FrameSample { waited: i % 10 == 0, ..frame(i as f64 * 0.1, 10.0, 0) });
        }
        // The window holds the frames less than a second older than the last (2.0 to
        // 2.9 s; 1.9 is a second and a rounding before it): 2.0 waited.
        assert_eq!(m.shown().waited, (1, 10));
    }

    #[test]
    fn the_worst_frame_is_the_windows_longest() {
        let mut m = StatsMeter::new(1.0, 0.1);
        m.add(frame(0.0, 80.0, 0));
        for i in 1..=20 {
            m.add(frame(i as f64 * 0.1, if i == 15 { 40.0 } else { 10.0 }, 0));
        }
        // The 80 ms frame has left the window; the 40 ms one is in it.
        let s = m.shown();
        assert_eq!(s.worst_ms, 40.0);
        assert!((s.upload_ms - s.frame_ms / 4.0).abs() < 1e-9, "{s:?}");
    }

    #[test]
    fn averages_follow_a_step_exponentially() {
        let mut m = StatsMeter::new(1.0, 0.5);
        m.add(frame(0.0, 10.0, 0));
        assert_eq!(m.shown().frame_ms, 10.0, "the first frame is taken as is");
        m.add(frame(0.1, 20.0, 0));
        assert_eq!(m.shown().frame_ms, 15.0);
        m.add(frame(0.2, 20.0, 0));
        assert_eq!((m.shown().frame_ms, m.shown().decode_ms), (17.5, 8.75));
    }

    #[test]
    fn a_pause_drops_old_frames_from_the_rate() {
        let mut m = StatsMeter::new(1.0, 0.1);
        for i in 0..10 {
            m.add(frame(i as f64 * 0.01, 1.0, 0));
        }
        m.add(frame(5.0, 1.0, 0));
        m.add(frame(5.5, 1.0, 0));
        assert!((m.shown().fps - 2.0).abs() < 1e-9, "{:?}", m.shown());
        assert_eq!(m.frames(), 12);
    }
}
