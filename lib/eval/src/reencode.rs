//! `pis-reencode`: a container's textures coded again, with another codec, rate or gamma.
//!
//! The source is the file's lossless master when it carries one (SPEC.md 6.7: the textures
//! as `pis-pack` solved them, and each object's screen-area weight), else every parameter
//! block of every layer decoded at all its samples. The linear textures are
//! gamma-compensated again (thesis 4.6), built into new adaptive Laplacian pyramids (4.3),
//! given storage by the equal-slope allocation `pis-pack` uses over all level images of all
//! blocks, layers and objects, weighted by screen area (4.5), and encoded: from a master, the
//! steps and inputs of a direct pack at the new settings. Geometry, cameras, the parameter
//! space, block origins and placements are copied; with `--block` the samples are grouped
//! into blocks of new sizes, their origins staggered per object as pis-pack staggers them
//! (thesis 4.7), each new block keeping the layer's texture placement. The output is written atomically, read
//! back and compared with the input's decoded textures (and, with a master, both files with
//! the master).

mod container;
mod master;
mod screen_area;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

use crate::metrics::SquaredError;
use anyhow::anyhow;
use pis_codec::allocate;
use pis_codec::CodecId;
use pis_format::reconstruct::{finish, prepare};
use pis_format::*;
use rayon::prelude::*;
use serde::Serialize;

pub use screen_area::screen_areas;

use pis_pack::blocks::{block_sizes, stagger};
use pis_pack::storage::{allocate_storage, build_pyramid, encode_levels, nudge, BlockPyramid};
use pis_pack::{Exit, Failure, MaxMse, Target};

/// What to re-encode.
#[derive(Clone, Debug)]
pub struct ReencodeRequest {
    pub input: PathBuf,
    pub output: PathBuf,
    pub codec: CodecId,
    /// What the lossy codecs aim at, as pis-pack's `--ratio` or `--psnr` give it
    /// ([`Target::given`]): a compression ratio (level-image bytes = raw image bytes /
    /// ratio) or a PSNR (dB) of the stored textures. None: the input's level-image bytes.
    pub target: Option<Target>,
    /// Gamma of the compensation (lossy codecs; default [`DEFAULT_GAMMA`]).
    pub gamma: Option<f32>,
    /// Write the lossless master into the output: the input's, or one made from the decoded
    /// textures of an input whose level images are all exact.
    pub keep_master: bool,
    /// New parameter-block sizes (one for every dimension, or one per dimension), the block
    /// origins staggered again as pis-pack staggers them; None keeps the input's blocks.
    pub block: Option<Vec<u32>>,
    /// The allocation's max-MSE constraint (thesis 4.8): `Off` or `On(α)`. None: what the
    /// input's provenance records its writer applied (`max_mse_ratio`), α = 1.25 where it
    /// records nothing.
    pub max_mse: Option<MaxMse>,
    /// The memory budget in bytes for the decoded textures and the new pyramids
    /// ([`crate::budget`]): an input that would take more is refused before decoding (exit 5).
    pub memory: u64,
}

/// The max-MSE constraint the input's writer applied, from its provenance setting
/// `max_mse_ratio` (`off` or α, as [`MaxMse`] parses it); α = 1.25 where none is recorded.
fn writer_max_mse<S>(c: &pis_format::Container<S>) -> MaxMse {
    c.provenance
        .as_ref()
        .and_then(|p| p.settings.iter().rev().find(|(k, _)| k == "max_mse_ratio"))
        .and_then(|(_, v)| v.parse::<MaxMse>().ok())
        .unwrap_or(MaxMse::On(pis_codec::allocate::DEFAULT_ALPHA))
}

/// The gamma lossy re-encodings use unless told otherwise (as `pis-pack`).
pub const DEFAULT_GAMMA: f32 = pis_codec::gamma::DEFAULT_GAMMA;

/// One object's part of the report.
#[derive(Clone, Debug, Serialize)]
pub struct ObjectReport {
    pub name: String,
    pub bytes_before: u64,
    pub bytes_after: u64,
    /// PSNR of the re-encoded textures against the input's decoded textures (display
    /// values, every parameter point); null when they are identical.
    pub psnr_db: Option<f64>,
    pub mse: f64,
    pub max_error: f64,
    pub exact: bool,
    /// Mean covered pixels per point: the allocation's screen-area weight (lossy codecs).
    pub area_px: Option<f64>,
    /// PSNR of the input's and the output's textures against the master (null without a
    /// master, or when identical).
    pub psnr_master_before_db: Option<f64>,
    pub psnr_master_after_db: Option<f64>,
}

