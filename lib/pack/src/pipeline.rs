//! `pis-pack`: a ray-traced set to a `.pis` container (thesis ch. 4).
//!
//! The stages, one module each: [`input`] reads (or traces) the set and [`plan`] resolves
//! the settings against it once (blocks, space, staggering, the allocation's aim);
//! [`infer_layers`] chooses each object's representation ([`registry`]) and runs it
//! ([`represent`] is the seam: layered environment maps for reflective objects, [`pem`], and
//! hybrid rendering for refractive ones, [`hybrid`], where asked; otherwise parameterized
//! surface textures, [`surface`]: texture coordinates per block (3.2), a view-independent
//! diffuse layer solved over all views by stacking and a view-dependent specular layer per
//! parameter sample, warm-started, black layers left out (3.5)), giving an
//! [`model::ObjectModel`] per object; [`encode`] cuts each layer into parameter-space blocks
//! whose origins are staggered per object ([`blocks`], 4.7), builds an adaptive Laplacian
//! pyramid (4.3) of gamma-compensated samples (4.6) per block and allocates storage by equal
//! slopes across levels, objects and layers ([`storage`], 4.5), whatever representation made
//! them, and writes each object with its scene role, its material's shading constants
//! ([`shading`]) and its mesh ([`stored_mesh`]);
//! [`report`] says what came out.
//! The container is written atomically. MIP levels are not stored: the player decimates
//! (3.6). [`sharded`] splits the solves over processes and merges them into the same file.
//!
//! The render matrices A come from the hardware model or, with `matrix: Probe`, are measured
//! through the player's pipeline on the GPU (probe mode, thesis 3.4.3; [`matrices`]), which
//! anisotropic filtering needs. The predicted PSNR renders the decoded textures through the
//! same A (with the MIP chain rebuilt by decimation as the player does) and compares with
//! the gold-standard layers over the pixels the tracer covers, on display values
//! ([`pis_codec::display`]).

pub mod blocks;
pub mod choice;
pub mod confidence;
pub mod density_choice;
pub mod encode;
pub mod filter_choice;
pub mod held_out;
pub mod hybrid;
pub mod infer_layers;
pub mod input;
pub mod matrices;
pub mod memory;
pub mod mesh;
pub mod model;
pub mod opacity;
pub mod packed;
pub mod pem;
pub mod plan;
pub mod played;
pub mod predict;
pub mod radiance;
pub mod registry;
pub mod relit;
pub mod report;
pub mod represent;
pub mod rows;
pub mod sample;
pub mod scratch;
pub mod screen;
pub mod set_images;
pub mod settings;
pub mod shading;
pub mod sharded;
pub mod shell_fit;
pub mod storage;
pub mod stored_mesh;
pub mod surface;
pub mod sweep;
pub mod texture_form;
pub mod textures;
pub mod transforms;

use std::path::PathBuf;
use std::time::Instant;

pub use pis_trace::set::Shard;

use pis_codec::CodecId;

pub use input::{cache_dir, scene_trace_settings};
pub use matrices::{filter_needs_probe, MatrixSource};
pub use packed::LayerTextures;
pub use report::{print_report, FragmentsReport, MemoryReport, ObjectReport, PackReport};
pub use settings::*;
pub use sharded::{fragment_files, fragment_path, merge_fragments, solve_shard, SolveReport};
pub use sweep::{Inferred, PackPoint};

use crate::error::{Exit, Failure};

/// What to pack: the input, the output and the settings. Derefs to its
/// [`PackSettings`].
#[derive(Clone, Debug)]
pub struct PackRequest {
    /// A ray-traced set directory or a scene.toml (traced first into a cache beside it).
    pub input: PathBuf,
    /// The set's scene.toml (default: the one set.json records, else SET_DIR/scene.toml, or
    /// the input scene.toml).
    pub scene: Option<PathBuf>,
    /// The container to write (atomically).
    pub output: PathBuf,
    pub settings: PackSettings,
    /// Where the solves go: the solver, or a store of solutions (a pack split over
    /// processes, [`solve_shard`] and [`merge_fragments`]).
    pub solver: crate::solutions::Solver,
    /// Solve only the objects of this shard ([`solve_shard`]).
    pub shard: Option<Shard>,
}

impl std::ops::Deref for PackRequest {
    type Target = PackSettings;
    fn deref(&self) -> &PackSettings {
        &self.settings
    }
}

impl PackRequest {
    /// `input` packed into `output` with `settings`.
    pub fn new(
        input: impl Into<PathBuf>,
        output: impl Into<PathBuf>,
        settings: PackSettings,
    ) -> Self {
        PackRequest {
            input: input.into(),
            scene: None,
            output: output.into(),
            settings,
            solver: Default::default(),
            shard: None,
        }
    }

