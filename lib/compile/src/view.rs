//! One view of an object as the solver reads it: its render matrix and the ray-traced pixels
//! the texture should reproduce there. Shared by the solver ([`crate::solve`]) and the
//! view-by-view assembly of a view-independent solve ([`crate::stacked`]).

use crate::RenderMatrix;

/// Colour channels per texel and per pixel (RGB, interleaved).
pub const CHANNELS: usize = 3;

/// One view's render matrix and its ray-traced pixels (`rows × 3`, interleaved RGB).
#[derive(Clone, Copy, Debug)]
pub struct View<'a> {
    pub a: &'a RenderMatrix,
    pub b: &'a [f32],
}
