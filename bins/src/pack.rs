//! `pis-pack`: a ray-traced set to a `.pis` container (thesis ch. 4).
//!
//! Per object: texture-coordinate optimization over the set's views (3.3); inference of the
//! object's layers as parameterized surface textures (3.5) — a view-independent diffuse
//! layer solved once over all views by stacking, depending on the non-view dimensions only,
//! and a view-dependent specular layer solved per parameter sample with a warm start from
//! the neighbouring sample; a layer that is black for an object is not stored. Each layer is
//! cut into parameter-space blocks whose origins are staggered per object (4.7), each block
//! coded as an adaptive Laplacian pyramid (4.3) of gamma-compensated textures (4.6), storage
//! allocated by equal slopes across levels, objects and layers (4.5), and the container
//! written atomically. MIP levels are not stored: the player decimates (3.6).
//!
//! The render matrices A come from the hardware model or, with `matrix: Probe`, are measured
//! through the player's pipeline on the GPU (probe mode, thesis 3.4.3; [`matrices`]), which
//! anisotropic filtering needs. The predicted PSNR renders the decoded textures through the
//! same A (with the MIP chain rebuilt by decimation as the player does) and compares with
//! the gold-standard layers over the pixels the tracer covers, on display values (see
//! [`crate::infer`]).

pub(crate) mod encode;
pub(crate) mod infer_layers;
pub(crate) mod input;
pub mod matrices;
mod report;
pub mod storage;
mod sweep;

use std::path::PathBuf;
use std::time::Instant;

use pis_codec::CodecId;
use pis_compile::Filter;

pub use report::{print_report, ObjectReport, PackReport};
pub use input::cache_dir;
pub use matrices::{filter_needs_probe, MatrixSource};
pub use sweep::{Inferred, PackPoint};

use crate::cli::{Exit, Failure};

/// What to pack.
#[derive(Clone, Debug)]
pub struct PackRequest {
    /// A ray-traced set directory or a scene.toml (traced first into a cache beside it).
    pub input: PathBuf,
    /// The set's scene.toml (default: SET_DIR/scene.toml, or the input scene.toml).
    pub scene: Option<PathBuf>,
    pub output: PathBuf,
    /// Target compression ratio: bytes = raw image bytes / ratio.
    pub ratio: Option<f64>,
    /// Target PSNR (dB) instead of a ratio.
    pub psnr: Option<f64>,
    pub codec: CodecId,
    /// Samples per block along each dimension (one value: the same for every dimension).
    pub block: Vec<u32>,
    /// The player's texture filter; `Anisotropic` needs `matrix: Probe`.
    pub filter: Filter,
    /// Where the render matrices come from: the hardware model or probe mode.
    pub matrix: MatrixSource,
    /// Largest used texture side.
    pub max_texture: u32,
    /// Texel budget: at most this many level-0 texels per pixel an object covers (its most
    /// covered view); None: the optimal resolution of thesis 3.2, capped by `max_texture` only.
    pub texels_per_pixel: Option<f64>,
    /// Display gamma g of the compensation γ(L) = L^(1/g); lossless packs use 1.
    pub gamma: f32,
    /// Tracing a scene.toml: size and samples per pixel overrides.
    pub resolution: Option<(u32, u32)>,
    pub spp: Option<u32>,
    /// Pyramid levels per block: the adaptive search (thesis 4.3) or the full dyadic sequence.
    pub pyramid: PyramidMode,
    /// Lighting layers: separate diffuse and specular layers, or one combined view-dependent
    /// layer (diffuse + specular) per parameter sample.
    pub layers: LayerMode,
    /// What the storage allocation weighs: screen error (default) or texture error.
    pub allocation: Allocation,
    /// Texture placements per parameter block or per object.
    pub placement: PlacementMode,
    /// Conjugate-gradient iteration cap per colour channel of every solve (None: the
    /// solver's default).
    pub max_iterations: Option<u32>,
    /// Tracing a scene.toml: a `[preset.NAME]` applied before the size overrides (also
    /// applied to the scene a set is read with).
    pub preset: Option<String>,
}