/// The report (`--json` prints it).
#[derive(Clone, Debug, Serialize)]
pub struct ReencodeReport {
    pub input: String,
    pub output: String,
    /// The input's codecs, by name.
    pub codecs_before: Vec<String>,
    pub codec: String,
    pub gamma: f32,
    pub target: String,
    /// What the new level images were coded from: `master` (the input's lossless master)
    /// or `decoded textures` (the input's level images decoded).
    pub source: String,
    /// Whole files, the lossless master included.
    pub bytes_before: u64,
    pub bytes_after: u64,
    /// Bytes of the lossless master in each file (0 without); the ratios leave them out.
    pub master_bytes_before: u64,
    pub master_bytes_after: u64,
    /// Level-image bytes.
    pub texture_bytes_before: u64,
    pub texture_bytes_after: u64,
    pub raw_image_bytes: u64,
    /// Raw image bytes over the bytes a player uses (file bytes less the master).
    pub ratio_before: f64,
    pub ratio_after: f64,
    /// Raw image bytes over level-image bytes.
    pub ratio_without_geometry_before: f64,
    pub ratio_without_geometry_after: f64,
    /// Whole-file texture PSNR of the output against the input's decoded textures; null when
    /// identical.
    pub psnr_db: Option<f64>,
    pub mse: f64,
    pub max_error: f64,
    /// The output decodes to exactly the input's textures.
    pub exact: bool,
    /// With a master: whole-file texture PSNR of the input and of the output against it, and
    /// the change (after − before; null when either is identical to the master).
    pub psnr_master_before_db: Option<f64>,
    pub psnr_master_after_db: Option<f64>,
    pub psnr_change_db: Option<f64>,
    pub level_images: usize,
    pub objects: Vec<ObjectReport>,
    pub stage_ms: BTreeMap<String, f64>,
}

/// Opens a container, naming the file in any error.
pub fn open(path: &Path) -> Result<PisReader, Failure> {
    PisReader::open(path).map_err(|e| in_file(path, e))
}

/// A reader error as a failure that names the file once.
pub fn in_file(path: &Path, e: Error) -> Failure {
    let msg = match &e {
        Error::Io { .. } => e.to_string(),
        _ => format!("{}: {e}", path.display()),
    };
    Failure::new(Failure::from(e).exit, anyhow!(msg))
}

fn usage(msg: String) -> Failure {
    Failure::new(Exit::Usage, anyhow!(msg))
}

/// Checks the request before anything is read.
fn check(req: &ReencodeRequest) -> Result<(), Failure> {
    if let Some(t) = req.target {
        t.check().map_err(usage)?;
        if t.within().is_some() {
            return Err(usage("a played-quality target needs the traced set to predict against: give pis-reencode --ratio or --psnr".to_string()));
        }
    }
    if let Some(g) = req.gamma {
        if !(g.is_finite() && g > 0.0) {
            return Err(usage(format!("--gamma must be positive, got {g}")));
        }
    }
    if !req.codec.is_lossy() {
        if req.target.is_some() {
            return Err(usage(format!(
                "--ratio and --psnr apply to the lossy codecs; {} stores textures exactly",
                req.codec
            )));
        }
        if req.gamma.is_some_and(|g| g != 1.0) {
            return Err(usage(format!(
                "{} stores linear textures exactly: --gamma must be 1",
                req.codec
            )));
        }
    }
    let parent =
        req.output.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    if !parent.is_dir() {
        return Err(Failure::new(
            Exit::Io,
            anyhow!("the output folder {} does not exist", parent.display()),
        ));
    }
    Ok(())
}

