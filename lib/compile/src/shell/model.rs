//! The render matrix A of one environment-map shell drawn on an object at one parameter point
//! (thesis 5.8: "the rendering matrix is created using test renderings with environment
//! mapping instead of texture mapping"): the object is rasterized as for a surface texture
//! (coverage, top-left rule, depth test), its world position and normal are interpolated
//! perspective-correct, and per pixel the reflection ray off the normal meets the shell
//! ([`super::geometry`]); the hit's cube-map lookup, its LOD from fine derivatives and its
//! trilinear, seamless taps ([`super::cube`]) give the row.
//!
//! WGSL twin: `fs_shell` in `lib/play/src/shell.wgsl`.

use glam::{DVec3, Mat4, Vec3, Vec4};
use rayon::prelude::*;

use super::cube::{cube_lod, cube_taps, footprint_row};
use super::geometry::{fresnel, lookup_direction, Shell};
use crate::filter::Taps;
use crate::interpolate::texcoord_at;
use crate::model::ModelError;
use crate::raster::{DepthBuffer, Fragments, ScreenTriangle};
use crate::transform::{DrawMesh, TextureTransform, Viewport};
use crate::{RenderMatrix, TextureLayout};

/// One object drawn with one shell: what the model needs to build the shell's A.
#[derive(Clone, Debug)]
pub struct ShellObject<'a> {
    /// Object-space positions, normals (one per position) and the triangle list.
    pub positions: &'a [[f32; 3]],
    pub normals: &'a [[f32; 3]],
    pub indices: &'a [u32],
    /// projection · view · world.
    pub clip_from_object: Mat4,
    /// world, a rigid transform (normals are rotated by its 3×3 part).
    pub world_from_object: Mat4,
    /// The camera's position in world space.
    pub eye: Vec3,
    pub shell: Shell,
    /// A cube layout ([`TextureLayout::cube`]); lookups are trilinear over its levels.
    pub layout: TextureLayout,
    /// Per triangle, whether the shell is drawn on it (thesis 5.7: triangles on the convex
    /// hull draw the distant shell only); `None` draws every triangle. Pixels of a triangle
    /// that does not draw the shell have no row.
    pub drawn: Option<&'a [bool]>,
    /// Lookups per pixel side (SPEC.md 8.2): 1 looks the shell up once at the pixel's
    /// centre; k averages k × k lookups at the sub-pixel offsets ((i + ½)/k − ½, (j + ½)/k −
    /// ½), each from the position and normal moved by the offsets times their fine screen
    /// derivatives, at the level of detail of D's derivatives divided by k.
    pub lookups: u32,
}

/// The world position and normal of every corner, per triangle: the vertex shader's
/// outputs.
struct WorldCorners {
    positions: Vec<[DVec3; 3]>,
    normals: Vec<[DVec3; 3]>,
}

fn check(viewport: Viewport, o: &ShellObject) -> Result<(), ModelError> {
    if viewport.width == 0
        || viewport.height == 0
        || viewport.width > 16384
        || viewport.height > 16384
    {
        return Err(ModelError::Viewport { width: viewport.width, height: viewport.height });
    }
    let l = o.layout;
    if l.faces != 6
        || l.width != l.height
        || l.width == 0
        || l.width > 16384
        || l.levels == 0
        || l.levels > TextureLayout::cube(l.width).levels
    {
        return Err(ModelError::Layout { width: l.width, height: l.height, levels: l.levels });
    }
    if o.normals.len() != o.positions.len() {
        return Err(ModelError::Uvs { positions: o.positions.len(), uvs: o.normals.len() });
    }
    if !o.indices.len().is_multiple_of(3) {
        return Err(ModelError::IndexCount(o.indices.len()));
    }
    if let Some((at, &index)) =
        o.indices.iter().enumerate().find(|(_, &i)| i as usize >= o.positions.len())
    {
        return Err(ModelError::Index { at, index, positions: o.positions.len() });
    }
    if let Some(k) = (0..o.positions.len())
        .find(|&k| !o.positions[k].iter().chain(o.normals[k].iter()).all(|v| v.is_finite()))
    {
        return Err(ModelError::NotFinite(k));
    }
    Ok(())
}

