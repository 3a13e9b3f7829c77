//! Adaptive tessellation of a lens object for one frame (thesis 6.4.1): the paths of the
//! lens model (the greedy two, or the ray tree's terms) traced at the vertices of the
//! front-facing triangles — and of the back-facing ones the eye sees through an open mesh's
//! holes, entered from inside as pis-trace enters them — triangles split at their edges'
//! midpoints (1-to-4, 1-to-3 or 1-to-2) where their vertices' paths differ in topology or in
//! exit direction by more than 3° (or, beyond the thesis, in F·G by more than 0.05), down to
//! a screen edge length τ; the T-junctions left between triangles split to different depths
//! removed afterwards through the same edge table, which also keeps each vertex's rays from
//! being traced twice.
//!
//! Deterministic: triangles are split level by level in mesh order, new vertices numbered in
//! that order, and their rays traced in parallel into their own slots.

use std::collections::HashMap;
use std::time::{Duration, Instant};

use glam::{Mat4, Vec3};
use rayon::prelude::*;

use super::lens::{LensObject, LensSurface};
use super::path::{lens_paths_counted, paths_differ, LensModel, LensPath, MAX_TERMS};

/// The camera of a frame.
#[derive(Clone, Copy, Debug)]
pub struct HybridView {
    pub eye: Vec3,
    /// World to clip space (the player's projection × view).
    pub clip_from_world: Mat4,
    /// Frame size in pixels.
    pub size: (u32, u32),
}

/// The tessellation's settings.
#[derive(Clone, Copy, Debug)]
pub struct TessellationSettings {
    /// τ: triangles are not split below this screen edge length, in pixels of the frame
    /// (default 1: the thesis's τ = 3 was measured in subpixels of 3 × 3 supersampled
    /// frames).
    pub tau_px: f32,
    /// Paths whose exit directions differ more than this (degrees) are different.
    pub max_angle_deg: f32,
    /// Paths whose F·G differ more than this in a channel are different.
    pub max_modulation: f32,
    /// Interfaces a path may meet after the first (pis-trace's `max_depth`).
    pub max_depth: u32,
    /// Splits of an original triangle at most.
    pub max_levels: u32,
    /// The paths traced at each vertex, and the terms they are grouped into.
    pub model: LensModel,
}

impl Default for TessellationSettings {
    fn default() -> Self {
        TessellationSettings {
            tau_px: 1.0,
            max_angle_deg: 3.0,
            max_modulation: 0.05,
            max_depth: 8,
            max_levels: 12,
            model: LensModel::Greedy,
        }
    }
}

/// A vertex of the tessellation with its traced paths.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HybridVertex {
    pub position: Vec3,
    /// Shading normal (unit).
    pub normal: Vec3,
    /// Seen from the eye past the lens object's other triangles.
    pub visible: bool,
    /// Traced as the outside of the surface (the eye on the side its normal faces); else
    /// as its inside, seen through a hole of an open mesh.
    pub front_face: bool,
    /// Per term of the lens model, its path (reflection-first, refraction-first, then the
    /// tree's); `None` past the model's terms.
    pub paths: [Option<LensPath>; MAX_TERMS],
}

/// What the tessellation did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TessellationStats {
    /// Vertices traced (original front-facing vertices, edge midpoints, T-junction centres).
    pub traced_vertices: u64,
    /// Rays cast through the lens object: visibility rays and path segments.
    pub rays: u64,
    /// Front-facing triangles of the mesh, and triangles drawn.
    pub front_triangles: u64,
    /// Back-facing triangles traced: those with a vertex the eye sees (an open mesh's
    /// inside through its holes).
    pub back_triangles: u64,
    pub triangles: u64,
    /// Triangles split, and triangles fanned to remove T-junctions.
    pub splits: u64,
    pub fans: u64,
}

/// A lens object's tessellation for one frame.
#[derive(Clone, Debug, PartialEq)]
pub struct Tessellation {
    pub vertices: Vec<HybridVertex>,
    /// Front-facing triangles, wound as the mesh's.
    pub triangles: Vec<[u32; 3]>,
    pub stats: TessellationStats,
}

