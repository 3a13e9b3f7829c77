use crate::CodecError;

/// The shape of one plane of a level image.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct PlaneShape {
    pub width: u32,
    pub height: u32,
    /// 1 to 4 interleaved channels.
    pub channels: u32,
}

impl PlaneShape {
    pub fn new(width: u32, height: u32, channels: u32) -> Self {
        PlaneShape { width, height, channels }
    }
}

/// Total number of values in `planes`, with every product checked. Planes must be non-empty
/// and have 1 to 4 channels.
pub fn value_count(planes: &[PlaneShape]) -> Result<usize, CodecError> {
    let mut total: usize = 0;
    for p in planes {
        let bad = || CodecError::Shape { width: p.width, height: p.height, channels: p.channels };
        if p.width == 0 || p.height == 0 || !(1..=4).contains(&p.channels) {
            return Err(bad());
        }
        let n = (p.width as usize)
            .checked_mul(p.height as usize)
            .and_then(|v| v.checked_mul(p.channels as usize))
            .ok_or_else(bad)?;
        total = total.checked_add(n).ok_or_else(bad)?;
    }
    // Keep byte counts representable (4 bytes per value).
    if total > usize::MAX / 4 {
        return Err(CodecError::Length { expected: usize::MAX / 4, found: total });
    }
    Ok(total)
}
