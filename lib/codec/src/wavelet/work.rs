//! The decoder's working memory, kept per thread between calls: the significance state and
//! the per-channel arrays of a large level image would otherwise be fresh pages, faulted in
//! and returned to the system again on every call (a player decodes one level image after
//! another on the same few threads).

use std::cell::RefCell;

use super::bitplane::CoefficientState;

/// Bytes of working memory a thread keeps after a decode; a larger one is freed.
const KEEP_BYTES: usize = 32 << 20;

/// Buffers whose contents do not carry over: each decode sizes and clears what it uses.
#[derive(Default)]
pub struct Work {
    /// The bit-plane decoder's state, 6 bytes per coefficient.
    pub coefficients: CoefficientState,
    /// Every (plane, channel) array, one after another.
    pub arrays: Vec<f32>,
    /// The lifting's row and column buffer.
    pub tmp: Vec<f32>,
}

impl Work {
    fn bytes(&self) -> usize {
        self.coefficients.bytes() + 4 * (self.arrays.capacity() + self.tmp.capacity())
    }
}

thread_local! {
    static WORK: RefCell<Work> = RefCell::new(Work::default());
}

/// Runs `f` with this thread's working memory.
pub fn with_work<R>(f: impl FnOnce(&mut Work) -> R) -> R {
    WORK.with(|cell| match cell.try_borrow_mut() {
        Ok(mut work) => {
            let out = f(&mut work);
            if work.bytes() > KEEP_BYTES {
                *work = Work::default();
            }
            out
        }
        // Already in use further up this thread's stack: a fresh one.
        Err(_) => f(&mut Work::default()),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn memory_is_kept_up_to_the_limit_only() {
        with_work(|w| w.arrays.resize(1000, 1.0));
        assert!(with_work(|w| w.arrays.capacity()) >= 1000);
        with_work(|w| w.arrays.resize(KEEP_BYTES / 4 + 1, 0.0));
        assert_eq!(with_work(|w| w.arrays.capacity()), 0);
    }

    #[test]
    fn a_nested_call_gets_its_own() {
        with_work(|outer| {
            outer.tmp.push(1.0);
            with_work(|inner| assert!(inner.tmp.is_empty()));
        });
    }
}