/// Traces the paths of a surface point seen from `eye` (thesis 6.4.1: the vertex ray), on
/// the outside of the surface (`front_face`, the side `normal` faces) or on its inside.
pub fn trace_vertex(
    lens: &LensObject,
    eye: Vec3,
    position: Vec3,
    normal: Vec3,
    front_face: bool,
    model: LensModel,
    max_depth: u32,
) -> (HybridVertex, u64) {
    let (dir, distance) = view_ray(eye, position);
    let eps = 1e-4 * (1.0 + position.abs().max_element());
    let visible = lens.closest(eye, dir, distance - eps).is_none();
    // The vertex's own surface: its shading normal stands for the geometric one too (a
    // vertex has no single face).
    let n = vertex_normal(normal, dir);
    let facing = if front_face { n } else { -n };
    let first = LensSurface { position, normal: facing, geometric_normal: facing, front_face };
    let (paths, rays) = lens_paths_counted(lens, &first, dir, model, max_depth);
    let rays = 1 + rays;
    (HybridVertex { position, normal: n, visible, front_face, paths }, rays)
}

/// The unit direction from `eye` to `position`, and their distance.
pub fn view_ray(eye: Vec3, position: Vec3) -> (Vec3, f32) {
    let to = position - eye;
    let distance = to.length();
    (to / distance, distance)
}

/// A traced vertex's shading normal: `normal` made unit, or facing the eye (−`dir`, the
/// view ray's direction) where it is zero.
pub fn vertex_normal(normal: Vec3, dir: Vec3) -> Vec3 {
    let n = normal.normalize_or_zero();
    if n == Vec3::ZERO {
        -dir
    } else {
        n
    }
}

/// A vertex whose paths are to be traced: its position, shading normal and side
/// ([`trace_vertex`]'s arguments).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VertexRay {
    pub position: Vec3,
    pub normal: Vec3,
    pub front_face: bool,
}

/// Traces the vertex rays of a tessellation level: each vertex as [`trace_vertex`] traces it,
/// with the rays it cast. [`CpuVertexTracer`] runs [`trace_vertex`] on the workers; the
/// player can trace them on the GPU instead (pis-play's `lens_rays`), the same walk written
/// in WGSL.
pub trait VertexTracer: Sync {
    fn trace(
        &self,
        lens: &LensObject,
        eye: Vec3,
        rays: &[VertexRay],
        model: LensModel,
        max_depth: u32,
    ) -> Vec<(HybridVertex, u64)>;
}

/// [`trace_vertex`] for each vertex, on the workers.
#[derive(Clone, Copy, Debug, Default)]
pub struct CpuVertexTracer;

impl VertexTracer for CpuVertexTracer {
    fn trace(
        &self,
        lens: &LensObject,
        eye: Vec3,
        rays: &[VertexRay],
        model: LensModel,
        max_depth: u32,
    ) -> Vec<(HybridVertex, u64)> {
        rays.par_iter()
            .map(|v| trace_vertex(lens, eye, v.position, v.normal, v.front_face, model, max_depth))
            .collect()
    }
}

/// Whether the eye sees `position` past the lens object's triangles.
fn sees(lens: &LensObject, eye: Vec3, position: Vec3) -> bool {
    let to = position - eye;
    let distance = to.length();
    let eps = 1e-4 * (1.0 + position.abs().max_element());
    distance > 0.0 && lens.closest(eye, to / distance, distance - eps).is_none()
}

/// Where a tessellation's time went (wall clock, not part of its result).
#[derive(Clone, Copy, Debug, Default)]
pub struct TessellationTimes {
    /// Tracing the vertices' paths (on the workers).
    pub trace: Duration,
    /// Everything else: front faces, splitting decisions, edge table, T-junctions.
    pub tessellate: Duration,
}

