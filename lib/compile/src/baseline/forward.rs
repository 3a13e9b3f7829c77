//! Forward mapping (thesis 3.3, \[Mar98\]): every level-0 texel centre is mapped to the image
//! and the object's layer is filtered there with a separable Lanczos-windowed sinc of
//! half-width 4 pixels (widened where a texel covers more than a pixel). The layer's
//! uncovered pixels are first filled by boundary reflection; texels that map nowhere on
//! screen are filled the same way in texture space. MIP levels by decimation.

use super::hole_fill::fill_by_reflection;
use super::lanczos::filter_at;
use super::texel_map::map_texels;
use super::{with_mip_levels, LayerImage};
use crate::transform::{DrawMesh, TextureTransform, Viewport};
use crate::{CompileError, TextureLayout};

/// Half-width of the forward-mapping filter, in pixels (thesis 3.6).
pub const FORWARD_LANCZOS: f64 = 4.0;

/// The forward-mapped texture (n_t × 3, the order of [`TextureLayout`]).
pub fn forward_map(
    mesh: &DrawMesh,
    transform: &TextureTransform,
    layer: &LayerImage,
    layout: &TextureLayout,
) -> Result<Vec<f32>, CompileError> {
    let n = layer.width as usize * layer.height as usize;
    if layer.rgb.len() != n * 3 || layer.covered.len() != n {
        return Err(CompileError::Size {
            what: "layer image (pixels × 3)".into(),
            expected: n * 3,
            found: layer.rgb.len(),
        });
    }
    crate::error::check_finite("layer image", &layer.rgb)?;
    let mut image = layer.rgb.clone();
    fill_by_reflection(&mut image, &layer.covered, layer.width, layer.height);
    let viewport = Viewport { width: layer.width, height: layer.height };
    let (w, h) = (layout.width, layout.height);
    let points = map_texels(mesh, transform, viewport, w, h);
    let on_screen = |k: usize| points[k].filter(|p| p.clip.w > 0.0).map(|p| p.screen);
    let mut level0 = vec![0.0f32; w as usize * h as usize * 3];
    let mut defined = vec![false; w as usize * h as usize];
    for j in 0..h as usize {
        for i in 0..w as usize {
            let k = j * w as usize + i;
            let Some(p) = on_screen(k) else { continue };
            // the texel's footprint: distance to its neighbours on screen
            let mut foot = 1.0f64;
            for q in
                [(i + 1 < w as usize).then(|| k + 1), (j + 1 < h as usize).then(|| k + w as usize)]
                    .into_iter()
                    .flatten()
            {
                if let Some(r) = on_screen(q) {
                    foot = foot.max(((r[0] - p[0]) as f64).hypot((r[1] - p[1]) as f64));
                }
            }
            let v = filter_at(
                &image,
                layer.width,
                layer.height,
                p[0] as f64,
                p[1] as f64,
                FORWARD_LANCZOS,
                foot.min(16.0),
            );
            level0[k * 3..k * 3 + 3].copy_from_slice(&v);
            defined[k] = true;
        }
    }
    fill_by_reflection(&mut level0, &defined, w, h);
    Ok(with_mip_levels(level0, layout))
}
