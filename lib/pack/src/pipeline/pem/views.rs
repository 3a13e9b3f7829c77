//! Every point as an object's shells see it: per shell, the render matrix A of the hardware
//! model's environment-map lookup (thesis 5.8: "test renderings with environment mapping
//! instead of texture mapping"), restricted to the pixels the tracer covers; the Fresnel
//! factor the player multiplies the reflection term by; and the tracer's local (RGBA,
//! premultiplied) and distant (RGB) incident specular layers there (5.7), which the shells
//! are solved for.

use anyhow::{anyhow, Result};
use pis_compile::shell::{shell_fresnel, shell_render_matrix, Shell, ShellObject};
use pis_compile::{scene_depth, DrawMesh, RenderMatrix, TextureLayout, Viewport};
use pis_trace::layers::LayerKind as TraceLayer;
use rayon::prelude::*;

use super::super::input::LoadedSet;
use super::super::mesh::{occluding_indices, Mesh};
use super::super::rows::restrict_rows;
use super::super::surface::coverage;

/// One point as the shells see it: the rows are the covered pixels, in the order of the
/// object's surface render matrices at the point.
pub struct ShellView {
    /// Per shell of the object, in the object's shell order: its render matrix.
    pub a: Vec<RenderMatrix>,
    /// F per row, RGB.
    pub fresnel: Vec<f32>,
    /// The tracer's local layer per row: premultiplied RGB and alpha (4 values).
    pub local: Vec<f32>,
    /// The tracer's distant layer per row (RGB).
    pub distant: Vec<f32>,
}

/// The tracer's layer `kind` of object channel `channel` at point `p`, `channels` values per
/// pixel (missing channels 0).
fn layer_values(
    set: &LoadedSet,
    p: usize,
    o: usize,
    kind: TraceLayer,
    names: &[&str],
) -> Result<Vec<f32>> {
    let (w, h) = set.resolution;
    let n = (w * h) as usize;
    let mut out = vec![0.0f32; n * names.len()];
    if let Some(l) = set.images.object(p, o)?.object_layer(&set.channels[o], kind) {
        for (c, name) in names.iter().enumerate() {
            if let Some(plane) = l.channel(name) {
                for k in 0..n {
                    out[k * names.len() + c] = plane[k];
                }
            }
        }
    }
    Ok(out)
}

fn gather_n(pixels: &[u32], values: &[f32], n: usize) -> Vec<f32> {
    pixels
        .iter()
        .flat_map(|&p| values[p as usize * n..p as usize * n + n].iter().copied())
        .collect()
}

/// The shell object of `o` at point `p` for `shell` with `layout`, its eye and its
/// clip-from-object, as the player draws it.
fn shell_object<'m>(
    set: &LoadedSet,
    p: usize,
    o: usize,
    mesh: &'m Mesh,
    (shell, layout, drawn): (&Shell, TextureLayout, Option<&'m [bool]>),
    lookups: u32,
) -> ShellObject<'m> {
    let (w, h) = set.resolution;
    let frame = &set.frames[p];
    let world = frame.instances[o].world_from_object;
    let clip = pis_trace::camera::projection_matrix(&frame.camera, (w, h))
        * frame.camera.world_from_camera.inverse()
        * world;
    ShellObject {
        positions: &mesh.positions,
        normals: &mesh.normals,
        indices: &mesh.indices,
        clip_from_object: clip,
        world_from_object: world,
        eye: frame.camera.world_from_camera.w_axis.truncate(),
        shell: shell.clone(),
        layout,
        drawn,
        lookups,
    }
}

/// The scene's depth at point `p` without object `o`: its occluders.
fn occluders(
    set: &LoadedSet,
    p: usize,
    o: usize,
    meshes: &[Mesh],
) -> Result<pis_compile::DepthBuffer> {
    let (w, h) = set.resolution;
    let frame = &set.frames[p];
    let view_proj = pis_trace::camera::projection_matrix(&frame.camera, (w, h))
        * frame.camera.world_from_camera.inverse();
    let draw: Vec<DrawMesh> = meshes
        .iter()
        .enumerate()
        .map(|(k, m)| DrawMesh {
            positions: &m.positions,
            uvs: &m.uvs,
            indices: occluding_indices(meshes, o, k),
            clip_from_object: view_proj * frame.instances[k].world_from_object,
        })
        .collect();
    Ok(scene_depth(Viewport { width: w, height: h }, &draw, Some(o))?)
}

/// `a` with a row at every pixel of `pixels` (ascending, a superset of `a`'s): its own row
/// where it has one, else an empty row (the shell is not drawn there).
fn with_rows_at(a: &RenderMatrix, pixels: &[u32]) -> RenderMatrix {
    let mut out = RenderMatrix {
        width: a.width,
        height: a.height,
        layout: a.layout,
        row_start: vec![0],
        ..Default::default()
    };
    let mut r = 0;
    for &p in pixels {
        while r < a.rows() && a.pixels[r] < p {
            r += 1;
        }
        if r < a.rows() && a.pixels[r] == p {
            let (c, v) = a.row(r);
            out.cols.extend_from_slice(c);
            out.vals.extend_from_slice(v);
            out.coverage.push(a.coverage[r]);
        } else {
            out.coverage.push(0.0);
        }
        out.row_start.push(out.cols.len() as u32);
        out.pixels.push(p);
    }
    out
}