/// Tessellates `lens` for `view`, its vertex rays traced on the workers.
pub fn tessellate(
    lens: &LensObject,
    view: &HybridView,
    settings: &TessellationSettings,
) -> Tessellation {
    tessellate_timed(lens, view, settings, &CpuVertexTracer).0
}

/// [`tessellate()`] with the vertex rays traced by `tracer`, and where its time went.
pub fn tessellate_timed(
    lens: &LensObject,
    view: &HybridView,
    settings: &TessellationSettings,
    tracer: &dyn VertexTracer,
) -> (Tessellation, TessellationTimes) {
    let start = Instant::now();
    let cos_max = settings.max_angle_deg.to_radians().cos();
    let mut stats = TessellationStats::default();
    let (front, back, mut used) = faces(lens, view);
    stats.front_triangles = front.len() as u64;
    stats.back_triangles = back.len() as u64;
    let mut mesh = Mesh {
        lens,
        view,
        settings,
        tracer,
        vertices: Vec::new(),
        midpoints: HashMap::new(),
        stats,
        trace_time: Duration::ZERO,
    };
    mesh.vertices = (0..lens.positions.len())
        .map(|i| HybridVertex {
            position: lens.positions[i],
            normal: lens.normals.get(i).copied().unwrap_or(Vec3::ZERO),
            visible: false,
            front_face: used[i],
            paths: [None; MAX_TERMS],
        })
        .collect();
    back.iter().flatten().for_each(|&v| used[v as usize] = true);
    let first_vertices: Vec<u32> =
        (0..lens.positions.len() as u32).filter(|&i| used[i as usize]).collect();
    mesh.trace(&first_vertices);
    // Split level by level.
    let mut current = front;
    current.extend(back);
    let mut leaves = Vec::new();
    for _ in 0..settings.max_levels {
        if current.is_empty() {
            break;
        }
        let mut next = Vec::new();
        let mut new_vertices = Vec::new();
        for tri in current {
            match mesh.split_edges(tri, cos_max) {
                None => leaves.push(tri),
                Some(split) => {
                    mesh.stats.splits += 1;
                    let mids = [0, 1, 2].map(|e| {
                        split[e].then(|| mesh.midpoint(tri[e], tri[(e + 1) % 3], &mut new_vertices))
                    });
                    next.extend(children(tri, mids));
                }
            }
        }
        mesh.trace(&new_vertices);
        current = next;
    }
    leaves.extend(current);
    // T-junctions: each leaf's edges with the midpoints its neighbours made.
    let mut triangles = Vec::with_capacity(leaves.len());
    let mut centres = Vec::new();
    let mut fans = Vec::new();
    for tri in leaves {
        let points: [Vec<u32>; 3] = [0, 1, 2].map(|e| mesh.edge_points(tri[e], tri[(e + 1) % 3]));
        let split: Vec<usize> = (0..3).filter(|&e| !points[e].is_empty()).collect();
        match split.len() {
            0 => triangles.push(tri),
            1 => {
                // Fan from the corner opposite the one split edge.
                let e = split[0];
                let apex = tri[(e + 2) % 3];
                let mut chain = vec![tri[e]];
                chain.extend(&points[e]);
                chain.push(tri[(e + 1) % 3]);
                triangles.extend(chain.windows(2).map(|w| [w[0], w[1], apex]));
                mesh.stats.fans += 1;
            }
            _ => {
                // A centre vertex, fanned to every boundary segment.
                let c = mesh.vertices.len() as u32 + centres.len() as u32;
                let [a, b, d] = tri.map(|v| mesh.vertices[v as usize]);
                centres.push((
                    (a.position + b.position + d.position) / 3.0,
                    (a.normal + b.normal + d.normal).normalize_or_zero(),
                    a.front_face || b.front_face || d.front_face,
                ));
                let mut ring = Vec::new();
                for e in 0..3 {
                    ring.push(tri[e]);
                    ring.extend(&points[e]);
                }
                fans.push((c, ring));
                mesh.stats.fans += 1;
            }
        }
    }
    if !centres.is_empty() {
        let first = mesh.vertices.len() as u32;
        mesh.vertices.extend(centres.iter().map(|&(p, n, front_face)| HybridVertex {
            position: p,
            normal: n,
            visible: false,
            front_face,
            paths: [None; MAX_TERMS],
        }));
        let ids: Vec<u32> = (first..mesh.vertices.len() as u32).collect();
        mesh.trace(&ids);
    }
    for (c, ring) in fans {
        triangles.extend((0..ring.len()).map(|k| [ring[k], ring[(k + 1) % ring.len()], c]));
    }
    let mut stats = mesh.stats;
    stats.triangles = triangles.len() as u64;
    let times = TessellationTimes {
        trace: mesh.trace_time,
        tessellate: start.elapsed().saturating_sub(mesh.trace_time),
    };
    (Tessellation { vertices: mesh.vertices, triangles, stats }, times)
}

