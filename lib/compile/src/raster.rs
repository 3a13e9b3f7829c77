//! Rasterization coverage (thesis 3.4: "we use hardware z-buffering to determine object
//! visibility"): which pixels a triangle covers, as Vulkan implementations decide it.
//!
//! Vertices are snapped to [`SUBPIXEL_BITS`] bits of sub-pixel precision (Mesa's lavapipe
//! uses 8, as most hardware does); a pixel is covered when its centre lies inside the
//! snapped triangle, or on a top or left edge (the top-left rule, framebuffer y down), so
//! pixels on an edge shared by two triangles are covered exactly once. Edge functions are
//! exact integers. Depth is z/w interpolated linearly in screen space, tested with `Less`
//! (an earlier triangle wins a tie), as the player's depth state does.

use crate::transform::{clip_depth, to_framebuffer, vertex, DrawMesh, TextureTransform, Viewport};

/// Sub-pixel precision of snapped vertex positions.
pub const SUBPIXEL_BITS: u32 = 8;
const ONE: f64 = (1u32 << SUBPIXEL_BITS) as f64;
/// Positions are clamped to ±GUARD pixels before snapping (a guard band).
const GUARD: f32 = 262_144.0;

/// A triangle after clipping and the viewport transform, ready to rasterize and interpolate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScreenTriangle {
    /// Framebuffer positions (x right, y down) before snapping.
    pub xy: [[f64; 2]; 3],
    /// Depth z/w per vertex.
    pub z: [f64; 3],
    /// 1/w per vertex (for perspective-correct interpolation).
    pub inv_w: [f64; 3],
    /// (s, t) per vertex.
    pub st: [[f64; 2]; 3],
    /// Snapped positions in 1/2^SUBPIXEL_BITS pixel units, oriented so the area is positive.
    fixed: [[i64; 2]; 3],
}

impl ScreenTriangle {
    /// Barycentric weights (screen-linear) of point (x, y), from the unsnapped positions.
    pub fn barycentric(&self, x: f64, y: f64) -> [f64; 3] {
        let [a, b, c] = self.xy;
        let e = |p: [f64; 2], q: [f64; 2]| (q[0] - p[0]) * (y - p[1]) - (q[1] - p[1]) * (x - p[0]);
        let area = e(a, b) + e(b, c) + e(c, a);
        [e(b, c) / area, e(c, a) / area, e(a, b) / area]
    }

    /// Depth z/w at (x, y), linear in screen space.
    pub fn depth_at(&self, x: f64, y: f64) -> f64 {
        let l = self.barycentric(x, y);
        l[0] * self.z[0] + l[1] * self.z[1] + l[2] * self.z[2]
    }

    /// Whether the pixel centre (px + ½, py + ½) is covered (top-left rule).
    pub fn covers(&self, px: i64, py: i64) -> bool {
        let half = (ONE as i64) / 2;
        let (x, y) = (px * ONE as i64 + half, py * ONE as i64 + half);
        let [a, b, c] = self.fixed;
        inside(a, b, x, y) && inside(b, c, x, y) && inside(c, a, x, y)
    }

    /// Pixel bounding box clipped to the viewport: (x0, y0, x1, y1), exclusive ends.
    fn pixel_bounds(&self, vp: Viewport) -> (i64, i64, i64, i64) {
        let one = ONE as i64;
        let min = |k: usize| self.fixed.iter().map(|p| p[k]).min().unwrap_or(0);
        let max = |k: usize| self.fixed.iter().map(|p| p[k]).max().unwrap_or(0);
        let lo = |v: i64| (v - one / 2).div_euclid(one).max(0);
        let (x0, y0) = (lo(min(0)), lo(min(1)));
        let x1 = ((max(0) - one / 2).div_euclid(one) + 1).min(vp.width as i64);
        let y1 = ((max(1) - one / 2).div_euclid(one) + 1).min(vp.height as i64);
        (x0, y0, x1, y1)
    }
}

/// Edge a→b of a positively oriented triangle (framebuffer y down): the point is inside, or
/// on the edge and the edge is a top edge (horizontal, interior below) or a left edge.
fn inside(a: [i64; 2], b: [i64; 2], x: i64, y: i64) -> bool {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let e = dx * (y - a[1]) - dy * (x - a[0]);
    e > 0 || (e == 0 && (dy < 0 || (dy == 0 && dx > 0)))
}

