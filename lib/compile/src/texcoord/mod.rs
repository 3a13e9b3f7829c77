//! Texture-coordinate and resolution optimization per object per parameter block (thesis
//! 3.2):
//!
//! 1. branch cuts in wrapped dimensions ([`branch_cut`]);
//! 2. the least-squares most-isometric linear map, eq. 3.1 ([`isometry`]);
//! 3. and 4. scaling until the largest singular value of the texture→screen Jacobian is
//!    under a threshold at every covered pixel ([`stretch`]);
//! 5. the minimum-area bounding rectangle over discrete directions ([`bounding`]);
//! 6. the used resolution, times a per-object reduction factor: the user's, or the one that
//!    keeps level 0 within a texel budget per covered pixel ([`TexcoordSettings::texels_per_pixel`]).
//!
//! Visibility comes from a minimal triangle-identifier z-buffer ([`visibility`]).
//!
//! The result is the affine transform of format-spec/SPEC.md 7.3:
//! `s = a·u + b·v + e`, `t = c·u + d·v + f`, (s, t) ∈ [0, 1]² spanning the used texture.
//! Where a branch cut was made the transform applies to the cut coordinates
//! `w' = (w − w_cut) − ⌊w − w_cut⌋` ([`TexturePlacement::branch_cut`]), which the geometry
//! handed to the player must carry.

pub mod bounding;
pub mod branch_cut;
pub mod charts;
pub mod edges;
pub mod isometry;
pub mod rechart;
pub mod stretch;
pub mod visibility;

use glam::{DMat2, DVec2, Vec2};

use crate::CompileError;
use edges::visible_edges;
use isometry::EdgeTerm;
pub use visibility::ViewGeometry;

/// Settings of texture-coordinate optimization.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TexcoordSettings {
    /// The largest texture→screen stretch allowed (thesis: 1.25).
    pub max_stretch: f64,
    /// Directions searched for the minimum-area rectangle over 90°.
    pub directions: u32,
    /// The object's resolution reduction factor (1: the optimal resolution; 0.5: half).
    pub reduction: f64,
    /// Largest used width or height (SPEC.md 7.3 allows 16384).
    pub max_size: u32,
    /// Texel budget: at most this many level-0 texels per pixel the object covers in its
    /// most covered view; a placement over budget is reduced further, uniformly. One
    /// affine map must reach the density of the most magnified pixel over the whole
    /// visible extent, so objects spanning large depth ranges (a floor) get many texels
    /// that only minified pixels read, through coarser MIP levels; beyond about one
    /// texel per pixel they add unknowns that no pixel constrains (thesis 3.2's
    /// per-object reduction factor, chosen automatically). None: no budget.
    pub texels_per_pixel: Option<f64>,
}

impl Default for TexcoordSettings {
    fn default() -> Self {
        TexcoordSettings {
            max_stretch: 1.25,
            directions: 90,
            reduction: 1.0,
            max_size: 16384,
            texels_per_pixel: None,
        }
    }
}

/// An object's mesh: per-vertex texture coordinates, triangles, and which texture
/// dimensions are periodic (wrapping enabled).
#[derive(Clone, Copy, Debug)]
pub struct ObjectMesh<'a> {
    pub name: &'a str,
    pub uvs: &'a [Vec2],
    pub indices: &'a [u32],
    pub wrap: [bool; 2],
}

/// The texture placement of one object in one parameter block.
#[derive(Clone, Debug, PartialEq)]
pub struct TexturePlacement {
    /// [a, b, c, d, e, f] of SPEC.md 7.3.
    pub affine: [f32; 6],
    /// Used texture size in texels; a power of two along a dimension that repeats.
    pub width: u32,
    pub height: u32,
    /// Whether the texture wraps along s and t (a periodic dimension without a cut).
    pub repeat: [bool; 2],
    /// The branch cut position along u and v, where one was made.
    pub branch_cut: [Option<f64>; 2],
    /// The largest texture→screen stretch over the covered pixels after scaling, at the
    /// optimal resolution (before the reduction factor).
    pub stretch: f64,
    /// Visible edges used over all views of the block.
    pub visible_edges: usize,
    /// The reduction factor applied: the settings' factor, times the texel budget's.
    pub reduction: f64,
    /// Pixels the object covers in its most covered view of the block.
    pub covered_pixels: usize,
}

