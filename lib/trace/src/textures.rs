//! Texture lookups: bilinear, wrapping, through a material's [`TextureRef`] (its
//! texture-coordinate set and KHR_texture_transform).

use glam::{Vec2, Vec3, Vec4};
use pis_scene::{Scene, TextureImage, TextureRef};

/// Bilinear, wrapping lookup of a texture's RGBA (UV (0,0) = top-left texel corner); white
/// for an empty texture or one whose texels do not fill its size.
pub fn sample_rgba(tex: &TextureImage, uv: Vec2) -> Vec4 {
    let (w, h) = (tex.width as usize, tex.height as usize);
    if w == 0 || h == 0 || tex.texels.len() < w * h || !uv.is_finite() {
        return Vec4::ONE;
    }
    let x = uv.x * w as f32 - 0.5;
    let y = uv.y * h as f32 - 0.5;
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let wrap = |v: f32, n: usize| (v as i64).rem_euclid(n as i64) as usize;
    let t = |xi: f32, yi: f32| Vec4::from(tex.texels[wrap(yi, h) * w + wrap(xi, w)]);
    let top = t(x0, y0).lerp(t(x0 + 1.0, y0), fx);
    let bottom = t(x0, y0 + 1.0).lerp(t(x0 + 1.0, y0 + 1.0), fx);
    top.lerp(bottom, fy)
}

/// [`sample_rgba`] without alpha.
pub fn sample_texture(tex: &TextureImage, uv: Vec2) -> Vec3 {
    sample_rgba(tex, uv).truncate()
}

/// The texel `reference` reads at a point whose texture-coordinate sets are `uvs`
/// (TEXCOORD_0, TEXCOORD_1); `None` without a reference or for a texture that does not exist.
#[inline]
pub fn lookup(scene: &Scene, reference: Option<&TextureRef>, uvs: [Vec2; 2]) -> Option<Vec4> {
    let r = reference?;
    scene.textures.get(r.texture).map(|t| sample_rgba(t, r.uv(uvs)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use pis_scene::UvTransform;

    /// A 2×1 texture, black on the left half, white on the right.
    fn halves() -> Scene {
        let texels = vec![[0.0, 0.0, 0.0, 1.0], [1.0, 1.0, 1.0, 1.0]];
        Scene { textures: vec![TextureImage { width: 2, height: 1, texels }], ..Scene::default() }
    }

    #[test]
    fn texture_transform_offsets_and_scales_uvs_at_lookup() {
        let s = halves();
        let plain = TextureRef::new(0);
        assert_eq!(
            lookup(&s, Some(&plain), [Vec2::new(0.25, 0.5), Vec2::ZERO]),
            Some(Vec4::new(0.0, 0.0, 0.0, 1.0))
        );
        // Offset ½: the left half reads the right texel.
        let shifted = TextureRef {
            transform: UvTransform { offset: [0.5, 0.0], ..UvTransform::IDENTITY },
            ..plain
        };
        assert_eq!(lookup(&s, Some(&shifted), [Vec2::new(0.25, 0.5), Vec2::ZERO]), Some(Vec4::ONE));
        // Set 1 with a scale of 3: u = 0.25 reads u = 0.75.
        let scaled = TextureRef {
            tex_coord: 1,
            transform: UvTransform { scale: [3.0, 1.0], ..UvTransform::IDENTITY },
            ..plain
        };
        assert_eq!(lookup(&s, Some(&scaled), [Vec2::ZERO, Vec2::new(0.25, 0.5)]), Some(Vec4::ONE));
        assert_eq!(lookup(&s, None, [Vec2::ZERO; 2]), None);
        assert_eq!(lookup(&s, Some(&TextureRef::new(7)), [Vec2::ZERO; 2]), None);
    }
}
