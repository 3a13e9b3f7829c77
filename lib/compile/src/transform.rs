//! Vertex transform (thesis 3.4, the first stage of the player's pipeline): object space →
//! clip space → framebuffer, with wgpu's conventions: clip-space depth in [0, w], NDC y up,
//! framebuffer y down with the origin at the top-left corner, pixel centres at (i + ½, j + ½).
//!
//! WGSL twin: `vs_main` in `lib/play/src/textured.wgsl` and `texcoord` in
//! `lib/play/src/texture_transform.wgsl`.

use glam::{Mat4, Vec3, Vec4};

/// The framebuffer the player draws into.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Viewport {
    pub width: u32,
    pub height: u32,
}

/// The texture-coordinate transform of a parameter block (SPEC.md 7.3): branch cuts in
/// periodic dimensions, `w' = (w − w_cut) − ⌊w − w_cut⌋` where a cut is made, then the
/// affine map `s = a·u' + b·v' + e`, `t = c·u' + d·v' + f`; (s, t) ∈ [0, 1]² spans the used
/// texture.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TextureTransform {
    /// `[a, b, c, d, e, f]`, the block's placement values 0..6.
    pub values: [f32; 6],
    /// The branch cut along u and v (placement values 6 and 7, flag bits 2 and 3), where
    /// one was made.
    pub cut: [Option<f32>; 2],
}

impl TextureTransform {
    /// s = u, t = v.
    pub const IDENTITY: TextureTransform =
        TextureTransform { values: [1.0, 0.0, 0.0, 1.0, 0.0, 0.0], cut: [None; 2] };

    /// The affine map `values` without branch cuts.
    pub const fn affine(values: [f32; 6]) -> TextureTransform {
        TextureTransform { values, cut: [None; 2] }
    }

    /// (u', v') of mesh texture coordinates (u, v): the branch cuts applied, in the order
    /// of operations of the WGSL `cut_uv`: `w − c − floor(w − c)` in f32.
    pub fn cut_uv(&self, uv: [f32; 2]) -> [f32; 2] {
        let mut w = uv;
        for (x, c) in w.iter_mut().zip(self.cut) {
            if let Some(c) = c {
                let d = *x - c;
                *x = d - d.floor();
            }
        }
        w
    }

    /// (s, t) of mesh texture coordinates (u, v), in the order of operations of the WGSL
    /// `texcoord`: the cuts ([`TextureTransform::cut_uv`]), then `a·u + b·v + e` evaluated
    /// left to right in f32.
    pub fn texcoord(&self, uv: [f32; 2]) -> [f32; 2] {
        let [a, b, c, d, e, f] = self.values;
        let uv = self.cut_uv(uv);
        [a * uv[0] + b * uv[1] + e, c * uv[0] + d * uv[1] + f]
    }
}

/// A right-handed perspective projection with wgpu's clip-space depth in [0, 1] (near → 0,
/// far → 1), camera looking down −z: `fovy` in radians, `aspect` = width / height.
pub fn perspective(fovy: f32, aspect: f32, near: f32, far: f32) -> Mat4 {
    let f = 1.0 / (0.5 * fovy).tan();
    let r = far / (near - far);
    Mat4::from_cols(
        Vec4::new(f / aspect, 0.0, 0.0, 0.0),
        Vec4::new(0.0, f, 0.0, 0.0),
        Vec4::new(0.0, 0.0, r, -1.0),
        Vec4::new(0.0, 0.0, r * near, 0.0),
    )
}

/// The view matrix of a camera at `eye` looking at `target` (right-handed, +y up on screen).
pub fn look_at(eye: Vec3, target: Vec3, up: Vec3) -> Mat4 {
    let f = (target - eye).normalize();
    let s = f.cross(up).normalize();
    let u = s.cross(f);
    Mat4::from_cols(
        Vec4::new(s.x, u.x, -f.x, 0.0),
        Vec4::new(s.y, u.y, -f.y, 0.0),
        Vec4::new(s.z, u.z, -f.z, 0.0),
        Vec4::new(-s.dot(eye), -u.dot(eye), f.dot(eye), 1.0),
    )
}

/// One mesh as the player draws it: object-space positions, texture coordinates (u, v),
/// a triangle list, and the object's clip-from-object matrix (projection · view · world).
#[derive(Clone, Copy, Debug)]
pub struct DrawMesh<'a> {
    pub positions: &'a [[f32; 3]],
    pub uvs: &'a [[f32; 2]],
    pub indices: &'a [u32],
    pub clip_from_object: Mat4,
}

/// A vertex after the vertex shader: clip-space position and texture coordinates (s, t).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClipVertex {
    pub clip: Vec4,
    pub st: [f32; 2],
}

/// The vertex shader: clip = clip_from_object · (p, 1), (s, t) = transform(u, v).
pub fn vertex(
    clip_from_object: &Mat4,
    position: [f32; 3],
    uv: [f32; 2],
    transform: &TextureTransform,
) -> ClipVertex {
    let clip = *clip_from_object * Vec4::new(position[0], position[1], position[2], 1.0);
    ClipVertex { clip, st: transform.texcoord(uv) }
}

/// Framebuffer position (x right, y down, in pixels) and depth of a clip-space position with
/// w > 0: the perspective divide and wgpu's viewport transform.
pub fn to_framebuffer(clip: Vec4, viewport: Viewport) -> [f32; 3] {
    let inv_w = 1.0 / clip.w;
    let (hw, hh) = (viewport.width as f32 * 0.5, viewport.height as f32 * 0.5);
    let (xn, yn, zn) = (clip.x * inv_w, clip.y * inv_w, clip.z * inv_w);
    [xn * hw + hw, -yn * hh + hh, zn]
}