impl TexturePlacement {
    /// (s, t) of texture coordinate (u, v) (after any branch cut).
    pub fn apply(&self, u: f32, v: f32) -> (f32, f32) {
        let [a, b, c, d, e, f] = self.affine;
        (a * u + b * v + e, c * u + d * v + f)
    }
}

/// Chooses the affine texture transform and used resolution of `mesh` for the views of one
/// parameter block (thesis 3.2). `views[k].clip` holds the mesh's clip-space vertices.
/// An object no view sees gets a 1×1 texture.
pub fn optimize_placement(
    mesh: &ObjectMesh<'_>,
    views: &[ViewGeometry],
    settings: &TexcoordSettings,
) -> Result<TexturePlacement, CompileError> {
    let fail = |message: String| CompileError::Geometry { object: mesh.name.to_string(), message };
    check_inputs(mesh, views, settings)?;

    // Step 1: branch cuts.
    let Cut { cut, repeat, uvs, per_view } = cut_branches(mesh, views);
    let edges: Vec<_> = per_view.iter().flat_map(|(e, _)| e.iter().copied()).collect();
    if edges.is_empty() {
        return Ok(TexturePlacement {
            affine: [1.0, 0.0, 0.0, 1.0, 0.0, 0.0],
            width: 1,
            height: 1,
            repeat,
            branch_cut: cut,
            stretch: 0.0,
            visible_edges: 0,
            reduction: settings.reduction,
            covered_pixels: 0,
        });
    }

    // Step 2: the most isometric linear map.
    let scale_only = repeat[0] || repeat[1];
    let r = most_isometric_map(&edges, scale_only);

    // Steps 3–4: scale until the stretch is under the threshold at every covered pixel.
    let jacobians = stretch_envelopes(mesh, views, &uvs);
    let (r, stretch) = stretch::limit_stretch(r, &jacobians, settings.max_stretch, scale_only);

    // Step 5: the minimum-area rectangle (no rotation when a dimension wraps).
    let (m, lo, hi) = bounding_rectangle(&edges, r, repeat, settings.directions);

    // Step 6: the used resolution, reduced to the texel budget.
    let ext = hi - lo;
    let covered_pixels = per_view.iter().map(|&(_, covered)| covered).max().unwrap_or(0);
    let (width, height, reduction) = used_resolution(ext, covered_pixels, repeat, settings);
    let affine = affine_of(m, lo, ext, repeat);
    let det = affine[0] * affine[3] - affine[1] * affine[2];
    if !(det.is_finite() && det != 0.0) {
        return Err(fail(format!("degenerate texture transform (determinant {det})")));
    }
    Ok(TexturePlacement {
        affine: affine.map(|v| v as f32),
        width,
        height,
        repeat,
        branch_cut: cut,
        stretch,
        visible_edges: edges.len(),
        reduction,
        covered_pixels,
    })
}

/// Indices within the mesh, one clip-space vertex per texture coordinate in every view, all
/// finite, and settings in range.
fn check_inputs(
    mesh: &ObjectMesh<'_>,
    views: &[ViewGeometry],
    settings: &TexcoordSettings,
) -> Result<(), CompileError> {
    let fail = |message: String| CompileError::Geometry { object: mesh.name.to_string(), message };
    if !mesh.indices.len().is_multiple_of(3) {
        return Err(fail(format!(
            "{} indices is not a whole number of triangles",
            mesh.indices.len()
        )));
    }
    if let Some(&i) = mesh.indices.iter().find(|&&i| i as usize >= mesh.uvs.len()) {
        return Err(fail(format!("index {i} past {} texture coordinates", mesh.uvs.len())));
    }
    for (k, v) in views.iter().enumerate() {
        if v.clip.len() != mesh.uvs.len() {
            return Err(fail(format!(
                "view {k} has {} vertices, the mesh {}",
                v.clip.len(),
                mesh.uvs.len()
            )));
        }
        if v.clip.iter().any(|c| !c.is_finite()) || mesh.uvs.iter().any(|u| !u.is_finite()) {
            return Err(fail(format!("view {k}: non-finite vertex or texture coordinate")));
        }
    }
    if !(settings.max_stretch > 0.0 && settings.reduction > 0.0 && settings.reduction.is_finite()) {
        return Err(CompileError::Setting("max stretch and reduction must be > 0".into()));
    }
    if settings.texels_per_pixel.is_some_and(|k| !(k > 0.0 && k.is_finite())) {
        return Err(CompileError::Setting("the texel budget per pixel must be > 0".into()));
    }
    Ok(())
}

