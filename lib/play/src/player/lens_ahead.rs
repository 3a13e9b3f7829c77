//! Lens objects traced ahead (thesis 6.4.1): for the frames the caller expects next
//! ([`super::Player::prefetch`]), each lens object's vertex rays are traced and its
//! tessellation refined on a thread of its own while the frame draws, so that a frame whose
//! transform, eye, projection, size and τ were predicted takes its tessellation ready made
//! instead of tracing on its critical path. A tessellation made ahead is the one the frame
//! would make: the same function of the same inputs.

use std::thread::JoinHandle;

use pis_compile::hybrid::{tessellate_timed, HybridView, Tessellation, TessellationSettings};

use super::objects::{Placed, TessellationKey};

/// A tessellation being made for a predicted frame: the lens object's draw index, what it
/// is made for, and the thread making it.
struct Job {
    draw: usize,
    key: TessellationKey,
    thread: JoinHandle<Tessellation>,
}

/// The tessellations being made ahead.
#[derive(Default)]
pub(super) struct LensAhead {
    jobs: Vec<Job>,
    /// Jobs whose frame was no longer expected: dropped (their threads finish unread).
    dropped: u64,
}

/// What a predicted frame's lens object needs traced: its draw index and the tessellation
/// key (the object's transform first).
pub(super) type LensRequest = (usize, TessellationKey);

impl LensAhead {
    /// Makes ahead the tessellations of `wanted` (in order): those already being made are
    /// kept, those no longer wanted dropped, the others started on threads of their own,
    /// with the object and tracer `place(draw, transform)` gives and its tessellation
    /// settings.
    pub(super) fn start(
        &mut self,
        wanted: &[LensRequest],
        place: impl Fn(usize, glam::Mat4) -> Option<(Placed, TessellationSettings)>,
    ) {
        let before = self.jobs.len();
        self.jobs.retain(|j| wanted.contains(&(j.draw, j.key)));
        self.dropped += (before - self.jobs.len()) as u64;
        for &(draw, key) in wanted {
            if self.jobs.iter().any(|j| (j.draw, j.key) == (draw, key)) {
                continue;
            }
            let Some(((lens, tracer), settings)) = place(draw, key.0) else { continue };
            let view = HybridView { eye: key.1, clip_from_world: key.2, size: key.3 };
            let thread = std::thread::Builder::new()
                .name("pis-lens-ahead".into())
                .spawn(move || tessellate_timed(&lens, &view, &settings, tracer.as_ref()).0);
            // Without a thread the frame traces its lens objects itself.
            if let Ok(thread) = thread {
                self.jobs.push(Job { draw, key, thread });
            }
        }
    }

    /// The tessellation made ahead for lens object `draw` at `key`, waiting for it if it is
    /// still being made; `None` where none was started (or its thread failed).
    pub(super) fn take(&mut self, draw: usize, key: &TessellationKey) -> Option<Tessellation> {
        let i = self.jobs.iter().position(|j| j.draw == draw && j.key == *key)?;
        self.jobs.swap_remove(i).thread.join().ok()
    }

    /// Tessellations dropped so far because their frame was no longer expected.
    pub(super) fn dropped(&self) -> u64 {
        self.dropped
    }
}
