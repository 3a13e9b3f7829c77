//! Hybrid rendering of lens objects (thesis ch. 6), the part the player computes per frame:
//! the lens model's paths traced through the lens object alone at the vertices of an
//! adaptively refined tessellation ([`tessellate()`]), giving per vertex the outgoing rays
//! that index the layered environment-map shells and the F·G modulation of each term. One
//! function, used by the player each frame and by pis-pack's render matrices; the vertex
//! walk ([`trace_vertex`]) is written again in WGSL for the player's GPU (pis-play's
//! `lens_rays.wgsl`, over [`lens_bvh`]'s flat BVH), behind [`VertexTracer`].

pub mod layers;
pub mod lens;
pub mod lens_bvh;
pub mod model;
pub mod path;
pub mod tessellate;

pub use layers::{
    choose_layers, cluster, fit_shell, layer_hits, relative_error, shells_error, FittedShell,
    Layers, OutgoingRay,
};
pub use lens::{LensMaterial, LensObject};
pub use model::{
    corner_values, hybrid_pixels, hybrid_render_matrix, shell_vector, term_radiance,
    vertex_modulation, vertex_vectors, HybridPixels, Missing,
};
pub use path::{
    file_lens_model, file_lens_terms, greedy_path, lens_paths, LensModel, LensPath, Term, Topology,
    MAX_TERMS, TERMS,
};
pub use tessellate::{
    tessellate, tessellate_timed, trace_vertex, vertex_normal, view_ray, CpuVertexTracer,
    HybridVertex, HybridView, Tessellation, TessellationSettings, TessellationStats,
    TessellationTimes, VertexRay, VertexTracer,
};