/// Step 1's result: the cut along u and v, where one was made; whether a dimension wraps;
/// the texture coordinates after the cuts; and each view's visible edges in them, with the
/// pixels it covers.
struct Cut {
    cut: [Option<f64>; 2],
    repeat: [bool; 2],
    uvs: Vec<Vec2>,
    per_view: Vec<(Vec<edges::VisibleEdge>, usize)>,
}

/// Step 1: branch cuts, from the visible edges' extents in the original coordinates. Each
/// view's edges are kept, and the pixels it covers counted; its triangle-id buffer (one
/// entry per pixel) is not: steps 3–4 rasterize each view again, one at a time, so that
/// memory does not grow with the number of views.
fn cut_branches(mesh: &ObjectMesh<'_>, views: &[ViewGeometry]) -> Cut {
    let edges_of = |uvs: &[Vec2]| -> Vec<(Vec<edges::VisibleEdge>, usize)> {
        views
            .iter()
            .map(|v| {
                let (e, ids) = visible_edges(v, uvs, mesh.indices);
                (e, ids.ids.iter().filter(|id| id.is_some()).count())
            })
            .collect()
    };
    let first = edges_of(mesh.uvs);
    let mut cut = [None, None];
    let mut repeat = [false, false];
    for dim in 0..2 {
        if !mesh.wrap[dim] {
            continue;
        }
        let extents: Vec<(f64, f64)> = first
            .iter()
            .flat_map(|(e, _)| e.iter())
            .map(|e| {
                let (p, q) = (e.uv[0][dim], e.uv[1][dim]);
                (p.min(q), p.max(q))
            })
            .collect();
        cut[dim] = branch_cut::find_cut(&extents);
        repeat[dim] = cut[dim].is_none();
        if cut[dim].is_some_and(|c| branch_cut::gap_holds_the_seam(&extents, c)) {
            // The visible part already lies inside one period: the coordinates stay as
            // they are and wrapping goes off. (A cut at the seam would send vertices at
            // w = 1 to 0 and fold the triangles beside them across the whole texture.)
            cut[dim] = None;
        }
    }
    let uvs: Vec<Vec2> = mesh
        .uvs
        .iter()
        .map(|uv| {
            let mut w = uv.as_dvec2();
            for dim in 0..2 {
                if let Some(c) = cut[dim] {
                    w[dim] = branch_cut::apply_cut(w[dim], c);
                }
            }
            w.as_vec2()
        })
        .collect();
    let per_view = if cut.iter().any(Option::is_some) { edges_of(&uvs) } else { first };
    Cut { cut, repeat, uvs, per_view }
}

/// Step 2: the most isometric linear map of the visible edges (eq. 3.1), a scale only
/// when a dimension wraps.
fn most_isometric_map(edges: &[edges::VisibleEdge], scale_only: bool) -> DMat2 {
    let terms: Vec<EdgeTerm> = edges
        .iter()
        .map(|e| EdgeTerm {
            screen_length: e.screen_length,
            duv: e.uv[1] - e.uv[0],
            weight: e.weight,
        })
        .collect();
    let r = isometry::most_isometric(&terms, scale_only);
    DMat2::from_cols(DVec2::new(r[0], r[2]), DVec2::new(r[1], r[3]))
}