/// Gamma-compensated values of a linear texture for `layer`; for exact codecs (gamma 1) the
/// stored MIP residuals are nudged so that the reader's `residual + decimate(finest)` gives
/// every linear value back bit for bit.
fn prepared(
    layer: &Layer<StreamRef>,
    layout: &LevelLayout,
    linear: &[f32],
    exact: bool,
) -> Vec<f32> {
    let mut p = prepare(layer, layout, linear);
    if !(exact && layer.mip_mode == MipMode::Stored && layout.mips > 1) {
        return p;
    }
    // Which values are MIP residuals (planes below the finest of each face).
    let mut residual = vec![false; p.len()];
    let mut start = 0;
    for (pi, s) in layout.planes().iter().enumerate() {
        let n = (s.width * s.height * s.channels) as usize;
        if !(pi as u32).is_multiple_of(layout.mips) {
            residual[start..start + n].iter_mut().for_each(|r| *r = true);
        }
        start += n;
    }
    let base: Vec<f32> = p.iter().zip(&residual).map(|(&v, &r)| if r { 0.0 } else { v }).collect();
    let decimated = finish(layer, layout, base);
    for i in (0..p.len()).filter(|&i| residual[i]) {
        let (d, x) = (decimated[i], linear[i]);
        for k in 0..=32 {
            let c = nudge(x - d, if k % 2 == 1 { (k + 1) / 2 } else { -(k / 2) });
            if (c + d).to_bits() == x.to_bits() {
                p[i] = c;
                break;
            }
        }
    }
    p
}

struct Timer(Vec<(String, f64)>, Instant);

impl Timer {
    fn done(&mut self, name: &str, what: &str) {
        let ms = self.1.elapsed().as_secs_f64() * 1e3;
        eprintln!("pis-reencode: {name:<9} {ms:8.0} ms  {what}");
        self.0.push((name.to_string(), ms));
        self.1 = Instant::now();
    }
}

fn stream_bytes<S>(o: &Object<S>, len: impl Fn(&S) -> u64) -> u64 {
    o.layers
        .iter()
        .flat_map(|l| &l.blocks)
        .flat_map(|b| &b.levels)
        .flat_map(|l| &l.images)
        .map(len)
        .sum()
}

/// The parameter blocks of the output: the input's, or `--block`'s sizes with the origins
/// staggered per object as pis-pack staggers them.
fn new_blocks<S>(
    c: &Container<S>,
    req: &ReencodeRequest,
) -> Result<(ParameterSpace, Vec<Vec<u32>>), Failure> {
    let mut space = c.space.clone();
    let staggers: Vec<Vec<u32>> = match &req.block {
        None => c.objects.iter().map(|o| o.stagger.clone()).collect(),
        Some(b) => {
            let sizes = block_sizes(b, c.space.dims.len()).map_err(|e| usage(e.to_string()))?;
            for (d, &s) in space.dims.iter_mut().zip(&sizes) {
                d.block_size = s;
            }
            let samples: Vec<usize> = c.space.dims.iter().map(|d| d.values.len()).collect();
            (0..c.objects.len())
                .map(|i| stagger(i, c.objects.len(), &sizes, &samples, pis_pack::Stagger::Auto))
                .collect()
        }
    };
    Ok((space, staggers))
}

/// Every block's textures, gamma compensated again, in their pyramids (in the order of the
/// objects, layers and blocks), with the layers' gammas.
struct Pyramids {
    blocks: Vec<BlockPyramid>,
    /// Per object, per layer.
    gammas: Vec<Vec<f32>>,
    /// A master made from an exactly coded input: per object, layer and table sample.
    made: Vec<Vec<Vec<Vec<f32>>>>,
}

