//! The render matrix A of one shell of a lens object's term at one view (thesis 6.3.3: "the
//! two rendering matrices A_R and A_T, corresponding to hybrid rendering with an initial
//! reflection or refraction"): the frame's tessellation ([`super::tessellate()`]) is
//! rasterized as the player draws it; per vertex the term's outgoing ray meets the shell and
//! the hit point minus the shell's origin is the vertex's cube-map vector ([`shell_vector`],
//! thesis 6.4.2); per pixel the vectors are interpolated perspective-correct, and the cube
//! lookup (face, LOD from fine derivatives, trilinear seamless taps over every stored level:
//! [`crate::shell::cube`]) gives the row. A triangle draws the term where a vertex has its
//! path ([`Missing`]: the others have F·G 0); the F·G modulation is the player's to multiply, per vertex
//! interpolated, and is not in A (the shells hold the radiance along the outgoing rays).

use glam::{DVec3, Mat4};
use rayon::prelude::*;

use super::path::{LensPath, Term};
use super::tessellate::Tessellation;
use crate::filter::Taps;
use crate::interpolate::texcoord_at;
use crate::raster::{DepthBuffer, Fragments};
use crate::shell::cube::{cube_lod, cube_taps, footprint_row};
use crate::shell::geometry::{shell_hit, Shell};
use crate::shell::model::ROWS_PER_CHUNK;
use crate::transform::{DrawMesh, TextureTransform, Viewport};
use crate::{RenderMatrix, TextureLayout};

/// The cube-map vector of `shell` for an outgoing ray: where the ray meets the shell minus
/// the shell's origin, rounded to `f32` as the player's vertex buffer holds it; `None` where
/// the ray does not meet the shell.
pub fn shell_vector(shell: &Shell, path: &LensPath) -> Option<[f32; 3]> {
    let (o, d) = (path.exit_origin.as_dvec3(), path.exit_direction.as_dvec3());
    let t = shell_hit(shell, o, d);
    (t >= 0.0).then(|| (o + d * t - shell.origin).as_vec3().to_array())
}

/// Per vertex of `tess`, the cube-map vector of `shell` for `term`, `None` where the vertex
/// has no such path or its ray misses the shell.
pub fn vertex_vectors(tess: &Tessellation, term: Term, shell: &Shell) -> Vec<Option<[f32; 3]>> {
    tess.vertices
        .par_iter()
        .map(|v| v.paths[term as usize].as_ref().and_then(|p| shell_vector(shell, p)))
        .collect()
}

/// What a triangle's corner without a value takes, where its other corners have one: the
/// term's path ends inside the lens object there (cut after the last interface), so its
/// F·G is 0 ([`Missing::Zero`]), and its cube vector, which F·G = 0 makes irrelevant, is
/// the mean of the others' ([`Missing::Mean`]), so that the lookup stays where the valid
/// corners look.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Missing {
    Zero,
    Mean,
}

/// Per triangle of `tess`, its corners' values for one term (`None`: no corner has one,
/// the triangle does not draw the term); corners without a value take `missing`, the mean
/// computed in `f32`. What the player's vertex buffer holds, corner by corner.
pub fn corner_values(
    tess: &Tessellation,
    values: &[Option<[f32; 3]>],
    missing: Missing,
) -> Vec<Option<[[f32; 3]; 3]>> {
    tess.triangles
        .par_iter()
        .map(|t| {
            let v = t.map(|i| values[i as usize]);
            let n = v.iter().flatten().count();
            if n == 0 {
                return None;
            }
            let fill = match missing {
                Missing::Zero => [0.0; 3],
                Missing::Mean => {
                    // The valid corners summed in corner order, then divided.
                    let s = v
                        .iter()
                        .flatten()
                        .fold([0.0f32; 3], |a, x| [a[0] + x[0], a[1] + x[1], a[2] + x[2]]);
                    let n = n as f32;
                    [s[0] / n, s[1] / n, s[2] / n]
                }
            };
            Some(v.map(|x| x.unwrap_or(fill)))
        })
        .collect()
}

