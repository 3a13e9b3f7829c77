//! The hardware model (thesis 3.4): the render matrix A of one textured object at one
//! parameter point, computed in software as the player's wgpu pipeline draws it — vertex
//! transform, clipping, rasterization with the top-left rule, depth test against the whole
//! scene, perspective-correct interpolation of the block's transformed texture coordinates,
//! fine derivatives, the Vulkan LOD, and the sampler's filter weights.

use rayon::prelude::*;
use thiserror::Error;

use crate::filter::{max_level, sample_taps, Taps};
use crate::interpolate::interpolate;
use crate::lod::texture_lod;
use crate::raster::{DepthBuffer, Fragments};
use crate::transform::{DrawMesh, TextureTransform, Viewport};
use crate::{RenderMatrix, Sampler, TextureLayout};

/// Why the model cannot build a render matrix.
#[derive(Debug, Error, PartialEq)]
pub enum ModelError {
    #[error("viewport {width}×{height} is empty or larger than 16384 pixels on a side")]
    Viewport { width: u32, height: u32 },
    #[error("texture layout {width}×{height} with {levels} levels is invalid (sizes 1..=16384, levels 1..=full chain)")]
    Layout { width: u32, height: u32, levels: u32 },
    #[error("mesh has {uvs} texture coordinates for {positions} positions")]
    Uvs { positions: usize, uvs: usize },
    #[error("mesh triangle list has {0} indices, not a multiple of 3")]
    IndexCount(usize),
    #[error("mesh index {index} at position {at} is out of range ({positions} positions)")]
    Index { at: usize, index: u32, positions: usize },
    #[error("mesh has a non-finite position or texture coordinate at vertex {0}")]
    NotFinite(usize),
    #[error("texture transform {0:?} is not finite or has a zero determinant a·d − b·c")]
    Transform([f32; 6]),
    #[error("occluder depth buffer is {got:?}, the viewport {want:?}")]
    DepthSize { got: Viewport, want: Viewport },
    #[error("the hardware model cannot describe anisotropic filtering (the adapter chooses its taps): measure the render matrix through the GPU (probe mode)")]
    Anisotropic,
    #[error("display filter sigma {sigma} / radius {radius} px or supersampling factor {factor} is invalid")]
    Filter { sigma: f32, radius: f32, factor: u32 },
}

/// Checks a mesh before it is drawn (data comes from files).
pub fn check_mesh(mesh: &DrawMesh) -> Result<(), ModelError> {
    if mesh.uvs.len() != mesh.positions.len() {
        return Err(ModelError::Uvs { positions: mesh.positions.len(), uvs: mesh.uvs.len() });
    }
    if !mesh.indices.len().is_multiple_of(3) {
        return Err(ModelError::IndexCount(mesh.indices.len()));
    }
    if let Some((at, &index)) =
        mesh.indices.iter().enumerate().find(|(_, &i)| i as usize >= mesh.positions.len())
    {
        return Err(ModelError::Index { at, index, positions: mesh.positions.len() });
    }
    if let Some(k) = (0..mesh.positions.len())
        .find(|&k| !mesh.positions[k].iter().chain(mesh.uvs[k].iter()).all(|v| v.is_finite()))
    {
        return Err(ModelError::NotFinite(k));
    }
    Ok(())
}

pub(crate) fn check_inputs(
    vp: Viewport,
    layout: &TextureLayout,
    transform: &TextureTransform,
) -> Result<(), ModelError> {
    if vp.width == 0 || vp.height == 0 || vp.width > 16384 || vp.height > 16384 {
        return Err(ModelError::Viewport { width: vp.width, height: vp.height });
    }
    let full = TextureLayout::full(layout.width.max(1), layout.height.max(1)).levels;
    let bad = |v: u32| v == 0 || v > 16384;
    if bad(layout.width) || bad(layout.height) || layout.levels == 0 || layout.levels > full {
        return Err(ModelError::Layout {
            width: layout.width,
            height: layout.height,
            levels: layout.levels,
        });
    }
    let [a, b, c, d, ..] = transform.values;
    let det = a * d - b * c;
    if !transform.values.iter().all(|v| v.is_finite()) || det == 0.0 || !det.is_finite() {
        return Err(ModelError::Transform(transform.values));
    }
    Ok(())
}

/// One object drawn with one block's texture: what the model needs to build its A.
#[derive(Clone, Copy, Debug)]
pub struct TexturedObject<'a> {
    pub mesh: DrawMesh<'a>,
    pub transform: TextureTransform,
    pub layout: TextureLayout,
    pub sampler: Sampler,
}

