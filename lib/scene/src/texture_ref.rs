//! How a material reads a texture: which texture, through which texture-coordinate set, and
//! KHR_texture_transform's affine map of the coordinates.

use glam::Vec2;

/// A material's reference to one of [`crate::Scene::textures`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TextureRef {
    /// Index into [`crate::Scene::textures`].
    pub texture: usize,
    /// The texture-coordinate set read: 0 (TEXCOORD_0) or 1 (TEXCOORD_1), KHR_texture_transform's
    /// `texCoord` override applied.
    pub tex_coord: u32,
    /// KHR_texture_transform (the identity without it).
    pub transform: UvTransform,
}

impl TextureRef {
    /// Texture `texture` read through TEXCOORD_0, untransformed.
    pub fn new(texture: usize) -> TextureRef {
        TextureRef { texture, tex_coord: 0, transform: UvTransform::IDENTITY }
    }

    /// The coordinate at which the texture is read at a point whose texture-coordinate sets
    /// are `uvs` (TEXCOORD_0, TEXCOORD_1).
    pub fn uv(&self, uvs: [Vec2; 2]) -> Vec2 {
        self.transform.apply(uvs[(self.tex_coord as usize).min(1)])
    }
}

/// KHR_texture_transform: uv' = offset + R · (scale ⊙ uv), where R rotates the UVs by
/// `rotation` radians counter-clockwise in UV space (u right, v down: the image turns
/// clockwise), i.e. u' = cos·u + sin·v, v' = −sin·u + cos·v before the offset.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UvTransform {
    pub offset: [f32; 2],
    /// Radians.
    pub rotation: f32,
    pub scale: [f32; 2],
}

impl UvTransform {
    pub const IDENTITY: UvTransform =
        UvTransform { offset: [0.0; 2], rotation: 0.0, scale: [1.0; 2] };

    /// `uv` transformed.
    #[inline]
    pub fn apply(&self, uv: Vec2) -> Vec2 {
        let s = uv * Vec2::from(self.scale);
        let r = if self.rotation == 0.0 {
            s
        } else {
            let (sin, cos) = self.rotation.sin_cos();
            Vec2::new(cos * s.x + sin * s.y, -sin * s.x + cos * s.y)
        };
        r + Vec2::from(self.offset)
    }
}

impl Default for UvTransform {
    fn default() -> Self {
        UvTransform::IDENTITY
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: Vec2, b: Vec2) -> bool {
        (a - b).abs().max_element() < 1e-6
    }

    #[test]
    fn texture_transform_offsets_and_scales_uvs() {
        let t = UvTransform { offset: [0.25, -0.5], rotation: 0.0, scale: [2.0, 0.5] };
        assert!(close(t.apply(Vec2::new(0.5, 1.0)), Vec2::new(1.25, 0.0)));
        assert!(close(UvTransform::IDENTITY.apply(Vec2::new(0.3, 0.7)), Vec2::new(0.3, 0.7)));
        // A texCoord override picks the set; a missing second set is the caller's to fill.
        let r = TextureRef { texture: 0, tex_coord: 1, transform: t };
        assert!(close(r.uv([Vec2::ZERO, Vec2::new(0.5, 1.0)]), Vec2::new(1.25, 0.0)));
    }

    /// The KHR_texture_transform specification's example: offset (0, 1), rotation π/2 and
    /// scale ½ read the lower-left quadrant of the image, turned clockwise by 90°.
    #[test]
    fn texture_transform_rotation_follows_the_specification_example() {
        let t = UvTransform {
            offset: [0.0, 1.0],
            rotation: std::f32::consts::FRAC_PI_2,
            scale: [0.5, 0.5],
        };
        assert!(close(t.apply(Vec2::new(0.0, 0.0)), Vec2::new(0.0, 1.0)));
        assert!(close(t.apply(Vec2::new(1.0, 0.0)), Vec2::new(0.0, 0.5)));
        assert!(close(t.apply(Vec2::new(0.0, 1.0)), Vec2::new(0.5, 1.0)));
        assert!(close(t.apply(Vec2::new(1.0, 1.0)), Vec2::new(0.5, 0.5)));
    }
}
