//! A shell layer as stored (SPEC.md 7.1, 7.3, 8.3): a cube map per sample, every MIP level
//! inferred and stored (mip mode `stored`: level images hold the finest level and each
//! coarser level's residual from the decimated finest, thesis 5.8.1), on the shell its
//! blocks name; composited "over" in its term in its order (0 nearest).

use pis_compile::shell::Shell;
use pis_compile::TextureLayout;
use pis_format::DepMask;

use super::super::model::LayerForm;

/// One shell layer's form: every block holds the same shell and cube layout.
pub struct ShellForm {
    pub shell: Shell,
    pub layout: TextureLayout,
    /// Lookups per pixel side the shell was solved through (SPEC.md 8.2).
    pub lookups: u32,
    /// 4 (premultiplied RGBA: a local shell) or 3 (opaque RGB).
    pub channels: u8,
    /// Order within its term (0 is nearest).
    pub order: u8,
    /// The term the shell is looked up in: the reflection term of a reflective object, the
    /// refraction term of a lens object (whose reflection term reads the same shells, SPEC.md 9).
    pub term: pis_format::Term,
}

impl LayerForm for ShellForm {
    fn layer(
        &self,
        kind: pis_format::LayerKind,
        _order: u8,
        depends_on: DepMask,
        gamma: f32,
    ) -> pis_format::Layer {
        pis_format::Layer {
            kind,
            mapping: pis_format::Mapping::Shell,
            channels: self.channels,
            mip_mode: pis_format::MipMode::Stored,
            term: self.term,
            order: self.order,
            combine: pis_format::Combine::Over,
            basis: 0,
            gamma,
            depends_on,
            blocks: vec![],
        }
    }

    fn block(&self, _b: usize) -> pis_format::Block {
        let (id, v) = self.shell.placement_values();
        let shape = match id {
            1 => pis_format::ShellShape::Sphere,
            2 => pis_format::ShellShape::Ellipsoid,
            3 => pis_format::ShellShape::Box,
            6 => pis_format::ShellShape::Depth,
            _ => pis_format::ShellShape::Cylinder,
        };
        let mut params = [0.0f32; 6];
        params.copy_from_slice(&v[3..9]);
        pis_format::Block {
            width: self.layout.width,
            height: self.layout.height,
            placement: pis_format::Placement::Shell {
                shape,
                origin: [v[0], v[1], v[2]],
                params,
                lookups: self.lookups,
            },
            levels: vec![],
        }
    }

    /// Every level of every face, as solved.
    fn stored(&self, _key: &[u32], solved: &[f32]) -> Vec<f32> {
        solved.to_vec()
    }

    fn drawn(&self, _key: &[u32], stored: Vec<f32>) -> Vec<f32> {
        stored
    }

    fn stored_texels(&self, _key: &[u32]) -> usize {
        self.layout.texel_count()
    }

    fn channels(&self) -> usize {
        self.channels as usize
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;
    use pis_compile::shell::ShellShape;

    #[test]
    fn a_shell_layer_is_stored_whole_on_its_shell() {
        let shell = Shell {
            origin: DVec3::new(0.5, 1.0, -2.0),
            shape: ShellShape::Ellipsoid { radii: DVec3::new(1.0, 2.0, 3.0) },
        };
        let f = ShellForm {
            shell,
            layout: TextureLayout::cube(8),
            lookups: 2,
            channels: 4,
            order: 0,
            term: pis_format::Term::Reflection,
        };
        let l = f.layer(pis_format::LayerKind::EnvLocal, 3, DepMask::of(&[0]), 1.0);
        assert_eq!(
            (l.mapping, l.mip_mode, l.term, l.combine, l.channels, l.order),
            (
                pis_format::Mapping::Shell,
                pis_format::MipMode::Stored,
                pis_format::Term::Reflection,
                pis_format::Combine::Over,
                4,
                0
            )
        );
        let b = f.block(0);
        assert_eq!((b.width, b.height), (8, 8));
        match b.placement {
            pis_format::Placement::Shell { shape, origin, params, lookups } => {
                assert_eq!(lookups, 2);
                assert_eq!(shape, pis_format::ShellShape::Ellipsoid);
                assert_eq!(origin, [0.5, 1.0, -2.0]);
                assert_eq!(params, [1.0, 2.0, 3.0, 0.0, 0.0, 0.0]);
            }
            _ => panic!("a shell placement"),
        }
        let x: Vec<f32> = (0..f.stored_texels(&[0]) * 4).map(|i| i as f32).collect();
        assert_eq!(f.drawn(&[0], f.stored(&[0], &x)), x);
    }
}