/// Clips a triangle against the near (z ≥ 0) and far (z ≤ w) planes of wgpu's clip volume,
/// interpolating (s, t) linearly in clip space (which keeps perspective-correct interpolation
/// unchanged). Returns a convex polygon of 0 or 3..=5 vertices.
pub fn clip_depth(tri: [ClipVertex; 3]) -> Vec<ClipVertex> {
    let mut poly: Vec<ClipVertex> = tri.to_vec();
    let planes: [fn(&Vec4) -> f32; 2] = [|c| c.z, |c| c.w - c.z];
    for dist in planes {
        if poly.iter().all(|v| dist(&v.clip) >= 0.0) {
            continue;
        }
        let mut out = Vec::with_capacity(poly.len() + 1);
        for k in 0..poly.len() {
            let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
            let (da, db) = (dist(&a.clip), dist(&b.clip));
            if da >= 0.0 {
                out.push(a);
            }
            if (da >= 0.0) != (db >= 0.0) {
                let t = da / (da - db);
                out.push(ClipVertex {
                    clip: a.clip + (b.clip - a.clip) * t,
                    st: [a.st[0] + (b.st[0] - a.st[0]) * t, a.st[1] + (b.st[1] - a.st[1]) * t],
                });
            }
        }
        poly = out;
        if poly.len() < 3 {
            return Vec::new();
        }
    }
    poly
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ndc_corners_map_to_framebuffer_corners_y_down() {
        let vp = Viewport { width: 8, height: 4 };
        assert_eq!(to_framebuffer(Vec4::new(-1.0, 1.0, 0.0, 1.0), vp), [0.0, 0.0, 0.0]);
        assert_eq!(to_framebuffer(Vec4::new(2.0, -2.0, 2.0, 2.0), vp), [8.0, 4.0, 1.0]);
    }

    #[test]
    fn near_plane_clipping_keeps_the_visible_part() {
        let v = |z: f32, s: f32| ClipVertex { clip: Vec4::new(0.0, 0.0, z, 1.0), st: [s, 0.0] };
        let poly = clip_depth([v(-1.0, 0.0), v(0.5, 1.0), v(0.5, 2.0)]);
        assert_eq!(poly.len(), 4);
        assert!(poly.iter().all(|p| p.clip.z >= 0.0));
        assert!(clip_depth([v(-1.0, 0.0), v(-0.5, 1.0), v(-0.5, 2.0)]).is_empty());
    }

    #[test]
    fn perspective_maps_near_to_0_and_far_to_1() {
        let p = perspective(1.0, 1.5, 0.5, 10.0);
        let n = p * Vec4::new(0.0, 0.0, -0.5, 1.0);
        let f = p * Vec4::new(0.0, 0.0, -10.0, 1.0);
        assert!((n.z / n.w).abs() < 1e-6 && (f.z / f.w - 1.0).abs() < 1e-6);
        let v = look_at(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y);
        assert!(
            (v * Vec4::new(0.0, 0.0, 0.0, 1.0) - Vec4::new(0.0, 0.0, -5.0, 1.0)).length() < 1e-6
        );
    }

    #[test]
    fn texture_transform_is_the_spec_affine() {
        let t = TextureTransform::affine([2.0, 0.5, -1.0, 3.0, 0.25, 0.125]);
        assert_eq!(t.texcoord([1.0, 2.0]), [2.0 + 1.0 + 0.25, -1.0 + 6.0 + 0.125]);
    }

    #[test]
    fn branch_cuts_wrap_each_cut_coordinate_into_0_1() {
        let none = TextureTransform::affine([1.0, 0.0, 0.0, 1.0, 0.0, 0.0]);
        assert_eq!(none.cut_uv([1.25, -0.5]), [1.25, -0.5], "no cut: coordinates unchanged");
        let u = TextureTransform { cut: [Some(0.25), None], ..none };
        // Above the cut: shifted down; below: shifted and wrapped up; v untouched.
        assert_eq!(u.cut_uv([0.75, 1.5]), [0.5, 1.5]);
        assert_eq!(u.cut_uv([0.125, 1.5]), [0.875, 1.5]);
        assert_eq!(
            u.cut_uv([1.5, -0.5]),
            [0.25, -0.5],
            "a wrapped range (u > 1) comes back into [0, 1)"
        );
        // A coordinate exactly at the cut maps to 0, and one period above it too.
        assert_eq!(u.cut_uv([0.25, 0.0]), [0.0, 0.0]);
        assert_eq!(u.cut_uv([1.25, 0.0]), [0.0, 0.0]);
        let v = TextureTransform { cut: [None, Some(0.5)], ..none };
        assert_eq!(v.cut_uv([1.5, 0.25]), [1.5, 0.75]);
        assert_eq!(v.cut_uv([1.5, 0.5]), [1.5, 0.0]);
        // Both cuts, then the affine map.
        let both = TextureTransform {
            values: [2.0, 0.0, 0.0, 4.0, 0.5, -1.0],
            cut: [Some(0.25), Some(0.5)],
        };
        assert_eq!(both.cut_uv([0.0, 0.0]), [0.75, 0.5]);
        assert_eq!(both.texcoord([0.0, 0.0]), [2.0 * 0.75 + 0.5, 4.0 * 0.5 - 1.0]);
        // Cuts that are not binary fractions: within f32 rounding of the exact wrap, in [0, 1).
        let r = TextureTransform { cut: [Some(0.3), None], ..none }.cut_uv([0.1, 0.0])[0];
        assert!((r - 0.8).abs() < 1e-6 && r < 1.0, "{r}");
    }
}