/// Every block's textures (the master's, or decoded), gamma compensated again, into its
/// pyramid.
fn build_pyramids(
    req: &ReencodeRequest,
    input: &PisReader,
    masters_in: &[Master],
    space: &ParameterSpace,
    staggers: &[Vec<u32>],
    gamma: f32,
) -> Result<Pyramids, Failure> {
    let runtime = |e: anyhow::Error| Failure::new(Exit::Runtime, e);
    let c = input.container();
    let exact = !req.codec.is_lossy();
    let from_master = !masters_in.is_empty();
    let mut pyramids: Vec<BlockPyramid> = Vec::new();
    let mut layers_out = Vec::new();
    // A master made from an exactly coded input: per object, layer and table sample.
    let mut made: Vec<Vec<Vec<Vec<f32>>>> = Vec::new();
    for (oi, o) in c.objects.iter().enumerate() {
        let mut per_layer = Vec::new();
        let mut made_layers = Vec::new();
        for (li, l) in o.layers.iter().enumerate() {
            let mut layer = l.clone();
            layer.gamma = gamma;
            let layer_samples = c.space.table_len(l.depends_on).max(1) as f64;
            let sources = match masters_in.iter().find(|m| m.object as usize == oi) {
                Some(m) => master::from_master(c, m, oi, li),
                None => master::from_decoded(input, oi, li),
            }
            .map_err(|e| in_file(&req.input, e))?;
            let sources = if req.block.is_some() {
                master::regroup(c, space, &staggers[oi], oi, li, sources)
                    .map_err(|e| Failure::new(Exit::NotSupported, anyhow::Error::from(e)))?
            } else {
                sources
            };
            let blocks = sources
                .par_iter()
                .map(|b| {
                    let samples: Vec<Vec<f32>> = b
                        .textures
                        .par_iter()
                        .map(|x| prepared(&layer, &b.layout, x, exact))
                        .collect();
                    let mut p = build_pyramid(
                        oi,
                        b.layout.planes(),
                        &b.extent,
                        &samples,
                        layer_samples,
                        exact,
                        false,
                    )
                    .map_err(runtime)?;
                    // The master's screen weights: the allocation of the pack that wrote it.
                    p.texel_weights = b.weights.clone().filter(|_| !exact);
                    Ok(p)
                })
                .collect::<Result<Vec<BlockPyramid>, Failure>>()?;
            if req.keep_master && !from_master {
                let mut table = vec![Vec::new(); layer_samples as usize];
                for b in sources {
                    for (x, t) in b.textures.into_iter().zip(b.tables) {
                        table[t] = x;
                    }
                }
                made_layers.push(table);
            }
            pyramids.extend(blocks);
            per_layer.push(layer.gamma);
        }
        layers_out.push(per_layer);
        made.push(made_layers);
    }
    Ok(Pyramids { blocks: pyramids, gammas: layers_out, made })
}

/// The allocation's target, and how the provenance records it.
fn target(
    req: &ReencodeRequest,
    raw: u64,
    texture_bytes_before: u64,
) -> (allocate::Target, String) {
    let given = req.target.and_then(|t| Some((t.fixed_allocation(raw)?, t.describe())));
    match given {
        _ if !req.codec.is_lossy() => (allocate::Target::Bytes(usize::MAX), "exact".to_string()),
        Some(fixed) => fixed,
        None => {
            let bytes = allocate::Target::Bytes(texture_bytes_before as usize);
            (bytes, format!("bytes {texture_bytes_before}"))
        }
    }
}

/// The objects' allocation weights: a master's (those its writer used), else measured
/// screen areas when `needed`.
fn allocation_areas(
    c: &Container<StreamRef>,
    masters_in: &[Master],
    needed: bool,
    t: &mut Timer,
) -> Option<Vec<f64>> {
    let from_master = !masters_in.is_empty();
    if from_master {
        Some(
            c.objects
                .iter()
                .enumerate()
                .map(|(oi, _)| {
                    masters_in.iter().find(|m| m.object as usize == oi).map_or(1.0, |m| m.area)
                })
                .collect::<Vec<f64>>(),
        )
    } else if needed {
        let a = screen_areas(c);
        t.done(
            "areas",
            &format!("screen areas of {} objects over {} points", a.len(), c.space.point_count()),
        );
        Some(a)
    } else {
        None
    }
}

/// The input's master, if it carries one; refused for `--keep-master` when it has none
/// and cannot make one (its level images are lossy).
fn masters_in(req: &ReencodeRequest, input: &PisReader) -> Result<Vec<Master>, Failure> {
    let c = input.container();
    let masters_in = if input.has_master() {
        input.masters().map_err(|e| in_file(&req.input, e))?
    } else {
        Vec::new()
    };
    let input_exact = c.level_images().all(|s| !s.codec.is_lossy());
    if req.keep_master && masters_in.is_empty() && !input_exact {
        return Err(usage(format!(
            "--keep-master: {} carries no master and its level images are lossy: a master is carried over from a file that has one (pis-pack --keep-master) or made from a losslessly coded file",
            req.input.display())));
    }
    Ok(masters_in)
}

