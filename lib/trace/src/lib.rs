//! The PIS reference ray tracer and the ray-traced set.
//!
//! A CPU distribution ray tracer on obvhs BVHs renders a [`pis_scene::Scene`] at each point
//! of its parameter space into segmented layers (thesis 3.1, 5.7, 6.2): per-object coverage,
//! diffuse and specular layers, Fresnel modulation with local and distant incident specular
//! radiance for reflective objects, the two terms of the greedy two-path model with
//! outgoing-ray records for refractive lens objects, and the combined gold-standard image.
//! [`set`] writes and reads the result as a ray-traced set (format-spec/RAYSET.md).
//!
//! Entry points:
//! - [`render_set`]: every point of a loaded scene (`pis_scene::load_with`) into a set
//!   directory, one EXR (and ray-record file) per point as it finishes, then `set.json`.
//! - [`render_point`]: one [`pis_scene::Frame`] into [`PointImages`] and ray records.
//! - [`probe::incident_radiance`]: radiance arriving at a point from given directions, one
//!   object left out (a traditional environment map, thesis 5.1).
//! - [`set::RaySet::open`], [`set::RaySet::read_point`], [`set::RaySet::read_records`]: read
//!   a set back (what `pis-pack` consumes).
//!
//! Determinism: every random number comes from a hash of the surface point (or, with
//! coherence off, of the pixel sample); work is split into fixed bands of rows and every sum
//! runs in a fixed order, so the output is byte-identical for any thread count.

pub mod adaptive;
pub mod bvh;
pub mod camera;
pub mod denoise;
pub mod environment;
pub mod error;
pub mod film;
pub mod integrator;
pub mod layers;
pub mod lights;
pub mod material;
pub mod memory;
pub mod oidn;
pub mod probe;
pub mod rays;
pub mod records;
pub mod render;
pub mod run;
pub mod sampling;
pub mod set;
pub mod settings;
pub mod tangent;
pub mod textures;

pub use denoise::DenoiseInput;
pub use error::TraceError;
pub use film::GaussianFilter;
pub use layers::{LayerImage, LayerKind, PointImages};
pub use records::{RayRecord, RecordHit};
pub use render::{channel_names, render_point, PointRender, RenderStats};
pub use run::{render_set, render_shard, NoProgress, Progress, SetReport, TraceRun};
pub use settings::{DenoiseMode, ShadingSeed, TraceSettings};
