//! Perspective-correct interpolation of the texture coordinates (s, t) and their screen-space
//! derivatives.
//!
//! Derivatives are Vulkan's *fine* derivatives (WGSL `dpdxFine` / `dpdyFine`): the difference
//! between the two pixels of the 2×2 quad in the pixel's row (x) or column (y), where the
//! quad's other pixels evaluate the same triangle's interpolant (helper invocations
//! extrapolate it). The player's fragment shader takes exactly these derivatives and computes
//! the LOD itself (see `lod`), so model and GPU agree on every pixel.
//!
//! WGSL twin: `fs_main` in `lib/play/src/textured.wgsl`.

use crate::raster::ScreenTriangle;

/// (s, t) at framebuffer point (x, y), perspective-correct (Vulkan's formula: screen-linear
/// barycentrics weighted by 1/w).
pub fn texcoord_at(tri: &ScreenTriangle, x: f64, y: f64) -> [f64; 2] {
    let l = tri.barycentric(x, y);
    let q = [l[0] * tri.inv_w[0], l[1] * tri.inv_w[1], l[2] * tri.inv_w[2]];
    let sum = q[0] + q[1] + q[2];
    let s = (q[0] * tri.st[0][0] + q[1] * tri.st[1][0] + q[2] * tri.st[2][0]) / sum;
    let t = (q[0] * tri.st[0][1] + q[1] * tri.st[1][1] + q[2] * tri.st[2][1]) / sum;
    [s, t]
}

/// The interpolated (s, t) at pixel (px, py) and its fine derivatives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interpolated {
    pub st: [f64; 2],
    /// ∂(s, t)/∂x.
    pub ddx: [f64; 2],
    /// ∂(s, t)/∂y.
    pub ddy: [f64; 2],
}

/// Interpolates at the centre of pixel (px, py) with quad-difference derivatives.
pub fn interpolate(tri: &ScreenTriangle, px: u32, py: u32) -> Interpolated {
    let at = |x: u32, y: u32| texcoord_at(tri, x as f64 + 0.5, y as f64 + 0.5);
    let (qx, qy) = (px & !1, py & !1);
    let st = at(px, py);
    let (l, r) = (at(qx, py), at(qx + 1, py));
    let (u, d) = (at(px, qy), at(px, qy + 1));
    Interpolated { st, ddx: [r[0] - l[0], r[1] - l[1]], ddy: [d[0] - u[0], d[1] - u[1]] }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::raster::setup_triangles;
    use crate::transform::{DrawMesh, TextureTransform, Viewport};
    use glam::Mat4;

    #[test]
    fn affine_triangle_interpolates_linearly() {
        let vp = Viewport { width: 8, height: 8 };
        let positions = [[-1.0, 1.0, 0.5], [1.0, 1.0, 0.5], [-1.0, -1.0, 0.5]];
        let uvs = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
        let mesh = DrawMesh {
            positions: &positions,
            uvs: &uvs,
            indices: &[0, 1, 2],
            clip_from_object: Mat4::IDENTITY,
        };
        let tris = setup_triangles(&mesh, &TextureTransform::IDENTITY, vp);
        let i = interpolate(&tris[0].1, 1, 2);
        assert!((i.st[0] - 1.5 / 8.0).abs() < 1e-9 && (i.st[1] - 2.5 / 8.0).abs() < 1e-9);
        assert!((i.ddx[0] - 0.125).abs() < 1e-9 && i.ddx[1].abs() < 1e-9);
        assert!((i.ddy[1] - 0.125).abs() < 1e-9 && i.ddy[0].abs() < 1e-9);
    }
}