/// The depth of every object of the scene except `skip` (the object being modelled): the
/// occluders against which its fragments are tested. Meshes are drawn in order.
pub fn scene_depth(
    viewport: Viewport,
    meshes: &[DrawMesh],
    skip: Option<usize>,
) -> Result<DepthBuffer, ModelError> {
    let mut depth = DepthBuffer::new(viewport);
    for (k, m) in meshes.iter().enumerate() {
        if Some(k) != skip {
            check_mesh(m)?;
            depth.draw(m);
        }
    }
    Ok(depth)
}

/// Checks what [`render_matrix`] checks before drawing (probe mode checks the same).
pub fn render_matrix_inputs_ok(
    viewport: Viewport,
    object: &TexturedObject,
) -> Result<(), ModelError> {
    check_mesh(&object.mesh)?;
    check_inputs(viewport, &object.layout, &object.transform)
}

/// The render matrix A of `object` in `viewport`, its fragments tested against `occluders`
/// (see [`scene_depth`]); every row has coverage 1 (no antialiasing: see
/// [`mod@crate::antialias`]). Rows are the visible pixels in increasing order.
pub fn render_matrix(
    viewport: Viewport,
    object: &TexturedObject,
    occluders: Option<&DepthBuffer>,
) -> Result<RenderMatrix, ModelError> {
    render_matrix_inputs_ok(viewport, object)?;
    if matches!(object.sampler.filter, crate::Filter::Anisotropic(_)) {
        return Err(ModelError::Anisotropic);
    }
    if let Some(o) = occluders {
        if o.viewport != viewport {
            return Err(ModelError::DepthSize { got: o.viewport, want: viewport });
        }
    }
    let frags = Fragments::rasterize(&object.mesh, &object.transform, viewport, occluders);
    let pixels = frags.pixels();
    let layout = object.layout;
    let size = [layout.width as f64, layout.height as f64];
    let q = max_level(&layout, &object.sampler);
    let rows: Vec<Taps> = pixels
        .par_iter()
        .map(|&p| {
            let (x, y) = (p % viewport.width, p / viewport.width);
            let tri = &frags.triangles[frags.triangle[p as usize] as usize];
            let i = interpolate(tri, x, y);
            let lambda = texture_lod(i.ddx, i.ddy, size, q);
            let mut taps = Taps::default();
            sample_taps(&layout, &object.sampler, i.st, lambda, &mut taps);
            taps
        })
        .collect();
    Ok(RenderMatrix::from_taps(viewport, layout, pixels, &rows))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Address, Filter};
    use glam::Mat4;

    const QUAD_UV: [[f32; 2]; 4] = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
    const QUAD_IDX: [u32; 6] = [0, 1, 2, 0, 2, 3];

    /// A full-screen quad, (u, v) = (0, 0) at the top-left corner.
    fn screen_quad() -> [[f32; 3]; 4] {
        [[-1.0, 1.0, 0.5], [1.0, 1.0, 0.5], [1.0, -1.0, 0.5], [-1.0, -1.0, 0.5]]
    }

    fn object<'a>(
        positions: &'a [[f32; 3]],
        layout: TextureLayout,
        filter: Filter,
    ) -> TexturedObject<'a> {
        TexturedObject {
            mesh: DrawMesh {
                positions,
                uvs: &QUAD_UV,
                indices: &QUAD_IDX,
                clip_from_object: Mat4::IDENTITY,
            },
            transform: TextureTransform::IDENTITY,
            layout,
            sampler: Sampler { filter, address: [Address::ClampToEdge; 2] },
        }
    }

    #[test]
    fn texel_aligned_screen_quad_is_the_identity() {
        let p = screen_quad();
        for filter in [Filter::Nearest, Filter::Bilinear, Filter::Trilinear] {
            let layout = TextureLayout::full(12, 7);
            let a =
                render_matrix(Viewport { width: 12, height: 7 }, &object(&p, layout, filter), None)
                    .unwrap();
            assert_eq!(a.rows(), 84, "{filter:?}");
            for r in 0..a.rows() {
                // Weight 1 on the pixel's own texel, up to rounding of (s, t).
                let (c, v) = a.row(r);
                let k = c.iter().position(|&c| c == a.pixels[r]).unwrap();
                assert!((v[k] - 1.0).abs() < 1e-5, "{filter:?} row {r}: {c:?} {v:?}");
            }
        }
    }

    #[test]
    fn two_to_one_minified_quad_reads_level_one() {
        let p = screen_quad();
        let layout = TextureLayout::full(32, 32);
        let a = render_matrix(
            Viewport { width: 16, height: 16 },
            &object(&p, layout, Filter::Trilinear),
            None,
        )
        .unwrap();
        let level1 = layout.level_offset(1) as u32..layout.level_offset(2) as u32;
        for r in 0..a.rows() {
            let (c, v) = a.row(r);
            // Pixel centres fall on level-1 texel centres: one tap of weight 1 on level 1
            // (λ = 1 up to rounding, so level 0 may keep a weight of order 1e-7).
            let k = v.iter().position(|&w| w > 0.5).unwrap();
            assert!(level1.contains(&c[k]), "row {r}: {c:?} {v:?}");
            assert!((v[k] - 1.0).abs() < 1e-5);
        }
    }

    #[test]
    fn rows_sum_to_one_on_a_perspective_quad() {
        let p = [[-1.0, 0.0, -2.0], [1.0, 0.0, -2.0], [1.0, 0.0, -12.0], [-1.0, 0.0, -12.0]];
        let proj = crate::transform::perspective(1.0, 4.0 / 3.0, 0.1, 100.0);
        let view = crate::transform::look_at(
            glam::Vec3::new(0.0, 1.0, 0.0),
            glam::Vec3::new(0.0, 0.0, -6.0),
            glam::Vec3::Y,
        );
        let mut o = object(&p, TextureLayout::full(37, 100), Filter::Trilinear);
        o.mesh.clip_from_object = proj * view;
        let a = render_matrix(Viewport { width: 64, height: 48 }, &o, None).unwrap();
        assert!(a.rows() > 300, "{} rows", a.rows());
        for r in 0..a.rows() {
            let s: f32 = a.row(r).1.iter().sum();
            assert!((s - 1.0).abs() < 1e-5);
            assert!(a.row(r).0.len() <= 8);
        }
        let mean = a.cols.len() as f64 / a.rows() as f64;
        assert!(mean > 4.0, "mean taps {mean}");
    }

    #[test]
    fn objects_off_screen_behind_the_camera_or_degenerate_give_few_or_no_rows() {
        let vp = Viewport { width: 32, height: 24 };
        let proj = crate::transform::perspective(1.0, 4.0 / 3.0, 0.1, 100.0);
        let layout = TextureLayout::full(16, 16);
        // Behind the camera (z > 0 in view space), half off-screen, and edge-on.
        let behind = [[-1.0, -1.0, 3.0], [1.0, -1.0, 3.0], [1.0, 1.0, 3.0], [-1.0, 1.0, 3.0]];
        let half = [[0.0, -1.0, -3.0], [9.0, -1.0, -3.0], [9.0, 1.0, -3.0], [0.0, 1.0, -3.0]];
        let edge_on = [[-1.0, 0.0, -2.0], [1.0, 0.0, -2.0], [1.0, 0.0, -4.0], [-1.0, 0.0, -4.0]];
        let rows = |p: &[[f32; 3]]| {
            let mut o = object(p, layout, Filter::Trilinear);
            o.mesh.clip_from_object = proj;
            render_matrix(vp, &o, None).unwrap().rows()
        };
        assert_eq!(rows(&behind), 0);
        let h = rows(&half);
        assert!(h > 0 && h < 32 * 24 / 2 + 24, "{h}");
        assert_eq!(rows(&edge_on), 0);
        // A non-finite matrix draws nothing rather than panicking.
        let mut o = object(&half, layout, Filter::Trilinear);
        o.mesh.clip_from_object = Mat4::from_cols_array(&[f32::NAN; 16]);
        assert_eq!(render_matrix(vp, &o, None).unwrap().rows(), 0);
    }

    #[test]
    fn anisotropic_filtering_is_not_modelled() {
        let p = screen_quad();
        let o = object(&p, TextureLayout::full(4, 4), Filter::Anisotropic(16));
        assert_eq!(
            render_matrix(Viewport { width: 4, height: 4 }, &o, None).unwrap_err(),
            ModelError::Anisotropic
        );
    }

    #[test]
    fn bad_inputs_are_errors() {
        let p = screen_quad();
        let vp = Viewport { width: 4, height: 4 };
        let mut o = object(&p, TextureLayout::full(4, 4), Filter::Bilinear);
        o.transform.values = [1.0, 0.0, 2.0, 0.0, 0.0, 0.0];
        assert!(matches!(render_matrix(vp, &o, None), Err(ModelError::Transform(_))));
        let o = object(&p[..3], TextureLayout::full(4, 4), Filter::Bilinear);
        assert!(matches!(render_matrix(vp, &o, None), Err(ModelError::Uvs { .. })));
        let o = object(&p, TextureLayout::new(4, 4, 9), Filter::Bilinear);
        assert!(matches!(render_matrix(vp, &o, None), Err(ModelError::Layout { .. })));
    }
}