/// How each block's pyramid levels are chosen.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum PyramidMode {
    /// Greedy choice of each level's counts (thesis 4.3).
    #[default]
    Adaptive,
    /// Every dimension halved (rounding up) per level down to one sample: no search.
    Full,
}

/// The error the storage allocation (thesis 4.5) minimizes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Allocation {
    /// Each level image's error weighted per texel by how much of the screen the texel
    /// reaches through the render matrices (column sums of A, carried down the decimation),
    /// so storage goes where errors are seen: texels no pixel reads weigh nothing, texels
    /// that magnified pixels read weigh more.
    #[default]
    Screen,
    /// Texture MSE weighted by each object's screen area (every texel of an object alike).
    Texture,
}

/// Which views a texture placement (thesis 3.2) is optimized over.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum PlacementMode {
    /// Per object per parameter block: the views of the block's samples (thesis 3.2).
    #[default]
    Block,
    /// One placement per object over every view of the set, shared by all its blocks.
    Object,
}

impl PlacementMode {
    /// The name `--placement` and the provenance use.
    pub fn name(self) -> &'static str {
        match self {
            PlacementMode::Block => "block",
            PlacementMode::Object => "object",
        }
    }
}

/// How the lighting layers are separated.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LayerMode {
    /// A view-independent diffuse layer and a view-dependent specular layer (thesis 4.8).
    #[default]
    Separate,
    /// One view-dependent layer of diffuse + specular radiance per parameter sample.
    Combined,
}

/// The provenance setting holding the predicted PSNR (dB, display values over the pixels the
/// objects cover) of a packed file.
pub const PREDICTED_PSNR_SETTING: &str = "predicted_psnr_db";

/// The default texel budget per covered pixel (`--texels-per-pixel`).
pub const DEFAULT_TEXELS_PER_PIXEL: Option<f64> = Some(1.0);

/// The default largest used texture side (`--max-texture`): a limit on what a GPU must
/// hold, not the resolution control (the texel budget is).
pub const DEFAULT_MAX_TEXTURE: u32 = 1024;

/// The default compression ratio when neither `--ratio` nor `--psnr` is given.
pub const DEFAULT_RATIO: f64 = 384.0;

/// Times one stage and prints its progress line on stderr.
pub(crate) struct Stages {
    pub(crate) ms: Vec<(String, f64)>,
    t: Instant,
    quiet: bool,
}

impl Stages {
    fn new() -> Self {
        Stages { ms: Vec::new(), t: Instant::now(), quiet: false }
    }

    /// Stages timed without progress lines.
    fn quiet() -> Self {
        Stages { quiet: true, ..Stages::new() }
    }

    pub(crate) fn done(&mut self, name: &str, what: &str) {
        let ms = self.t.elapsed().as_secs_f64() * 1e3;
        if !self.quiet {
            eprintln!("pis-pack: {name:<9} {ms:8.0} ms  {what}");
        }
        self.ms.push((name.to_string(), ms));
        self.t = Instant::now();
    }
}

/// What `pis-pack` writes beside the level images a player uses.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PackExtras {
    /// Keep the lossless master (SPEC.md 6.7): every solved texture of every layer sample,
    /// before gamma compensation and coding, and each object's allocation weight, so that
    /// `pis-reencode` codes again from the solve rather than from the decoded textures.
    pub keep_master: bool,
}

/// Runs the whole pipeline and writes the container; on error no output file is left.
pub fn pack(req: &PackRequest) -> Result<PackReport, Failure> {
    pack_with(req, PackExtras::default())
}