/// The master the output carries: none without `--keep-master`; the input's; or one made
/// from the exactly coded input's textures (`made`), with the measured `areas`.
fn masters_out(
    req: &ReencodeRequest,
    out: &Container,
    masters_in: &[Master],
    made: &[Vec<Vec<Vec<f32>>>],
    areas: Option<&[f64]>,
    t: &mut Timer,
) -> Result<Vec<Master>, Failure> {
    Ok(if !req.keep_master {
        Vec::new()
    } else if !masters_in.is_empty() {
        masters_in.to_vec()
    } else {
        let a = areas.unwrap_or(&[]);
        let m = made
            .iter()
            .enumerate()
            .map(|(oi, textures)| {
                Master::encode(out, oi, a.get(oi).copied().unwrap_or(1.0), textures, None)
            })
            .collect::<Result<Vec<Master>, Error>>()
            .map_err(|e| Failure::new(Exit::Runtime, anyhow::Error::from(e)))?;
        t.done("master", &format!("decoded textures of {} objects coded losslessly", m.len()));
        m
    })
}

/// Scores against the master: the pooled error and each object's.
type MasterScores = Option<(SquaredError, Vec<SquaredError>)>;

/// Per object: bytes before and after, the output's error against the input, and with a
/// master both files' errors against it.
fn object_reports(
    c: &Container<StreamRef>,
    output: &PisReader,
    diff: &crate::diff::ContentDiff,
    areas: Option<&[f64]>,
    (vs_before, vs_after): (&MasterScores, &MasterScores),
) -> Vec<ObjectReport> {
    let finite = |p: f64| p.is_finite().then_some(p);
    let object_psnr = |s: &MasterScores, i: usize| s.as_ref().and_then(|s| finite(s.1[i].psnr()));
    c.objects
        .iter()
        .zip(&output.container().objects)
        .zip(&diff.objects)
        .enumerate()
        .map(|(i, ((a, b), d))| ObjectReport {
            name: a.name.clone(),
            bytes_before: stream_bytes(a, |s| s.length as u64),
            bytes_after: stream_bytes(b, |s| s.length as u64),
            psnr_db: d.score.psnr_db,
            mse: d.score.mse,
            max_error: d.score.max_error,
            exact: d.score.exact,
            area_px: areas.map(|a| a[i]),
            psnr_master_before_db: object_psnr(vs_before, i),
            psnr_master_after_db: object_psnr(vs_after, i),
        })
        .collect()
}