/// The pixels that draw the term (increasing order) and, per pixel, its interpolated cube
/// vector and those of its right and lower neighbours in the 2×2 quad (fine derivatives).
pub struct HybridPixels {
    pub pixels: Vec<u32>,
    pub vectors: Vec<[DVec3; 3]>,
}

/// The pixels of `tess` (world positions, drawn with `clip_from_world`) that draw a term
/// with per-vertex values `vectors` (a triangle draws where at least one corner has a
/// value; the others take `missing`), depth-tested against the tessellation itself and
/// `occluders`.
pub fn hybrid_pixels(
    viewport: Viewport,
    tess: &Tessellation,
    clip_from_world: Mat4,
    vectors: &[Option<[f32; 3]>],
    missing: Missing,
    occluders: Option<&DepthBuffer>,
) -> HybridPixels {
    // Each triangle's corners carry barycentric (s, t) = (λ1, λ2), interpolated
    // perspective-correct like the player's vertex attributes.
    let corners: Vec<[f32; 3]> = tess
        .triangles
        .iter()
        .flat_map(|t| t.map(|i| tess.vertices[i as usize].position.to_array()))
        .collect();
    let bary: Vec<[f32; 2]> =
        tess.triangles.iter().flat_map(|_| [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]).collect();
    let order: Vec<u32> = (0..corners.len() as u32).collect();
    let mesh = DrawMesh {
        positions: &corners,
        uvs: &bary,
        indices: &order,
        clip_from_object: clip_from_world,
    };
    let frags = Fragments::rasterize(&mesh, &TextureTransform::IDENTITY, viewport, occluders);
    let corner_vectors: Vec<Option<[DVec3; 3]>> = corner_values(tess, vectors, missing)
        .into_iter()
        .map(|c| c.map(|c| c.map(|x| DVec3::from(x.map(f64::from)))))
        .collect();
    let pixels: Vec<u32> = frags
        .pixels()
        .into_iter()
        .filter(|&p| {
            corner_vectors[frags.source[frags.triangle[p as usize] as usize] as usize].is_some()
        })
        .collect();
    let vectors = pixels
        .par_iter()
        .map(|&p| {
            let (x, y) = (p % viewport.width, p / viewport.width);
            let k = frags.triangle[p as usize] as usize;
            let (tri, src) = (&frags.triangles[k], frags.source[k] as usize);
            let v = corner_vectors[src].expect("pixels of drawn triangles");
            let at = |x: u32, y: u32| {
                let [b1, b2] = texcoord_at(tri, x as f64 + 0.5, y as f64 + 0.5);
                v[0] * (1.0 - b1 - b2) + v[1] * b1 + v[2] * b2
            };
            let (qx, qy) = (x & !1, y & !1);
            [at(x, y), at(qx + 1, y) - at(qx, y), at(x, qy + 1) - at(x, qy)]
        })
        .collect();
    HybridPixels { pixels, vectors }
}