/// The triangles a tessellation starts from: the front-facing ones, the back-facing ones
/// with a vertex the eye sees past the object (an open mesh's inside seen through its
/// holes), and which vertices the front-facing ones use.
fn faces(lens: &LensObject, view: &HybridView) -> (Vec<[u32; 3]>, Vec<[u32; 3]>, Vec<bool>) {
    // Front-facing triangles, and the vertices they use.
    let front: Vec<[u32; 3]> = (0..lens.triangles.len())
        .filter(|&t| {
            let a = lens.positions[lens.triangles[t][0] as usize];
            lens.face_normal(t).dot(view.eye - a) > 0.0
        })
        .map(|t| lens.triangles[t])
        .collect();
    let mut used = vec![false; lens.positions.len()];
    front.iter().flatten().for_each(|&v| used[v as usize] = true);
    // Back-facing triangles with a vertex no part of the object hides: an open mesh's
    // inside seen through its holes (a closed mesh's are hidden, but at its silhouette).
    let back_candidates: Vec<[u32; 3]> = (0..lens.triangles.len())
        .filter(|&t| {
            let a = lens.positions[lens.triangles[t][0] as usize];
            lens.face_normal(t).dot(view.eye - a) <= 0.0
        })
        .map(|t| lens.triangles[t])
        .collect();
    let mut back_vertex: Vec<u32> =
        back_candidates.iter().flatten().copied().filter(|&v| !used[v as usize]).collect();
    back_vertex.sort_unstable();
    back_vertex.dedup();
    let seen: Vec<bool> =
        back_vertex.par_iter().map(|&v| sees(lens, view.eye, lens.positions[v as usize])).collect();
    let mut visible_back = vec![false; lens.positions.len()];
    back_vertex.iter().zip(&seen).for_each(|(&v, &s)| visible_back[v as usize] = s);
    let back: Vec<[u32; 3]> = back_candidates
        .into_iter()
        .filter(|t| t.iter().any(|&v| visible_back[v as usize]))
        .collect();
    (front, back, used)
}

/// The children of `tri` (corners a, b, c) with midpoints `mids` on edges ab, bc, ca.
fn children(tri: [u32; 3], mids: [Option<u32>; 3]) -> Vec<[u32; 3]> {
    let [a, b, c] = tri;
    match mids {
        [Some(ab), Some(bc), Some(ca)] => vec![[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]],
        [Some(ab), None, None] => vec![[a, ab, c], [ab, b, c]],
        [None, Some(bc), None] => vec![[a, b, bc], [a, bc, c]],
        [None, None, Some(ca)] => vec![[a, b, ca], [ca, b, c]],
        [Some(ab), Some(bc), None] => vec![[ab, b, bc], [a, ab, bc], [a, bc, c]],
        [None, Some(bc), Some(ca)] => vec![[bc, c, ca], [b, bc, ca], [b, ca, a]],
        [Some(ab), None, Some(ca)] => vec![[ca, a, ab], [c, ca, ab], [c, ab, b]],
        [None, None, None] => vec![tri],
    }
}