/// Re-encodes `req.input` into `req.output`; on error no output file is left.
pub fn reencode(req: &ReencodeRequest) -> Result<ReencodeReport, Failure> {
    check(req)?;
    crate::budget::check_reencode(&req.input, req.memory)?;
    let runtime = |e: anyhow::Error| Failure::new(Exit::Runtime, e);
    let mut t = Timer(Vec::new(), Instant::now());
    let input = open(&req.input)?;
    let c = input.container();
    let masters_in = masters_in(req, &input)?;
    let from_master = !masters_in.is_empty();
    // The parameter blocks: the input's, or new sizes with origins staggered per object.
    let (space, staggers) = new_blocks(c, req)?;
    let exact = !req.codec.is_lossy();
    let gamma = if exact { 1.0 } else { req.gamma.unwrap_or(DEFAULT_GAMMA) };
    let texture_bytes_before: u64 =
        c.objects.iter().map(|o| stream_bytes(o, |s| s.length as u64)).sum();
    let raw =
        c.provenance.as_ref().map(|p| p.raw_image_bytes).filter(|&b| b > 0).unwrap_or(
            c.space.point_count() * c.cameras.width as u64 * c.cameras.height as u64 * 3,
        );

    // Every block's textures (the master's, or decoded), gamma compensated again, into its
    // pyramid.
    let source = if from_master { "master" } else { "decoded textures" };
    let Pyramids { blocks: mut pyramids, gammas: layers_out, made } =
        build_pyramids(req, &input, &masters_in, &space, &staggers, gamma)?;
    let level_images: usize = pyramids.iter().flat_map(|p| &p.levels).map(|l| l.1.len()).sum();
    t.done(
        "pyramid",
        &format!(
            "{} blocks from the {source}, {level_images} level images in adaptive pyramids",
            pyramids.len()
        ),
    );

    let (target, target_text) = target(req, raw, texture_bytes_before);
    // A budget too small for section 12's limits is refused before encoding; what the codec
    // makes of a budget that suffices is checked before writing (`check_limits`).
    let need = container::check_budget(&pyramids, &target, &target_text, raw)?;
    // A master carries the allocation weights its writer used; otherwise they are measured.
    let need_areas = !exact || (req.keep_master && !from_master);
    let areas = allocation_areas(c, &masters_in, need_areas, &mut t);
    // The constraint as asked, else as the writer applied it (a best-of choice needs the
    // traced set, which a re-encoding does not have).
    let max_mse = match req.max_mse.unwrap_or_else(|| writer_max_mse(c)) {
        MaxMse::Best(a) => MaxMse::On(a),
        m => m,
    };
    let storage = allocate_storage(
        &pyramids,
        req.codec,
        target,
        if exact { &[] } else { areas.as_deref().unwrap_or(&[]) },
        max_mse,
    )
    .map_err(runtime)?;
    if let Some(total) = storage.allocated {
        t.done("allocate", &format!("{total} bytes over {level_images} level images"));
    }
    let texture_bytes_after =
        encode_levels(&mut pyramids, req.codec, &storage.rates).map_err(runtime)? as u64;
    t.done("encode", &format!("{level_images} level images with {}", req.codec));

    // The container: everything copied but gamma and pyramids.
    let mut out = container::assemble(c, req, &space, &staggers, &layers_out, pyramids)?;
    let codecs_before = container::codecs(c);
    out.provenance = Some(container::provenance(
        c,
        req,
        &space,
        container::Applied { gamma, target: &target_text, max_mse },
        &codecs_before,
        raw,
    ));
    container::check_limits(&out, need)?;
    let masters_out = masters_out(req, &out, &masters_in, &made, areas.as_deref(), &mut t)?;
    let bytes_after =
        pis_format::write_with_masters(&req.output, &out, &masters_out).map_err(|e| match e {
            Error::Io { .. } => Failure::from(e),
            e => runtime(e.into()),
        })?;
    t.done("write", &format!("{} ({bytes_after} bytes)", req.output.display()));

    // Read back and compare with the input's decoded textures.
    let output = open(&req.output)?;
    let (diff, _) =
        crate::diff::compare(&input, &output, false, &mut |_| {}).map_err(|e| runtime(e.into()))?;
    t.done("compare", "output decoded at every sample against the input");
    let against =
        |r: &PisReader| master::error_against(r, &masters_in).map_err(|e| in_file(r.path(), e));
    let (vs_before, vs_after) = if from_master {
        let scores = (against(&input)?, against(&output)?);
        t.done("master", "input and output decoded at every sample against the master");
        (Some(scores.0), Some(scores.1))
    } else {
        (None, None)
    };
    let finite = |p: f64| p.is_finite().then_some(p);
    let objects = object_reports(c, &output, &diff, areas.as_deref(), (&vs_before, &vs_after));
    let bytes_before = input.len();
    let (master_bytes_before, master_bytes_after) = (input.master_bytes(), output.master_bytes());
    let psnr_master_before_db = vs_before.as_ref().and_then(|s| finite(s.0.psnr()));
    let psnr_master_after_db = vs_after.as_ref().and_then(|s| finite(s.0.psnr()));
    Ok(ReencodeReport {
        input: req.input.display().to_string(),
        output: req.output.display().to_string(),
        codecs_before,
        codec: req.codec.name().to_string(),
        gamma,
        target: target_text,
        source: source.to_string(),
        bytes_before,
        bytes_after,
        master_bytes_before,
        master_bytes_after,
        texture_bytes_before,
        texture_bytes_after,
        raw_image_bytes: raw,
        ratio_before: raw as f64 / (bytes_before - master_bytes_before).max(1) as f64,
        ratio_after: raw as f64 / (bytes_after - master_bytes_after).max(1) as f64,
        ratio_without_geometry_before: raw as f64 / texture_bytes_before.max(1) as f64,
        ratio_without_geometry_after: raw as f64 / texture_bytes_after.max(1) as f64,
        psnr_db: diff.score.psnr_db,
        mse: diff.score.mse,
        max_error: diff.score.max_error,
        exact: diff.score.exact && diff.complete,
        psnr_master_before_db,
        psnr_master_after_db,
        psnr_change_db: psnr_master_before_db.zip(psnr_master_after_db).map(|(b, a)| a - b),
        level_images,
        objects,
        stage_ms: t.0.into_iter().collect(),
    })
}

fn db(p: Option<f64>) -> String {
    p.map_or("identical".to_string(), |p| format!("{p:.2} dB"))
}