/// The render matrix of `object`'s shell in `viewport`, its fragments tested against
/// `occluders`; every row has coverage 1 (see [`crate::antialias`]). Rows are the pixels
/// that draw the shell, in increasing order.
pub fn shell_render_matrix(
    viewport: Viewport,
    object: &ShellObject,
    occluders: Option<&DepthBuffer>,
) -> Result<RenderMatrix, ModelError> {
    check(viewport, object)?;
    if let Some(o) = occluders {
        if o.viewport != viewport {
            return Err(ModelError::DepthSize { got: o.viewport, want: viewport });
        }
    }
    let (frags, world, pixels) = shell_fragments(viewport, object, occluders);
    let layout = object.layout;
    let eye = object.eye.as_dvec3();
    let max_level = layout.levels.saturating_sub(1) as f64;
    // Pixel p's coordinates and its triangle's interpolated world position and normal at
    // any pixel of the triangle's plane (the fragment shader's inputs): fine derivatives are
    // differences across p's 2×2 quad. As `cube_sample_pixel` in shell.wgsl, one lookup
    // takes D's derivatives alone, k × k lookups the attributes' too.
    let world = &world;
    let frags = &frags;
    let fragment = |p: u32| {
        let (x, y) = (p % viewport.width, p / viewport.width);
        let t = frags.triangle[p as usize] as usize;
        let (tri, src) = (&frags.triangles[t], frags.source[t] as usize);
        let at = move |x: u32, y: u32| attributes_at(tri, world, src, x, y);
        (x, y, at)
    };
    let dir = |pos: DVec3, n: DVec3| lookup_direction(&object.shell, pos, n, eye);
    let k = object.lookups.max(1);
    if k == 1 {
        let rows: Vec<Taps> = pixels
            .par_iter()
            .map(|&p| {
                let (x, y, at) = fragment(p);
                let d_at = |x: u32, y: u32| {
                    let (pos, n) = at(x, y);
                    dir(pos, n)
                };
                let (qx, qy) = (x & !1, y & !1);
                let d = d_at(x, y);
                let ddx = d_at(qx + 1, y) - d_at(qx, y);
                let ddy = d_at(x, qy + 1) - d_at(x, qy);
                let lambda = cube_lod(d, ddx, ddy, layout.width as f64, max_level);
                let mut taps = Taps::default();
                cube_taps(&layout, d, lambda, &mut taps);
                taps
            })
            .collect();
        return Ok(RenderMatrix::from_taps(viewport, layout, pixels, &rows));
    }
    // k × k lookups per pixel (SPEC.md 8.2): each chunk of pixels fills its own entries,
    // one row buffer reused from pixel to pixel.
    let kf = k as f64;
    let chunks: Vec<(Vec<u32>, Vec<f32>, Vec<u32>)> = pixels
        .par_chunks(ROWS_PER_CHUNK)
        .map(|chunk| {
            let (mut cols, mut vals, mut lens) =
                (Vec::new(), Vec::new(), Vec::with_capacity(chunk.len()));
            let mut row: Vec<(u32, f32)> =
                Vec::with_capacity(k as usize * k as usize * crate::filter::MAX_TAPS);
            let mut taps = Taps::default();
            for &p in chunk {
                let (x, y, at) = fragment(p);
                let (qx, qy) = (x & !1, y & !1);
                let (pos, n) = at(x, y);
                let ((px0, nx0), (px1, nx1)) = (at(qx, y), at(qx + 1, y));
                let ((py0, ny0), (py1, ny1)) = (at(x, qy), at(x, qy + 1));
                let (dpx, dnx, dpy, dny) = (px1 - px0, nx1 - nx0, py1 - py0, ny1 - ny0);
                let ddx = dir(px1, nx1) - dir(px0, nx0);
                let ddy = dir(py1, ny1) - dir(py0, ny0);
                let moved =
                    |ox: f64, oy: f64| dir(pos + ox * dpx + oy * dpy, n + ox * dnx + oy * dny);
                footprint_row(&layout, k, (ddx / kf, ddy / kf), moved, &mut taps, &mut row);
                cols.extend(row.iter().map(|e| e.0));
                vals.extend(row.iter().map(|e| e.1));
                lens.push(row.len() as u32);
            }
            (cols, vals, lens)
        })
        .collect();
    Ok(RenderMatrix::from_row_chunks(viewport, layout, pixels, chunks))
}

