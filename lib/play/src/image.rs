//! Float images read back from the GPU, and their comparison.

/// An RGBA f32 image, rows from the top.
#[derive(Clone, Debug, PartialEq)]
pub struct FloatImage {
    pub width: u32,
    pub height: u32,
    pub rgba: Vec<f32>,
}

impl FloatImage {
    /// RGBA of pixel `p = y · width + x`.
    pub fn pixel(&self, p: usize) -> [f32; 4] {
        [self.rgba[4 * p], self.rgba[4 * p + 1], self.rgba[4 * p + 2], self.rgba[4 * p + 3]]
    }
}