    /// The same request with other settings.
    pub fn with(&self, change: impl FnOnce(&mut PackSettings)) -> Self {
        let mut r = self.clone();
        change(&mut r.settings);
        r
    }
}

/// What a pack tells while it works: each stage as it ends, and notes on objects. Called
/// on the calling thread.
pub trait Progress {
    /// A stage ended after `ms` milliseconds, having done `what`.
    fn stage(&self, _name: &str, _ms: f64, _what: &str) {}
    /// A note on the work (an object left out, the probe adapter, …).
    fn note(&self, _text: &str) {}
}

/// No progress display.
pub struct NoProgress;
impl Progress for NoProgress {}

/// Progress as `pis-pack` prints it on stderr: one line per stage with its time, one per
/// note.
pub struct StderrProgress;
impl Progress for StderrProgress {
    fn stage(&self, name: &str, ms: f64, what: &str) {
        eprintln!("pis-pack: {name:<9} {ms:8.0} ms  {what}");
    }
    fn note(&self, text: &str) {
        eprintln!("pis-pack: {text}");
    }
}

/// Times the stages of a pack and tells its progress.
pub struct Stages<'p> {
    pub ms: Vec<(String, f64)>,
    /// Per stage in order, the process's peak resident memory in MiB when it ended (where
    /// the system tells it).
    pub peak_mib: Vec<(String, f64)>,
    t: Instant,
    progress: &'p dyn Progress,
}

impl<'p> Stages<'p> {
    fn new(progress: &'p dyn Progress) -> Self {
        Stages { ms: Vec::new(), peak_mib: Vec::new(), t: Instant::now(), progress }
    }

    /// Stages timed without progress.
    fn quiet() -> Stages<'static> {
        Stages::new(&NoProgress)
    }

    pub fn done(&mut self, name: &str, what: &str) {
        let ms = self.t.elapsed().as_secs_f64() * 1e3;
        self.progress.stage(name, ms, what);
        self.ms.push((name.to_string(), ms));
        if let Some(b) = pis_trace::memory::peak_resident() {
            self.peak_mib.push((name.to_string(), b as f64 / (1 << 20) as f64));
        }
        self.t = Instant::now();
    }

    pub fn note(&self, text: &str) {
        self.progress.note(text);
    }

    /// Where the progress goes.
    pub fn progress(&self) -> &'p dyn Progress {
        self.progress
    }
}

/// Packs the ray-traced set (or scene.toml, traced first into `.pis-cache/` beside it) at
/// `input` into the container `output` with `settings`, telling `progress` as it goes; on
/// error no output file is left. The whole of `pis-pack`.
pub fn pack(
    input: &std::path::Path,
    output: &std::path::Path,
    settings: &PackSettings,
    progress: &dyn Progress,
) -> Result<PackReport, Failure> {
    pack_request(&PackRequest::new(input, output, settings.clone()), progress)
}

/// The checks before any work, the set read (or traced), the settings resolved against it
/// ([`plan::Plan`]) and the render-matrix source opened.
fn begin(
    req: &PackRequest,
    stages: &mut Stages,
) -> Result<(input::LoadedSet, plan::Plan, matrices::Matrices), Failure> {
    req.target.check().map_err(|e| Failure::new(Exit::Usage, anyhow::anyhow!(e)))?;
    if let Some(why) = filter_needs_probe(req.filter, req.matrix) {
        return Err(Failure::new(Exit::Usage, anyhow::anyhow!(why)));
    }
    if !(1..=pis_format::MAX_SHELL_LOOKUPS).contains(&req.shell_lookups) {
        return Err(Failure::new(
            Exit::Usage,
            anyhow::anyhow!(
                "--shell-lookups must be 1 to {}, got {}",
                pis_format::MAX_SHELL_LOOKUPS,
                req.shell_lookups
            ),
        ));
    }
    let set = input::load(req, stages)?;
    // A ratio is checked before any work: it must leave a lossy codec's level images a byte.
    let raw = set.raw_image_bytes();
    let binding = req.target.ratio().filter(|_| req.codec.is_lossy());
    if let Some(r) = binding.filter(|r| raw as f64 / r < 1.0) {
        return Err(Failure::new(Exit::Usage, anyhow::anyhow!("--ratio {r} leaves no byte for the level images of this set (raw images {raw} bytes): the highest ratio is {raw}:1")));
    }
    let plan = plan::Plan::new(&set, req).map_err(|e| Failure::new(Exit::Usage, e))?;
    let matrices = matrices::Matrices::open(req.matrix, req.filter)?;
    if let Some(device) = matrices.device() {
        stages.note(&format!("probe mode on {device}"));
    }
    Ok((set, plan, matrices))
}

