//! Memory before work: what a traced point and a whole set take in memory, and what the
//! machine has, so that a resolution or a set too large fails at once with the figures
//! rather than aborting on allocation hours in.

use pis_scene::ObjectRole;

use crate::layers::LayerKind;

/// Bytes of memory this machine has available (Linux: `MemAvailable` of /proc/meminfo);
/// `None` where it cannot tell.
pub fn available_memory() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib.saturating_mul(1024))
}

/// Bytes of the largest resident memory this process has had so far (Linux: `VmHWM` of
/// /proc/self/status); `None` where it cannot tell.
pub fn peak_resident() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = text.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib.saturating_mul(1024))
}

/// Float channels of one point's images: `combined` and every object's layers for its role
/// (a lens model of `lens_terms` terms).
pub fn point_channels(roles: impl IntoIterator<Item = ObjectRole>, lens_terms: usize) -> u64 {
    3 + roles
        .into_iter()
        .map(|r| {
            LayerKind::for_role(r, lens_terms)
                .iter()
                .map(|l| l.channels().len() as u64)
                .sum::<u64>()
        })
        .sum::<u64>()
}

/// Bytes of `channels` float images of `width`×`height` pixels, `copies` times.
pub fn image_bytes(width: u32, height: u32, channels: u64, copies: u64) -> u64 {
    (width as u64)
        .saturating_mul(height as u64)
        .saturating_mul(channels)
        .saturating_mul(4)
        .saturating_mul(copies)
}

/// `bytes` as GiB with two decimals.
pub fn gib(bytes: u64) -> String {
    format!("{:.2} GiB", bytes as f64 / (1u64 << 30) as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_point_holds_combined_and_each_objects_layers() {
        // combined RGB + diffuse object: coverage A, diffuse RGB, specular RGB
        assert_eq!(point_channels([ObjectRole::Diffuse], 2), 3 + 7);
        assert_eq!(image_bytes(640, 480, 10, 1), 640 * 480 * 10 * 4);
        assert_eq!(
            image_bytes(u32::MAX, u32::MAX, u64::MAX, 3),
            u64::MAX,
            "saturates, never wraps"
        );
    }
}