/// [`pack`], writing `extras` too.
pub fn pack_with(req: &PackRequest, extras: PackExtras) -> Result<PackReport, Failure> {
    if req.ratio.is_some() && req.psnr.is_some() {
        return Err(Failure::new(Exit::Usage, anyhow::anyhow!("give --ratio or --psnr, not both")));
    }
    if let Some(r) = req.ratio {
        if !(r.is_finite() && r >= 1.0) {
            return Err(Failure::new(Exit::Usage, anyhow::anyhow!("--ratio must be at least 1, got {r}")));
        }
    }
    let parent = req.output.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(std::path::Path::new("."));
    if !parent.is_dir() {
        return Err(Failure::new(Exit::Io, anyhow::anyhow!("the output folder {} does not exist", parent.display())));
    }
    let mut stages = Stages::new();
    if let Some(why) = filter_needs_probe(req.filter, req.matrix) {
        return Err(Failure::new(Exit::Usage, anyhow::anyhow!(why)));
    }
    let set = input::load(req, &mut stages)?;
    // A ratio is checked before any work: it must leave the level images a byte.
    let raw = set.raw_image_bytes();
    if let Some(r) = req.ratio.filter(|r| raw as f64 / r < 1.0) {
        return Err(Failure::new(Exit::Usage, anyhow::anyhow!("--ratio {r} leaves no byte for the level images of this set (raw images {raw} bytes): the highest ratio is {raw}:1")));
    }
    let mut matrices = matrices::Matrices::open(req.matrix, req.filter)?;
    let inferred = infer_layers::infer_all(&set, req, &mut matrices, &mut stages).map_err(|e| Failure::new(Exit::Runtime, e))?;
    let probe_renderings = matrices.renderings();
    drop(matrices);
    let mut packed = encode::encode_all(&set, &inferred, req, &mut stages)?;
    let quality = encode::predicted_psnr(&set, &inferred, &packed).map_err(|e| Failure::new(Exit::Runtime, e))?;
    stages.done("predict", &format!("decoded textures rendered through the render matrices ({})", req.matrix.name()));
    // The prediction travels with the file: `pis-diff FILE SET --max-psnr-drop` measures
    // the played PSNR against it.
    if let Some(p) = packed.container.provenance.as_mut() {
        p.settings.push((PREDICTED_PSNR_SETTING.to_string(), format!("{:.4}", quality.overall)));
    }
    let masters = if extras.keep_master {
        let m = encode::masters(&inferred, &packed).map_err(|e| Failure::new(Exit::Runtime, e))?;
        let n: u64 = m.iter().map(pis_format::Master::payload_len).sum();
        stages.done("master", &format!("solved textures of {} objects coded losslessly ({n} bytes)", m.len()));
        m
    } else {
        Vec::new()
    };
    let bytes = pis_format::write_with_masters(&req.output, &packed.container, &masters)?;
    stages.done("write", &format!("{} ({bytes} bytes)", req.output.display()));
    // The master read back from the file decodes to the solved textures bit for bit.
    let master = if extras.keep_master {
        Some(encode::check_master(&req.output, &inferred).map_err(|e| Failure::new(Exit::Runtime, e))?)
    } else {
        None
    };
    // Lossless: the file's level images decode bit-exactly and the decoded textures equal
    // the solved ones.
    let exact = if req.codec == CodecId::Lossless {
        let levels = encode::check_lossless(&req.output, &packed).map_err(|e| Failure::new(Exit::Runtime, e))?;
        Some(levels && quality.max_texel_error == 0.0)
    } else {
        None
    };
    let mut report = report::build(&set, &inferred, &packed, &quality, bytes, exact, req, stages);
    report.probe_renderings = probe_renderings;
    if let Some((master_bytes, exact)) = master {
        report.set_master(master_bytes, exact);
    }
    Ok(report)
}

/// `N`, or `NxM…`: sizes of at least 1 separated by `x` (`--block`, `--resolution`).
pub fn parse_sizes(s: &str) -> Result<Vec<u32>, String> {
    s.split(['x', 'X']).map(|p| p.trim().parse::<u32>().ok().filter(|&b| b > 0).ok_or_else(|| format!("bad size {s:?}: expected N or NxM"))).collect()
}