struct Mesh<'a> {
    lens: &'a LensObject,
    view: &'a HybridView,
    settings: &'a TessellationSettings,
    tracer: &'a dyn VertexTracer,
    vertices: Vec<HybridVertex>,
    /// Edge (lower, higher vertex index) → its midpoint vertex.
    midpoints: HashMap<(u32, u32), u32>,
    stats: TessellationStats,
    trace_time: Duration,
}

impl Mesh<'_> {
    /// Traces the paths of vertices `ids` (their position and normal set) with the tracer.
    fn trace(&mut self, ids: &[u32]) {
        let start = Instant::now();
        let rays: Vec<VertexRay> = ids
            .iter()
            .map(|&i| {
                let v = &self.vertices[i as usize];
                VertexRay { position: v.position, normal: v.normal, front_face: v.front_face }
            })
            .collect();
        let (model, depth) = (self.settings.model, self.settings.max_depth);
        let traced = self.tracer.trace(self.lens, self.view.eye, &rays, model, depth);
        for (&i, (v, rays)) in ids.iter().zip(traced) {
            self.vertices[i as usize] = v;
            self.stats.rays += rays;
        }
        self.stats.traced_vertices += ids.len() as u64;
        self.trace_time += start.elapsed();
    }

    /// The edges of `tri` to split, or `None` when it stays whole: its vertices' paths agree
    /// for every term, all three are hidden, or no edge is longer than τ on screen.
    fn split_edges(&self, tri: [u32; 3], cos_max: f32) -> Option<[bool; 3]> {
        let v = tri.map(|i| &self.vertices[i as usize]);
        if v.iter().all(|v| !v.visible) {
            return None;
        }
        let differ = (0..3).any(|e| {
            let (p, q) = (v[e], v[(e + 1) % 3]);
            (0..self.settings.model.terms()).any(|t| {
                paths_differ(
                    p.paths[t].as_ref(),
                    q.paths[t].as_ref(),
                    cos_max,
                    self.settings.max_modulation,
                )
            })
        });
        if !differ {
            return None;
        }
        let split = [0, 1, 2].map(|e| {
            self.screen_length(v[e].position, v[(e + 1) % 3].position) > self.settings.tau_px
        });
        split.iter().any(|&s| s).then_some(split)
    }

    /// The length in pixels of the segment pq on screen (0 where it reaches behind the eye).
    fn screen_length(&self, p: Vec3, q: Vec3) -> f32 {
        let (w, h) = (self.view.size.0 as f32, self.view.size.1 as f32);
        let project = |x: Vec3| {
            let c = self.view.clip_from_world * x.extend(1.0);
            (c.w > 0.0).then(|| glam::Vec2::new(c.x / c.w * 0.5 * w, c.y / c.w * 0.5 * h))
        };
        match (project(p), project(q)) {
            (Some(a), Some(b)) => (a - b).length(),
            _ => 0.0,
        }
    }

    /// The midpoint vertex of edge ab, made (untraced, appended to `made`) the first time.
    fn midpoint(&mut self, a: u32, b: u32, made: &mut Vec<u32>) -> u32 {
        let key = (a.min(b), a.max(b));
        if let Some(&m) = self.midpoints.get(&key) {
            return m;
        }
        let (p, q) = (self.vertices[key.0 as usize], self.vertices[key.1 as usize]);
        let m = self.vertices.len() as u32;
        self.vertices.push(HybridVertex {
            position: (p.position + q.position) * 0.5,
            normal: (p.normal + q.normal).normalize_or_zero(),
            visible: false,
            front_face: p.front_face || q.front_face,
            paths: [None; MAX_TERMS],
        });
        self.midpoints.insert(key, m);
        made.push(m);
        m
    }

    /// The vertices other triangles put on edge ab, in order from a to b.
    fn edge_points(&self, a: u32, b: u32) -> Vec<u32> {
        let Some(&m) = self.midpoints.get(&(a.min(b), a.max(b))) else { return Vec::new() };
        let mut out = self.edge_points(a, m);
        out.push(m);
        out.extend(self.edge_points(m, b));
        out
    }
}