fn snap(v: f32) -> i64 {
    (v.clamp(-GUARD, GUARD) as f64 * ONE).round_ties_even() as i64
}

/// Runs the vertex stage and clipping over a mesh: the screen triangles in draw order, with
/// the index of the source triangle. Triangles of zero snapped area are dropped (as the
/// rasterizer drops them).
pub fn setup_triangles(
    mesh: &DrawMesh,
    transform: &TextureTransform,
    vp: Viewport,
) -> Vec<(u32, ScreenTriangle)> {
    let mut out = Vec::with_capacity(mesh.indices.len() / 3);
    for (t, idx) in mesh.indices.chunks_exact(3).enumerate() {
        let v = |i: u32| {
            let i = i as usize;
            let uv = mesh.uvs.get(i).copied().unwrap_or([0.0; 2]);
            vertex(&mesh.clip_from_object, mesh.positions[i], uv, transform)
        };
        let tri = [v(idx[0]), v(idx[1]), v(idx[2])];
        let poly = if tri.iter().all(|v| v.clip.z >= 0.0 && v.clip.z <= v.clip.w) {
            tri.to_vec()
        } else {
            clip_depth(tri)
        };
        for k in 1..poly.len().saturating_sub(1) {
            let corners = [poly[0], poly[k], poly[k + 1]];
            if corners.iter().any(|c| c.clip.w <= 0.0 || !c.clip.is_finite()) {
                continue;
            }
            let fb = corners.map(|c| to_framebuffer(c.clip, vp));
            let mut fixed = fb.map(|p| [snap(p[0]), snap(p[1])]);
            let area = (fixed[1][0] - fixed[0][0]) * (fixed[2][1] - fixed[0][1])
                - (fixed[1][1] - fixed[0][1]) * (fixed[2][0] - fixed[0][0]);
            if area == 0 {
                continue;
            }
            if area < 0 {
                fixed.swap(1, 2);
            }
            out.push((
                t as u32,
                ScreenTriangle {
                    xy: fb.map(|p| [p[0] as f64, p[1] as f64]),
                    z: fb.map(|p| p[2] as f64),
                    inv_w: corners.map(|c| 1.0 / c.clip.w as f64),
                    st: corners.map(|c| [c.st[0] as f64, c.st[1] as f64]),
                    fixed,
                },
            ));
        }
    }
    out
}

/// A depth buffer (Depth32Float, cleared to 1) holding the nearest depth of every object
/// drawn into it: the occluders of the object whose render matrix is built.
#[derive(Clone, Debug, PartialEq)]
pub struct DepthBuffer {
    pub viewport: Viewport,
    pub depth: Vec<f32>,
}

impl DepthBuffer {
    pub fn new(viewport: Viewport) -> Self {
        DepthBuffer {
            viewport,
            depth: vec![1.0; viewport.width as usize * viewport.height as usize],
        }
    }

    /// Draws a mesh's depth (test `Less`, write on).
    pub fn draw(&mut self, mesh: &DrawMesh) {
        let tris = setup_triangles(mesh, &TextureTransform::IDENTITY, self.viewport);
        let w = self.viewport.width as usize;
        for (_, tri) in &tris {
            for_each_covered(tri, self.viewport, |x, y| {
                let z = tri.depth_at(x as f64 + 0.5, y as f64 + 0.5) as f32;
                let d = &mut self.depth[y as usize * w + x as usize];
                if z < *d {
                    *d = z;
                }
            });
        }
    }
}

/// Calls `f(x, y)` for every pixel the triangle covers inside the viewport.
pub fn for_each_covered(tri: &ScreenTriangle, vp: Viewport, mut f: impl FnMut(i64, i64)) {
    let (x0, y0, x1, y1) = tri.pixel_bounds(vp);
    for y in y0..y1 {
        for x in x0..x1 {
            if tri.covers(x, y) {
                f(x, y);
            }
        }
    }
}

/// Which triangle of an object each pixel shows after the depth test against the object's
/// own triangles (in draw order) and the occluders' depth.
#[derive(Clone, Debug)]
pub struct Fragments {
    pub viewport: Viewport,
    pub triangles: Vec<ScreenTriangle>,
    /// Per entry of `triangles`: the mesh triangle it was set up from (clipping may split one
    /// mesh triangle into several).
    pub source: Vec<u32>,
    /// Per pixel: index into `triangles`, or `u32::MAX` where the object is not visible.
    pub triangle: Vec<u32>,
}

