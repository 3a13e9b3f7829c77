//! Surface textures as the container stores them (thesis 3.2, 3.6): each block's texture
//! placed by its branch cuts, affine map and used size; level images hold level 0, and the
//! player rebuilds the MIP chain by decimation.

use std::collections::BTreeMap;

use pis_compile::TextureLayout;
use pis_format::DepMask;

use super::mesh::Placed;
use super::model::LayerForm;

/// A surface texture layer as stored: every block's texture placed as thesis 3.2 places it
/// (branch cuts, affine map, used size); level images hold level 0 and the player rebuilds
/// the MIP chain by decimation (3.6).
pub struct TextureForm {
    /// The placements of the object (the layer's blocks index into them).
    pub placements: Vec<Placed>,
    /// Per block of the layer's grid, its placement.
    pub block_placements: Vec<usize>,
    /// Per sample key, its block's placement.
    pub placement_of: BTreeMap<Vec<u32>, usize>,
    /// 3 (RGB), or 4: premultiplied RGB and the opacity of a translucent object.
    pub channels: usize,
}

impl TextureForm {
    fn layout(&self, key: &[u32]) -> TextureLayout {
        self.placements[self.placement_of[key]].layout
    }
}

impl LayerForm for TextureForm {
    fn layer(
        &self,
        kind: pis_format::LayerKind,
        order: u8,
        depends_on: DepMask,
        gamma: f32,
    ) -> pis_format::Layer {
        surface_layer(kind, order, depends_on, gamma, self.channels as u8)
    }

    fn block(&self, b: usize) -> pis_format::Block {
        let placed = &self.placements[self.block_placements[b]];
        pis_format::Block {
            width: placed.layout.width,
            height: placed.layout.height,
            placement: pis_format::Placement::Surface {
                affine: placed.transform.values,
                repeat: placed.repeat,
                cut: placed.transform.cut,
            },
            levels: vec![],
        }
    }

    fn stored(&self, key: &[u32], solved: &[f32]) -> Vec<f32> {
        finest(self.layout(key), solved, self.channels)
    }

    fn drawn(&self, key: &[u32], stored: Vec<f32>) -> Vec<f32> {
        mip_chain(self.layout(key), stored, self.channels)
    }

    fn stored_texels(&self, key: &[u32]) -> usize {
        let l = self.layout(key);
        l.width as usize * l.height as usize
    }

    fn channels(&self) -> usize {
        self.channels
    }
}

fn surface_layer(
    kind: pis_format::LayerKind,
    order: u8,
    depends_on: DepMask,
    gamma: f32,
    channels: u8,
) -> pis_format::Layer {
    pis_format::Layer {
        kind,
        mapping: pis_format::Mapping::Surface,
        channels,
        mip_mode: pis_format::MipMode::Decimated,
        term: pis_format::Term::Surface,
        order,
        combine: pis_format::Combine::Add,
        basis: 0,
        gamma,
        depends_on,
        blocks: vec![],
    }
}

/// The finest level of a solved texture of layout `layout`, `c` channels (the chain's
/// level 0).
pub fn finest(layout: pis_compile::TextureLayout, x: &[f32], c: usize) -> Vec<f32> {
    x[..layout.width as usize * layout.height as usize * c].to_vec()
}

/// The MIP chain of layout `l` from the finest level, by decimation (thesis 3.6).
pub fn mip_chain(l: pis_compile::TextureLayout, finest: Vec<f32>, c: usize) -> Vec<f32> {
    let mut x = finest.clone();
    let mut cur = finest;
    for lv in 1..l.levels {
        let (w, h) = l.level_size(lv - 1);
        cur = pis_format::mip::decimate(&cur, w, h, c as u32);
        x.extend_from_slice(&cur);
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two placements: 8×4 and 5×3 texels, each with its full MIP chain.
    fn form() -> TextureForm {
        let placed = |w, h| Placed {
            transform: pis_compile::TextureTransform::IDENTITY,
            layout: TextureLayout::full(w, h),
            repeat: [false; 2],
            reduction: 1.0,
        };
        TextureForm {
            placements: vec![placed(8, 4), placed(5, 3)],
            block_placements: vec![0, 1],
            placement_of: BTreeMap::from([(vec![0], 0), (vec![1], 1)]),
            channels: 3,
        }
    }

    #[test]
    fn a_texture_layer_stores_level_0_and_draws_the_decimated_chain() {
        let f = form();
        for (key, (w, h)) in [(vec![0u32], (8usize, 4usize)), (vec![1], (5, 3))] {
            let layout = f.placements[f.placement_of[&key]].layout;
            let finest: Vec<f32> = (0..w * h * 3).map(|i| (i % 7) as f32 * 0.1).collect();
            let chain = mip_chain(layout, finest.clone(), 3);
            assert_eq!(chain.len(), layout.texel_count() * 3, "the whole chain is drawn");
            assert_eq!(f.stored_texels(&key), w * h);
            assert_eq!(f.stored(&key, &chain), finest, "level images hold level 0 only");
            assert_eq!(
                f.drawn(&key, f.stored(&key, &chain)),
                chain,
                "the player's decimation rebuilds the chain"
            );
        }
    }

    #[test]
    fn a_texture_layer_describes_each_block_by_its_placement() {
        let f = form();
        let b = f.block(1);
        assert_eq!((b.width, b.height), (5, 3));
        assert!(
            matches!(b.placement, pis_format::Placement::Surface { .. }) && b.levels.is_empty()
        );
        let l = f.layer(pis_format::LayerKind::Diffuse, 0, DepMask::of(&[0]), 2.2);
        assert_eq!(
            (l.mapping, l.mip_mode, l.channels),
            (pis_format::Mapping::Surface, pis_format::MipMode::Decimated, 3)
        );
    }
}