/// Human-readable lines of the report.
pub fn print_report(r: &ReencodeReport, out: &mut impl std::io::Write) -> std::io::Result<()> {
    writeln!(
        out,
        "{} → {}: {} → {} (gamma {}, target {}), from the {}",
        r.input,
        r.output,
        r.codecs_before.join("+"),
        r.codec,
        r.gamma,
        r.target,
        r.source
    )?;
    writeln!(
        out,
        "  bytes     {:>12} → {:>12}  (level images {} → {})",
        r.bytes_before, r.bytes_after, r.texture_bytes_before, r.texture_bytes_after
    )?;
    writeln!(
        out,
        "  ratio     {:>12.1} → {:>12.1}  (level images alone {:.1} → {:.1}; raw {} bytes)",
        r.ratio_before,
        r.ratio_after,
        r.ratio_without_geometry_before,
        r.ratio_without_geometry_after,
        r.raw_image_bytes
    )?;
    if r.master_bytes_before > 0 || r.master_bytes_after > 0 {
        writeln!(
            out,
            "  lossless master {:>12} → {:>12} bytes, not counted by the ratios",
            r.master_bytes_before, r.master_bytes_after
        )?;
    }
    writeln!(
        out,
        "  texture PSNR against the input's decoded textures: {} (max display error {:.4}){}",
        db(r.psnr_db),
        r.max_error,
        if r.exact { ", exact" } else { "" }
    )?;
    if r.source == "master" {
        let change = r.psnr_change_db.map_or("n/a".to_string(), |d| format!("{d:+.2} dB"));
        writeln!(
            out,
            "  texture PSNR against the master: {} → {} (change {change})",
            db(r.psnr_master_before_db),
            db(r.psnr_master_after_db)
        )?;
    }
    for o in &r.objects {
        writeln!(
            out,
            "  {:<12} {:>10} → {:>10} bytes  {:>10}  max error {:.4}",
            o.name,
            o.bytes_before,
            o.bytes_after,
            db(o.psnr_db),
            o.max_error
        )?;
    }
    let stages: Vec<String> = r.stage_ms.iter().map(|(k, v)| format!("{k} {v:.0}")).collect();
    writeln!(out, "  stages (ms): {}", stages.join(", "))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A stored-MIP layer at gamma 1 and an 8×8 texture as a reader decodes it from stored
    /// values: every MIP value is `residual + decimate(finest)` in f32, the residuals random.
    fn case() -> (Layer<StreamRef>, LevelLayout, Vec<f32>) {
        let layer = Layer {
            kind: LayerKind::EnvDistant,
            mapping: Mapping::Shell,
            channels: 3,
            mip_mode: MipMode::Stored,
            term: Term::Reflection,
            order: 0,
            combine: Combine::Over,
            basis: 0,
            gamma: 1.0,
            depends_on: DepMask::NONE,
            blocks: vec![],
        };
        let layout = LevelLayout { width: 8, height: 8, channels: 3, faces: 1, mips: 4 };
        let n: usize =
            layout.planes().iter().map(|p| (p.width * p.height * p.channels) as usize).sum();
        let mut seed = 12345u32;
        // Finest texels small, residuals large: the sums round.
        let linear = (0..n)
            .map(|i| {
                seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
                let u = (seed >> 8) as f32 / (1u32 << 24) as f32;
                if i < 8 * 8 * 3 {
                    u * 0.01
                } else {
                    u * 7.0 - 3.0
                }
            })
            .collect();
        let linear = finish(&layer, &layout, linear);
        (layer, layout, linear)
    }

    #[test]
    fn stored_mip_values_a_reader_decoded_round_trip_exactly() {
        let (layer, layout, linear) = case();
        let differ = |p: Vec<f32>| {
            finish(&layer, &layout, p)
                .iter()
                .zip(&linear)
                .filter(|(a, b)| a.to_bits() != b.to_bits())
                .count()
        };
        assert_eq!(differ(prepared(&layer, &layout, &linear, true)), 0);
        // The values are those the decoder's sum gives, whatever the residuals' scale.
        assert!(
            linear.iter().skip(8 * 8 * 3).any(|v| v.abs() > 1.0)
                && linear.iter().take(8 * 8 * 3).all(|v| v.abs() < 0.01)
        );
    }
}