/// Pixels per parallel chunk of a render matrix with several lookups per pixel.
pub(crate) const ROWS_PER_CHUNK: usize = 256;

/// The object rasterized as the player draws it, each triangle's world corners, and the
/// pixels that draw the shell (in increasing order).
fn shell_fragments(
    viewport: Viewport,
    object: &ShellObject,
    occluders: Option<&DepthBuffer>,
) -> (Fragments, WorldCorners, Vec<u32>) {
    // Each triangle's corners carry barycentric (s, t) = (λ1, λ2): interpolated
    // perspective-correct, they weight the corners' world attributes as the GPU's
    // interpolation of those attributes does.
    let triangles = object.indices.len() / 3;
    let corners: Vec<[f32; 3]> =
        object.indices.iter().map(|&i| object.positions[i as usize]).collect();
    let bary: Vec<[f32; 2]> =
        (0..triangles).flat_map(|_| [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]).collect();
    let order: Vec<u32> = (0..corners.len() as u32).collect();
    let mesh = DrawMesh {
        positions: &corners,
        uvs: &bary,
        indices: &order,
        clip_from_object: object.clip_from_object,
    };
    let frags = Fragments::rasterize(&mesh, &TextureTransform::IDENTITY, viewport, occluders);
    let world = world_corners(object);
    let pixels: Vec<u32> = frags
        .pixels()
        .into_iter()
        .filter(|&p| {
            let src = frags.source[frags.triangle[p as usize] as usize] as usize;
            object.drawn.is_none_or(|d| d.get(src).copied().unwrap_or(false))
        })
        .collect();
    (frags, world, pixels)
}

/// Schlick's Fresnel factor ([`super::geometry::fresnel`]) at every pixel that draws the
/// shell, in the rows' order of [`shell_render_matrix`]: the factor the player multiplies
/// the reflection term by. Returns the pixels and one RGB factor per pixel.
pub fn shell_fresnel(
    viewport: Viewport,
    object: &ShellObject,
    occluders: Option<&DepthBuffer>,
    f0: [f32; 3],
) -> Result<(Vec<u32>, Vec<[f32; 3]>), ModelError> {
    check(viewport, object)?;
    let (frags, world, pixels) = shell_fragments(viewport, object, occluders);
    let (eye, f0) = (object.eye.as_dvec3(), Vec3::from(f0).as_dvec3());
    let f = pixels
        .par_iter()
        .map(|&p| {
            let k = frags.triangle[p as usize] as usize;
            let (pos, n) = attributes_at(
                &frags.triangles[k],
                &world,
                frags.source[k] as usize,
                p % viewport.width,
                p / viewport.width,
            );
            fresnel(f0, pos, n, eye).as_vec3().to_array()
        })
        .collect();
    Ok((pixels, f))
}

fn world_corners(o: &ShellObject) -> WorldCorners {
    let m = o.world_from_object;
    let (positions, normals) = o
        .indices
        .chunks_exact(3)
        .map(|t| {
            let t = [t[0], t[1], t[2]];
            let p = t.map(|i| {
                (m * Vec4::from((Vec3::from(o.positions[i as usize]), 1.0))).truncate().as_dvec3()
            });
            let n = t.map(|i| {
                (m * Vec4::from((Vec3::from(o.normals[i as usize]), 0.0))).truncate().as_dvec3()
            });
            (p, n)
        })
        .unzip();
    WorldCorners { positions, normals }
}