/// [`pack`] of a [`PackRequest`] (which may name the set's scene.toml).
pub fn pack_request(req: &PackRequest, progress: &dyn Progress) -> Result<PackReport, Failure> {
    let parent = req
        .output
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(std::path::Path::new("."));
    if !parent.is_dir() {
        return Err(Failure::new(
            Exit::Io,
            anyhow::anyhow!("the output folder {} does not exist", parent.display()),
        ));
    }
    let mut stages = Stages::new(progress);
    let (set, plan, mut matrices) = begin(req, &mut stages)?;
    let inferred = infer_layers::infer_all(&set, req, &plan, &mut matrices, &mut stages)
        .map_err(|e| Failure::new(Exit::Runtime, e))?;
    let probe_renderings = matrices.renderings();
    drop(matrices);
    let (inferred, chosen) = choice::choose(&set, inferred, &plan, req, &mut stages)?;
    let (mut packed, quality) = match chosen {
        Some(done) => done,
        None => {
            let packed = encode::encode_all(&set, &inferred, &plan, req, &mut stages)?;
            let quality = predict::predicted_psnr(&set, &inferred, &packed)
                .map_err(|e| Failure::new(Exit::Runtime, e))?;
            stages.done(
                "predict",
                &format!(
                    "decoded textures rendered through the render matrices ({})",
                    req.matrix.name()
                ),
            );
            (packed, quality)
        }
    };
    // The prediction travels with the file: `pis-diff FILE SET --max-psnr-drop` measures
    // the played PSNR against it.
    if let Some(p) = packed.container.provenance.as_mut() {
        p.settings.push((PREDICTED_PSNR_SETTING.to_string(), format!("{:.4}", quality.overall)));
    }
    // So does what half floats would cost: a player holds 16-bit textures where it is far
    // below the coding error (SPEC.md 6.6).
    let half_float_psnr = predict::half_float_psnr(&set, &inferred, &packed)
        .map_err(|e| Failure::new(Exit::Runtime, e))?;
    stages.done("half floats", &report::half_float_note(half_float_psnr, quality.overall));
    if let (Some(p), Some(h)) = (packed.container.provenance.as_mut(), half_float_psnr) {
        p.settings.push((HALF_FLOAT_PSNR_SETTING.to_string(), format!("{h:.4}")));
    }
    // And what 16-bit level images would cost a player that rebuilds on the GPU.
    let level16_psnr = predict::level16_psnr(&set, &inferred, &packed)
        .map_err(|e| Failure::new(Exit::Runtime, e))?;
    stages.done("16-bit level images", &report::level16_note(level16_psnr, quality.overall));
    if let (Some(p), Some(h)) = (packed.container.provenance.as_mut(), level16_psnr) {
        p.settings.push((LEVEL16_PSNR_SETTING.to_string(), format!("{h:.4}")));
    }
    let masters = if req.keep_master {
        let m = encode::masters(&inferred, &packed).map_err(|e| Failure::new(Exit::Runtime, e))?;
        let n: u64 = m.iter().map(pis_format::Master::payload_len).sum();
        stages.done(
            "master",
            &format!("solved textures of {} objects coded losslessly ({n} bytes)", m.len()),
        );
        m
    } else {
        Vec::new()
    };
    let bytes = pis_format::write_with_masters(&req.output, &packed.container, &masters)?;
    stages.done("write", &format!("{} ({bytes} bytes)", req.output.display()));
    // The master read back from the file decodes to the solved textures bit for bit.
    let master = if req.keep_master {
        Some(
            encode::check_master(&req.output, &inferred)
                .map_err(|e| Failure::new(Exit::Runtime, e))?,
        )
    } else {
        None
    };
    // Lossless: the file's level images decode bit-exactly and the decoded textures equal
    // the solved ones.
    let exact = if req.codec == CodecId::Lossless {
        let levels = encode::check_lossless(&req.output, &packed)
            .map_err(|e| Failure::new(Exit::Runtime, e))?;
        Some(levels && quality.max_texel_error == 0.0)
    } else {
        None
    };
    let mut report = report::build(&set, &inferred, &packed, &quality, bytes, exact, req, stages);
    report.probe_renderings = probe_renderings;
    report.half_float_psnr_db = half_float_psnr;
    report.level16_psnr_db = level16_psnr;
    if let Some((master_bytes, exact)) = master {
        report.set_master(master_bytes, exact);
    }
    Ok(report)
}

/// `N`, or `NxM…`: sizes of at least 1 separated by `x` (`--block`, `--resolution`).
pub fn parse_sizes(s: &str) -> Result<Vec<u32>, String> {
    s.split(['x', 'X'])
        .map(|p| {
            p.trim()
                .parse::<u32>()
                .ok()
                .filter(|&b| b > 0)
                .ok_or_else(|| format!("bad size {s:?}: expected N or NxM"))
        })
        .collect()
}