/// The set's points `points` as object `o`'s `shells` (each with its cube layout, and the
/// triangles it is drawn on: `None` all of them) see them. `pixels[k]` are the rows of the
/// object's surface render matrices at point `points[k]`, which the shells' rows must equal;
/// a pixel whose triangle does not draw a shell has an empty row in its matrix.
/// Each pixel looks every shell up `lookups` × `lookups` times (SPEC.md 8.2).
pub fn shell_views(
    set: &LoadedSet,
    o: usize,
    meshes: &[Mesh],
    shells: &[(Shell, TextureLayout, Option<&[bool]>)],
    lookups: u32,
    f0: [f32; 3],
    (pixels, points): (&[Vec<u32>], &[usize]),
) -> Result<Vec<ShellView>> {
    let (w, h) = set.resolution;
    let vp = Viewport { width: w, height: h };
    let name = &set.scene.objects[o].name;
    points
        .par_iter()
        .zip(pixels)
        .map(|(&p, pixels)| {
            let depth = occluders(set, p, o, meshes)?;
            let cov = coverage(set, p, o)?;
            let mut a = Vec::with_capacity(shells.len());
            for (shell, layout, drawn) in shells {
                let m = shell_render_matrix(vp, &shell_object(set, p, o, &meshes[o], (shell, *layout, *drawn), lookups), Some(&depth))?;
                let mut m = restrict_rows(&m, &cov);
                if drawn.is_some() {
                    m = with_rows_at(&m, pixels);
                }
                if m.pixels != *pixels {
                    return Err(anyhow!("object {name}: point {p}: the shell and surface render matrices cover different pixels"));
                }
                a.push(m);
            }
            let (fp, f) = shell_fresnel(vp, &shell_object(set, p, o, &meshes[o], (&shells[0].0, shells[0].1, None), 1), Some(&depth), f0)?;
            let mut fresnel = Vec::with_capacity(pixels.len() * 3);
            let mut k = 0;
            for &px in pixels {
                while fp[k] != px {
                    k += 1;
                }
                fresnel.extend_from_slice(&f[k]);
            }
            let local = gather_n(pixels, &layer_values(set, p, o, TraceLayer::Local, &["R", "G", "B", "A"])?, 4);
            let distant = gather_n(pixels, &layer_values(set, p, o, TraceLayer::Distant, &["R", "G", "B"])?, 3);
            Ok(ShellView { a, fresnel, local, distant })
        })
        .collect()
}

/// The cube-face resolution of a shell (thesis 5.8.2: "test renderings to determine the most
/// detailed EM MIPMAP level actually accessed"): `shell` drawn with a `largest`-texel cube
/// map at every `step`-th point; the finest level that at least [`ACCESS_SHARE`] of the rows
/// read is the level whose size is chosen (at least [`MIN_FACE`]). The renderings look the
/// shell up once per pixel whatever `--shell-lookups` is: sub-pixel lookups shape a pixel's
/// footprint, they do not make the pixel see finer detail (measured at the teapot-pem paper
/// preset at 384:1: sized from 2 × 2 lookups, the faces doubled and the lid's local shell
/// was left no bytes).
pub fn face_resolution(
    set: &LoadedSet,
    o: usize,
    meshes: &[Mesh],
    shell: &Shell,
    largest: u32,
) -> Result<u32> {
    let (w, h) = set.resolution;
    let vp = Viewport { width: w, height: h };
    let layout = TextureLayout::cube(largest);
    let step = set.frames.len().div_ceil(8).max(1);
    let mut finest = vec![0usize; layout.levels as usize];
    for p in (0..set.frames.len()).step_by(step) {
        let depth = occluders(set, p, o, meshes)?;
        let a = restrict_rows(
            &shell_render_matrix(
                vp,
                &shell_object(set, p, o, &meshes[o], (shell, layout, None), 1),
                Some(&depth),
            )?,
            &coverage(set, p, o)?,
        );
        for r in 0..a.rows() {
            let (cols, vals) = a.row(r);
            let level = cols
                .iter()
                .zip(vals)
                .filter(|(_, &v)| v > 0.0)
                .map(|(&c, _)| level_of(&layout, c as usize))
                .min();
            if let Some(l) = level {
                finest[l] += 1;
            }
        }
    }
    let total: usize = finest.iter().sum();
    let mut seen = 0;
    for (l, &n) in finest.iter().enumerate() {
        seen += n;
        if seen as f64 >= ACCESS_SHARE * total as f64 && total > 0 {
            return Ok((largest >> l).max(MIN_FACE));
        }
    }
    Ok(MIN_FACE)
}

/// The share of rows whose finest level read decides the face resolution.
pub const ACCESS_SHARE: f64 = 0.02;
/// The smallest cube face chosen.
pub const MIN_FACE: u32 = 8;
/// The largest cube face tried when choosing a shell's resolution (thesis 5.8.2).
pub const LARGEST_FACE: u32 = 256;

/// The MIP level of column `c` of a cube layout.
fn level_of(layout: &TextureLayout, c: usize) -> usize {
    let within = c % layout.face_len();
    (0..layout.levels).rev().find(|&m| layout.level_offset(m) <= within).unwrap_or(0) as usize
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_are_placed_at_their_pixels_and_the_others_left_empty() {
        let a = RenderMatrix {
            width: 4,
            height: 1,
            layout: TextureLayout::cube(1),
            row_start: vec![0, 2, 3],
            cols: vec![0, 1, 5],
            vals: vec![0.25, 0.75, 1.0],
            pixels: vec![1, 3],
            coverage: vec![1.0, 0.5],
        };
        let b = with_rows_at(&a, &[0, 1, 2, 3]);
        assert_eq!(b.pixels, [0, 1, 2, 3]);
        assert_eq!(b.coverage, [0.0, 1.0, 0.0, 0.5]);
        assert_eq!(b.row(0).0.len(), 0);
        assert_eq!(b.row(1), (&[0u32, 1][..], &[0.25f32, 0.75][..]));
        assert_eq!(b.row(2).0.len(), 0);
        assert_eq!(b.row(3), (&[5u32][..], &[1.0f32][..]));
    }
}