impl Fragments {
    /// Rasterizes an object with depth test `Less` against itself and against `occluders`.
    pub fn rasterize(
        mesh: &DrawMesh,
        transform: &TextureTransform,
        vp: Viewport,
        occluders: Option<&DepthBuffer>,
    ) -> Self {
        let (source, triangles): (Vec<u32>, Vec<ScreenTriangle>) =
            setup_triangles(mesh, transform, vp).into_iter().unzip();
        let n = vp.width as usize * vp.height as usize;
        let mut depth = match occluders {
            Some(o) if o.viewport == vp => o.depth.clone(),
            _ => vec![1.0f32; n],
        };
        let mut triangle = vec![u32::MAX; n];
        let w = vp.width as usize;
        for (k, tri) in triangles.iter().enumerate() {
            for_each_covered(tri, vp, |x, y| {
                let z = tri.depth_at(x as f64 + 0.5, y as f64 + 0.5) as f32;
                let p = y as usize * w + x as usize;
                if z < depth[p] && z >= 0.0 {
                    depth[p] = z;
                    triangle[p] = k as u32;
                }
            });
        }
        Fragments { viewport: vp, triangles, source, triangle }
    }

    /// The visible pixels `y · width + x`, in increasing order.
    pub fn pixels(&self) -> Vec<u32> {
        (0..self.triangle.len() as u32).filter(|&p| self.triangle[p as usize] != u32::MAX).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Mat4;

    /// A quad in NDC split along a diagonal: every pixel it covers is covered exactly once.
    #[test]
    fn top_left_rule_covers_a_shared_edge_once() {
        let vp = Viewport { width: 16, height: 16 };
        // Corners on pixel centres so that many centres lie exactly on the edges.
        let c = |x: f32, y: f32| [x / 8.0 - 1.0, 1.0 - y / 8.0, 0.5];
        let positions = [c(2.5, 2.5), c(12.5, 2.5), c(12.5, 12.5), c(2.5, 12.5), c(7.5, 0.5)];
        let uvs = [[0.0; 2]; 5];
        let indices = [0, 1, 2, 0, 2, 3, 0, 4, 1];
        let mesh = DrawMesh {
            positions: &positions,
            uvs: &uvs,
            indices: &indices,
            clip_from_object: Mat4::IDENTITY,
        };
        let tris = setup_triangles(&mesh, &TextureTransform::IDENTITY, vp);
        let mut count = vec![0u32; 256];
        for (_, t) in &tris {
            for_each_covered(t, vp, |x, y| count[(y * 16 + x) as usize] += 1);
        }
        assert!(count.iter().all(|&c| c <= 1), "a pixel covered twice");
        // The square's top edge (y = 2.5) and left edge (x = 2.5) are in, bottom and right out.
        for y in 0..16 {
            for x in 0..16 {
                let (fx, fy) = (x as f32 + 0.5, y as f32 + 0.5);
                let in_square = (2.5..12.5).contains(&fx) && (2.5..12.5).contains(&fy);
                if in_square {
                    assert_eq!(count[y * 16 + x], 1, "pixel {x},{y}");
                }
            }
        }
    }

    #[test]
    fn depth_test_keeps_the_nearest_and_occluders_hide() {
        let vp = Viewport { width: 4, height: 4 };
        let quad = |z: f32| [[-1.0, -1.0, z], [1.0, -1.0, z], [1.0, 1.0, z], [-1.0, 1.0, z]];
        let (far, near) = (quad(0.6), quad(0.3));
        let uvs = [[0.0; 2]; 4];
        let idx = [0, 1, 2, 0, 2, 3];
        let m = |p: &'static [[f32; 3]]| DrawMesh {
            positions: p,
            uvs: &uvs,
            indices: &idx,
            clip_from_object: Mat4::IDENTITY,
        };
        let far: &'static [[f32; 3]] = Box::leak(Box::new(far));
        let near: &'static [[f32; 3]] = Box::leak(Box::new(near));
        let mut occ = DepthBuffer::new(vp);
        occ.draw(&m(near));
        assert!(occ.depth.iter().all(|&d| (d - 0.3).abs() < 1e-6));
        let hidden = Fragments::rasterize(&m(far), &TextureTransform::IDENTITY, vp, Some(&occ));
        assert!(hidden.pixels().is_empty());
        let shown = Fragments::rasterize(&m(far), &TextureTransform::IDENTITY, vp, None);
        assert_eq!(shown.pixels().len(), 16);
    }
}