/// The render matrix of one shell (per-vertex vectors `vectors`, cube layout `layout`) for
/// one term of the tessellated lens object; rows are [`hybrid_pixels`]'s pixels. With
/// `lookups` k > 1 a row is the mean of k × k lookups at the sub-pixel offsets
/// o = ((i + ½)/k − ½, (j + ½)/k − ½), each along d + o_x·∂d/∂x + o_y·∂d/∂y (the vector moved
/// by its fine derivatives) at the LOD of the derivatives divided by k, as the reflection
/// shells' `cube_sample_pixel` (SPEC.md 8.2): the pixel's footprint, which the tracer's
/// samples average, instead of its centre.
pub fn hybrid_render_matrix(
    viewport: Viewport,
    tess: &Tessellation,
    clip_from_world: Mat4,
    vectors: &[Option<[f32; 3]>],
    layout: TextureLayout,
    lookups: u32,
    occluders: Option<&DepthBuffer>,
) -> RenderMatrix {
    let px = hybrid_pixels(viewport, tess, clip_from_world, vectors, Missing::Mean, occluders);
    let k = lookups.max(1);
    if k == 1 {
        let max_level = layout.levels.saturating_sub(1) as f64;
        let rows: Vec<Taps> = px
            .vectors
            .par_iter()
            .map(|&[d, ddx, ddy]| {
                let lambda = cube_lod(d, ddx, ddy, layout.width as f64, max_level);
                let mut taps = Taps::default();
                cube_taps(&layout, d, lambda, &mut taps);
                taps
            })
            .collect();
        return RenderMatrix::from_taps(viewport, layout, px.pixels, &rows);
    }
    let kf = k as f64;
    let chunks: Vec<(Vec<u32>, Vec<f32>, Vec<u32>)> = px
        .vectors
        .par_chunks(ROWS_PER_CHUNK)
        .map(|chunk| {
            let (mut cols, mut vals, mut lens) =
                (Vec::new(), Vec::new(), Vec::with_capacity(chunk.len()));
            let mut row = Vec::with_capacity(k as usize * k as usize * crate::filter::MAX_TAPS);
            let mut taps = Taps::default();
            for &[d, ddx, ddy] in chunk {
                let moved = |ox: f64, oy: f64| d + ox * ddx + oy * ddy;
                footprint_row(&layout, k, (ddx / kf, ddy / kf), moved, &mut taps, &mut row);
                cols.extend(row.iter().map(|e| e.0));
                vals.extend(row.iter().map(|e| e.1));
                lens.push(row.len() as u32);
            }
            (cols, vals, lens)
        })
        .collect();
    RenderMatrix::from_row_chunks(viewport, layout, px.pixels, chunks)
}

/// One term of a lens object as the player draws it (SPEC.md 9; `frame/hybrid.wgsl`'s
/// `hybrid_term` is its twin): at every pixel of `fg` (the pixels that draw the term, each
/// with its interpolated F·G in `vectors[k][0]`), the term's shells looked up through their
/// render matrices `a` (one per shell, in order, order 0 nearest; rows a subset of `fg`'s
/// pixels) in their RGBA cube maps `cubes` (premultiplied colour, then alpha), composited
/// "over" in increasing order — `rgb += through · c.rgb`, `through ·= 1 − clamp(c.a, 0, 1)`
/// — and multiplied by F·G. Returns RGB per pixel of `fg`, in its order.
pub fn term_radiance(fg: &HybridPixels, a: &[&RenderMatrix], cubes: &[&[f32]]) -> Vec<[f32; 3]> {
    let n = fg.pixels.len();
    let mut acc = vec![[0.0f32; 3]; n];
    let mut through = vec![1.0f32; n];
    for (m, cube) in a.iter().zip(cubes) {
        let mut k = 0;
        for r in 0..m.rows() {
            let p = m.pixels[r];
            while k < n && fg.pixels[k] < p {
                k += 1;
            }
            if k == n || fg.pixels[k] != p {
                continue;
            }
            let (cols, vals) = m.row(r);
            let mut c = [0.0f32; 4];
            for (&col, &w) in cols.iter().zip(vals) {
                let t = &cube[col as usize * 4..col as usize * 4 + 4];
                for ch in 0..4 {
                    c[ch] += w * t[ch];
                }
            }
            for ch in 0..3 {
                acc[k][ch] += through[k] * c[ch];
            }
            through[k] *= 1.0 - c[3].clamp(0.0, 1.0);
        }
    }
    acc.iter()
        .zip(&fg.vectors)
        .map(|(c, v)| [c[0] * v[0].x as f32, c[1] * v[0].y as f32, c[2] * v[0].z as f32])
        .collect()
}

/// Per vertex of `tess`, the F·G modulation of `term` (`None` where the vertex has no such
/// path): what [`hybrid_pixels`] interpolates, with [`Missing::Zero`], for [`term_radiance`].
pub fn vertex_modulation(tess: &Tessellation, term: Term) -> Vec<Option<[f32; 3]>> {
    tess.vertices.iter().map(|v| v.paths[term as usize].map(|p| p.modulation.to_array())).collect()
}
