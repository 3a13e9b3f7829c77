//! What a file's textures take in memory once decoded, computed from `LAYR` alone (no
//! codestream read), so that a tool refuses a file it cannot hold before it allocates:
//! SPEC.md section 12 lets a valid file of a few hundred KB declare level images of
//! 16384 × 16384 texels (4 GiB each as `f32` with a stored MIP chain). The player checks one
//! frame's needs against its cache budget and the adapter ([`crate::Player::open`]); pis-diff
//! and pis-reencode check what they hold at once against their memory budgets.

use pis_format::{Container, LevelLayout, Mapping, MipMode};

/// One parameter block of one layer, and the bytes its decoded images take.
#[derive(Clone, Debug, PartialEq)]
pub struct BlockBytes {
    pub object: usize,
    pub layer: usize,
    pub block: usize,
    /// What the block is, for messages: "object 'NAME' layer L (KIND) block B: a W×H RGB
    /// texture, its MIP chain stored".
    pub name: String,
    pub width: u32,
    pub height: u32,
    pub mapping: Mapping,
    /// One level image (every plane: faces and stored MIP levels), `f32`; one rebuilt
    /// texture (a sample's linear values) takes as many.
    pub image: u64,
    /// Pyramid levels: the images on one sample's pyramid path.
    pub levels: u64,
    /// Every level image of the block.
    pub images: u64,
    /// Samples of the block (the product of its extent).
    pub samples: u64,
}

impl BlockBytes {
    /// The level images on one sample's pyramid path (what one texture decodes from).
    pub fn path(&self) -> u64 {
        self.image.saturating_mul(self.levels)
    }

    /// Every level image of the block.
    pub fn all_images(&self) -> u64 {
        self.image.saturating_mul(self.images)
    }

    /// Every sample's rebuilt texture.
    pub fn all_textures(&self) -> u64 {
        self.image.saturating_mul(self.samples)
    }
}

/// Every block of every layer of `c`, in file order.
pub fn blocks<S>(c: &Container<S>) -> Vec<BlockBytes> {
    let mut out = Vec::new();
    for (oi, o) in c.objects.iter().enumerate() {
        for (li, l) in o.layers.iter().enumerate() {
            for (bi, b) in l.blocks.iter().enumerate() {
                let layout = LevelLayout::of(l, b);
                let values: u64 = layout
                    .planes()
                    .iter()
                    .map(|p| p.width as u64 * p.height as u64 * p.channels as u64)
                    .sum();
                let colour = if l.channels == 4 { "RGBA" } else { "RGB" };
                let shape = match (l.mapping, l.mip_mode) {
                    (Mapping::Shell, MipMode::Stored) => ", cube faces with MIP chains stored",
                    (Mapping::Shell, MipMode::Decimated) => ", cube faces",
                    (Mapping::Surface, MipMode::Stored) => ", its MIP chain stored",
                    (Mapping::Surface, MipMode::Decimated) => "",
                };
                let samples = b
                    .levels
                    .last()
                    .map_or(1, |lv| lv.counts.iter().map(|&c| c as u64).product::<u64>().max(1));
                out.push(BlockBytes {
                    object: oi,
                    layer: li,
                    block: bi,
                    name: format!(
                        "object '{}' layer {li} ({}) block {bi}: a {}×{} {colour} texture{shape}",
                        o.name,
                        l.kind.name(),
                        b.width,
                        b.height
                    ),
                    width: b.width,
                    height: b.height,
                    mapping: l.mapping,
                    image: values.saturating_mul(4),
                    levels: b.levels.len() as u64,
                    images: b.levels.iter().map(|lv| lv.images.len() as u64).sum(),
                    samples,
                });
            }
        }
    }
    out
}

/// `bytes` in the largest binary unit that keeps it at 1 or more, one decimal ("4.0 GiB",
/// "512.0 MiB").
pub fn size(bytes: u64) -> String {
    const UNITS: [&str; 5] = ["bytes", "KiB", "MiB", "GiB", "TiB"];
    let mut v = bytes as f64;
    let mut u = 0;
    // 1023.95 and above would print as 1024.0 of the smaller unit.
    while v >= 1023.95 && u + 1 < UNITS.len() {
        v /= 1024.0;
        u += 1;
    }
    if u == 0 {
        format!("{bytes} bytes")
    } else {
        format!("{v:.1} {}", UNITS[u])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_read_in_binary_units() {
        assert_eq!(size(12), "12 bytes");
        assert_eq!(size(512 << 20), "512.0 MiB");
        assert_eq!(size((1 << 32) - 4), "4.0 GiB");
        assert_eq!(size((1 << 30) - 4), "1.0 GiB");
        assert_eq!(size(1023), "1023 bytes");
    }

    #[test]
    fn the_worked_example_is_one_small_image() {
        let c = pis_format::samples::minimal().unwrap();
        let b = blocks(&c);
        assert_eq!(b.len(), 1);
        assert_eq!(b[0].image, 2 * 2 * 3 * 4);
        assert_eq!((b[0].levels, b[0].images, b[0].samples), (1, 1, 1));
        assert!(b[0].name.contains("object 'quad' layer 0 (diffuse) block 0: a 2×2 RGB texture"));
    }
}