/// Steps 3–4's input: the texture→screen Jacobians at the covered pixels of every view, of
/// which each view keeps those that can be the most stretched.
fn stretch_envelopes(mesh: &ObjectMesh<'_>, views: &[ViewGeometry], uvs: &[Vec2]) -> Vec<DMat2> {
    let mut jacobians = Vec::new();
    let mut in_view = Vec::new();
    for view in views {
        in_view.clear();
        let ids = visibility::rasterize_ids(view, mesh.indices);
        for (k, id) in ids.ids.iter().enumerate() {
            let Some(t) = id else { continue };
            let tri = &mesh.indices[3 * *t as usize..3 * *t as usize + 3];
            let Some(sv) = visibility::screen_triangle(view, tri) else { continue };
            let p = DVec2::new(
                (k % view.width as usize) as f64 + 0.5,
                (k / view.width as usize) as f64 + 0.5,
            );
            let tuv = [uvs[tri[0] as usize], uvs[tri[1] as usize], uvs[tri[2] as usize]];
            if let Some(j) = visibility::uv_jacobian(&sv, tuv, p) {
                in_view.push(j);
            }
        }
        jacobians.extend(stretch::envelope(&in_view));
    }
    jacobians
}

/// Step 5: the map `r` turned by the minimum-area rectangle of the mapped edges (not turned
/// when a dimension wraps, which keeps one whole period), with the rectangle's corners.
fn bounding_rectangle(
    edges: &[edges::VisibleEdge],
    r: DMat2,
    repeat: [bool; 2],
    directions: u32,
) -> (DMat2, DVec2, DVec2) {
    let points: Vec<DVec2> = edges.iter().flat_map(|e| [r * e.uv[0], r * e.uv[1]]).collect();
    let (theta, mut lo, mut hi) = if repeat[0] || repeat[1] {
        let (lo, hi) = bounding::bounds(&points, 0.0);
        (0.0, lo, hi)
    } else {
        bounding::min_area_rectangle(&points, directions)
    };
    let m = DMat2::from_angle(-theta) * r;
    for dim in 0..2 {
        if repeat[dim] {
            // A wrapped dimension keeps one whole period: s = u (or t = v).
            let k = m.col(dim)[dim].abs();
            lo[dim] = 0.0;
            hi[dim] = k;
        }
    }
    (m, lo, hi)
}

/// Step 6: the used width and height for the extent `ext` in texels, and the reduction
/// factor applied: the settings', times the texel budget's for `covered_pixels`.
fn used_resolution(
    ext: DVec2,
    covered_pixels: usize,
    repeat: [bool; 2],
    settings: &TexcoordSettings,
) -> (u32, u32, f64) {
    let mut reduction = settings.reduction;
    if let Some(k) = settings.texels_per_pixel {
        let texels = ext.x.max(1.0) * ext.y.max(1.0) * reduction * reduction;
        let budget = k * covered_pixels.max(1) as f64;
        if texels > budget {
            reduction *= (budget / texels).sqrt();
        }
    }
    let size =
        |e: f64| ((e * reduction).ceil().max(1.0) as u64).min(settings.max_size as u64) as u32;
    let (mut width, mut height) = (size(ext.x), size(ext.y));
    // A wrapped dimension keeps repeat addressing, which the player supports only on a
    // power-of-two used size (thesis 3.2: the next power of two above the optimum).
    for (dim, side) in [&mut width, &mut height].into_iter().enumerate() {
        if repeat[dim] {
            let p = side.next_power_of_two();
            *side = if p > settings.max_size {
                (settings.max_size + 1).next_power_of_two() / 2
            } else {
                p
            };
        }
    }
    (width, height, reduction)
}

/// [a, b, c, d, e, f] of SPEC.md 7.3: the rows of `m` and the offset `−lo`, over the extent;
/// s = u (or t = v) along a wrapped dimension.
fn affine_of(m: DMat2, lo: DVec2, ext: DVec2, repeat: [bool; 2]) -> [f64; 6] {
    let mut affine = [0.0f64; 6];
    for dim in 0..2 {
        let e = if ext[dim] > 1e-12 { ext[dim] } else { 1.0 };
        if repeat[dim] {
            affine[2 * dim + dim] = 1.0;
            continue;
        }
        // row `dim` of M, divided by the extent
        affine[2 * dim] = m.col(0)[dim] / e;
        affine[2 * dim + 1] = m.col(1)[dim] / e;
        affine[4 + dim] = -lo[dim] / e;
    }
    affine
}

#[cfg(test)]
mod tests;