/// The interpolated world position and (unnormalized) normal at the centre of pixel (x, y)
/// of screen triangle `tri`, set up from mesh triangle `src`.
fn attributes_at(
    tri: &ScreenTriangle,
    world: &WorldCorners,
    src: usize,
    x: u32,
    y: u32,
) -> (DVec3, DVec3) {
    let [b1, b2] = texcoord_at(tri, x as f64 + 0.5, y as f64 + 0.5);
    let b0 = 1.0 - b1 - b2;
    let (p, n) = (&world.positions[src], &world.normals[src]);
    (p[0] * b0 + p[1] * b1 + p[2] * b2, n[0] * b0 + n[1] * b1 + n[2] * b2)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shell::geometry::ShellShape;
    use crate::transform::{look_at, perspective};

    /// A UV sphere of radius 1 at the origin, normals outward.
    pub(crate) fn ball(rings: u32, segments: u32) -> (Vec<[f32; 3]>, Vec<[f32; 3]>, Vec<u32>) {
        let mut p = Vec::new();
        for r in 0..=rings {
            let th = std::f32::consts::PI * r as f32 / rings as f32;
            for s in 0..=segments {
                let ph = 2.0 * std::f32::consts::PI * s as f32 / segments as f32;
                p.push([th.sin() * ph.cos(), th.cos(), th.sin() * ph.sin()]);
            }
        }
        let mut idx = Vec::new();
        let w = segments + 1;
        for r in 0..rings {
            for s in 0..segments {
                let (a, b, c, d) = (r * w + s, r * w + s + 1, (r + 1) * w + s, (r + 1) * w + s + 1);
                idx.extend_from_slice(&[a, c, b, b, c, d]);
            }
        }
        (p.clone(), p, idx)
    }

    #[test]
    fn a_mirror_ball_reads_every_face_with_unit_row_sums() {
        let (p, n, idx) = ball(24, 48);
        let vp = Viewport { width: 96, height: 72 };
        let eye = Vec3::new(0.0, 0.5, 3.5);
        let clip = perspective(0.7, 96.0 / 72.0, 0.1, 100.0) * look_at(eye, Vec3::ZERO, Vec3::Y);
        let shell = Shell { origin: DVec3::ZERO, shape: ShellShape::Sphere { radius: 4.0 } };
        let layout = TextureLayout::cube(16);
        let o = ShellObject {
            positions: &p,
            normals: &n,
            indices: &idx,
            clip_from_object: clip,
            world_from_object: Mat4::IDENTITY,
            eye,
            shell,
            layout,
            drawn: None,
            lookups: 1,
        };
        let a = shell_render_matrix(vp, &o, None).unwrap();
        assert!(a.rows() > 1000);
        for r in 0..a.rows() {
            let s: f32 = a.row(r).1.iter().sum();
            assert!((s - 1.0).abs() < 1e-4);
        }
        // A mirror ball reflects the whole sphere of directions: every face is read.
        let mut faces = [false; 6];
        for &c in &a.cols {
            faces[c as usize / layout.face_len()] = true;
        }
        assert_eq!(faces, [true; 6]);
    }

    #[test]
    fn triangles_that_do_not_draw_the_shell_have_no_rows() {
        let (p, n, idx) = ball(8, 16);
        let vp = Viewport { width: 48, height: 48 };
        let eye = Vec3::new(0.0, 0.0, 3.0);
        let clip = perspective(0.9, 1.0, 0.1, 100.0) * look_at(eye, Vec3::ZERO, Vec3::Y);
        let shell = Shell {
            origin: DVec3::ZERO,
            shape: ShellShape::Ellipsoid { radii: DVec3::new(1.5, 1.2, 1.5) },
        };
        let none = vec![false; idx.len() / 3];
        let mut o = ShellObject {
            positions: &p,
            normals: &n,
            indices: &idx,
            clip_from_object: clip,
            world_from_object: Mat4::IDENTITY,
            eye,
            shell,
            layout: TextureLayout::cube(8),
            drawn: None,
            lookups: 1,
        };
        assert!(shell_render_matrix(vp, &o, None).unwrap().rows() > 0);
        o.drawn = Some(&none);
        assert_eq!(shell_render_matrix(vp, &o, None).unwrap().rows(), 0);
    }
}
