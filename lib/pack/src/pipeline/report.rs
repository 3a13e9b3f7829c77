//! The closing report of `pis-pack` (stderr lines; `--json` on stdout).

use std::collections::BTreeMap;

use serde::Serialize;

use super::input::LoadedSet;
use super::model::ObjectModel;
use super::packed::Packed;
use super::packed::Quality;
use super::{PackRequest, Stages};

/// One object's part of the report.
#[derive(Clone, Debug, Serialize)]
pub struct ObjectReport {
    pub name: String,
    /// The texture filter its surface textures were solved for (the file's, or its own:
    /// `--filter auto`).
    pub filter: String,
    /// The texel budget its placements were made under (level-0 texels per pixel of its most
    /// covered view: `--texels-per-pixel`, or its own under `auto`; `None`: no budget).
    pub texels_per_pixel: Option<f64>,
    /// The layers stored: `diffuse`, `specular` or `diffuse+specular`.
    pub representation: String,
    /// Why this representation was chosen.
    pub why: String,
    /// Under `--representation auto`, for an object with an alternative representation:
    /// the solved figures the screen read, whether the alternative was solved, weighed by
    /// whole-file encodes and kept.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub auto: Option<super::model::AutoChoice>,
    /// Where the mesh's texture coordinates could not hold a texture: what was charted
    /// again, and how.
    pub recharted: Option<String>,
    /// Codestream bytes of the object's level images.
    pub bytes: usize,
    /// Codestream bytes per stored layer.
    pub layer_bytes: BTreeMap<String, usize>,
    /// Predicted PSNR of the decoded textures through the hardware model.
    pub psnr_db: f64,
    /// The same for the textures as solved, before coding: the inference's own limit.
    pub psnr_db_solved: f64,
    /// The largest used texture size of the object's blocks.
    pub texture: [u32; 2],
    /// That texture's resolution reduction factor against thesis 3.2's optimal resolution
    /// (below 1 where the texel budget, `--texels-per-pixel`, reduced it; `--max-texture`
    /// clamps after it).
    pub reduction: f64,
    /// The used sizes of the distinct placements its blocks carry (thesis 3.2, per
    /// parameter block; one with `--placement object`).
    pub placements: Vec<[u32; 2]>,
    /// Block origin offsets per dimension (thesis 4.7).
    pub stagger: Vec<u32>,
    pub blocks: usize,
    pub level_images: usize,
    pub solver_iterations: u64,
    /// Mean covered pixels per point: the allocation's area weight.
    pub area_px: f64,
}

/// What the merge of a pack split over processes read ([`super::merge_fragments`]).
#[derive(Clone, Debug, Serialize)]
pub struct FragmentsReport {
    /// Fragment files read.
    pub files: usize,
    /// Solutions they hold.
    pub solutions: usize,
    /// Solves read from them.
    pub read: usize,
    /// Solves no fragment held, solved by the merge.
    pub solved: usize,
}

/// The pack report (`--json` prints it).
#[derive(Clone, Debug, Serialize)]
pub struct PackReport {
    pub output: String,
    pub source: String,
    pub codec: String,
    /// The player's texture filter the textures were solved for (`nearest`, `bilinear`,
    /// `trilinear`, `anisotropic`).
    /// The texel budget of `--texels-per-pixel` (`None`: none); an object's own is in its
    /// report.
    pub texels_per_pixel: Option<f64>,
    pub filter: String,
    /// The anisotropy clamp of `anisotropic` filtering.
    pub anisotropy: Option<u8>,
    /// Where the render matrices came from: `model` (the hardware model) or `probe`
    /// (measured through the GPU, thesis 3.4.3).
    pub matrix: String,
    /// Probe mode: test renderings made to measure every matrix (0 for the model).
    pub probe_renderings: u64,
    pub points: usize,
    pub resolution: [u32; 2],
    /// Raw image bytes of the set (points × width × height × 3).
    pub raw_image_bytes: u64,
    /// Bytes of the whole file, the lossless master included.
    pub bytes: u64,
    /// Bytes of the lossless master (`--keep-master`; 0 without): stored for re-encoding,
    /// never read by a player, and not counted by `ratio`.
    pub master_bytes: u64,
    /// `--keep-master`: the master read back from the file decodes to the solved textures
    /// bit for bit.
    pub master_exact: Option<bool>,
    /// Bytes of the level images alone.
    pub texture_bytes: usize,
    /// raw / bytes a player uses (file bytes less the master).
    pub ratio: f64,
    /// raw / level-image bytes.
    pub ratio_without_geometry: f64,
    /// The target ratio, when one was given (or the default); it applies to the level
    /// images, `ratio_without_geometry`.
    pub target_ratio: Option<f64>,
    pub target_psnr_db: Option<f64>,
    /// The played-quality target (the default): dB below the textures as solved.
    pub target_within_db: Option<f64>,
    /// Under a played-quality target: the predicted played PSNR aimed at, whether the file
    /// reaches it, and every allocation the search encoded and predicted.
    pub played: Option<PlayedReport>,
    /// Predicted PSNR over every object's covered pixels, decoded textures.
    pub psnr_db: f64,
    /// The same with the textures as solved.
    pub psnr_db_solved: f64,
    /// Largest |decoded − solved| over the finest texels (linear).
    pub max_texel_error: f32,
    /// Frames drawn from the decoded textures rounded to half floats against frames drawn
    /// from them in full (dB; SPEC.md 6.6 `half_float_psnr_db`); none where a texel lies
    /// beyond the half-float range.
    pub half_float_psnr_db: Option<f64>,
    /// Frames drawn from textures rebuilt from the level images held in 16 bits a value
    /// against frames drawn from the textures as decoded (dB; SPEC.md 6.6
    /// `level16_psnr_db`); none where a level image holds a value that is not finite.
    pub level16_psnr_db: Option<f64>,
    /// Lossless codec: every level image read back from the file decodes bit-exactly to
    /// what was encoded, and the decoded finest texels equal the solved ones bit for bit.
    pub lossless_exact: Option<bool>,
    /// The merge of a pack split over processes: what its fragments gave.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fragments: Option<FragmentsReport>,
    /// The allocation's max-MSE constraint (thesis 4.8) as applied: `off`, or its α.
    pub max_mse_ratio: Option<String>,
    /// `--max-mse-ratio auto` where the constraint changed the allocation: the predicted
    /// PSNR (dB) with it and with the free allocation; the higher was kept.
    pub max_mse_psnr_db: Option<MaxMsePsnr>,
    pub objects: Vec<ObjectReport>,
    pub stage_ms: BTreeMap<String, f64>,
    /// Per stage in order, `[name, MiB]`: the process's peak resident memory when the stage
    /// ended (empty where the system does not tell it).
    pub stage_peak_mib: Vec<(String, f64)>,
    /// How the pack held the set: in memory or streamed, and why.
    pub memory: MemoryReport,
    pub notes: Vec<String>,
}

/// How a pack held its set ([`super::memory`]).
#[derive(Clone, Debug, Serialize)]
pub struct MemoryReport {
    /// The budget in bytes (`--memory`, else the memory available; `None`: unknown).
    pub budget_bytes: Option<u64>,
    /// Whether the budget was asked for (`--memory`).
    pub budget_asked: bool,
    /// The bytes the pack was expected to take in memory.
    pub held_estimate_bytes: u64,
    /// Whether it streamed through a scratch file.
    pub streamed: bool,
    /// Bytes written to the scratch file.
    pub scratch_bytes: u64,
    /// The process's peak resident memory when the report was made (where the system tells
    /// it).
    pub peak_bytes: Option<u64>,
    /// In words.
    pub why: String,
}

impl MemoryReport {
    /// Whether the pack's peak went above the budget asked for: what a streamed pack still
    /// holds did not fit it.
    pub fn over_budget(&self) -> bool {
        self.budget_asked
            && matches!((self.peak_bytes, self.budget_bytes), (Some(p), Some(b)) if p > b)
    }
}

/// The search of a played-quality target.
#[derive(Clone, Debug, serde::Serialize)]
pub struct PlayedReport {
    /// The predicted played PSNR aimed at (dB).
    pub goal_db: f64,
    /// The file meets it; otherwise the codec's richest allocation falls short.
    pub reached: bool,
    /// Each allocation the last search tried, in order: the coding PSNR it aimed at, its
    /// level-image bytes, its predicted played PSNR.
    pub trials: Vec<super::played::Trial>,
    /// Objects that played more than 3 times the target below their own solved figure, whose
    /// allocation weight was raised for the next search.
    pub held: Vec<String>,
    /// Searches made (1 where no object needed holding).
    pub searches: usize,
}

/// Both allocations' predicted PSNR, when `auto` encoded both.
#[derive(Clone, Debug, serde::Serialize)]
pub struct MaxMsePsnr {
    pub constrained: f64,
    pub free: f64,
}

#[allow(clippy::too_many_arguments)]
pub fn build(
    set: &LoadedSet,
    models: &[ObjectModel],
    packed: &Packed,
    q: &Quality,
    bytes: u64,
    exact: Option<bool>,
    req: &PackRequest,
    stages: Stages,
) -> PackReport {
    let raw = set.raw_image_bytes();
    let texture_bytes: usize = packed.layer_bytes.iter().flatten().sum();
    let objects = models
        .iter()
        .enumerate()
        .map(|(mi, m)| {
            let ob = &packed.container.objects[mi];
            let used = m.used_placements();
            let largest = used
                .iter()
                .map(|&p| &m.placements[p])
                .max_by_key(|p| p.layout.width as u64 * p.layout.height as u64)
                .unwrap_or(&m.placements[0]);
            ObjectReport {
                name: m.name.clone(),
                filter: m.filter.name().to_string(),
                texels_per_pixel: m.texels_per_pixel,
                representation: m.representation.clone(),
                why: m.why.clone(),
                auto: m.auto.clone(),
                recharted: m.mesh.recharted.clone(),
                bytes: packed.layer_bytes[mi].iter().sum(),
                layer_bytes: m
                    .layers
                    .iter()
                    .zip(&packed.layer_bytes[mi])
                    .map(|(l, b)| (l.kind.name().to_string(), *b))
                    .collect(),
                psnr_db: q.objects[mi].0,
                psnr_db_solved: q.objects[mi].1,
                texture: [largest.layout.width, largest.layout.height],
                reduction: largest.reduction,
                placements: used
                    .iter()
                    .map(|&p| [m.placements[p].layout.width, m.placements[p].layout.height])
                    .collect(),
                stagger: packed.stagger[mi].clone(),
                blocks: ob.layers.iter().map(|l| l.blocks.len()).sum(),
                level_images: ob
                    .layers
                    .iter()
                    .flat_map(|l| &l.blocks)
                    .flat_map(|b| &b.levels)
                    .map(|l| l.images.len())
                    .sum(),
                solver_iterations: m.layers.iter().map(|l| l.iterations).sum(),
                area_px: m.area,
            }
        })
        .collect();
    PackReport {
        output: req.output.display().to_string(),
        source: set.dir.display().to_string(),
        codec: req.codec.name().to_string(),
        filter: req.filter.name().to_string(),
        texels_per_pixel: req.texels_per_pixel,
        anisotropy: match req.filter {
            pis_compile::Filter::Anisotropic(n) => Some(n),
            _ => None,
        },
        matrix: req.matrix.name().to_string(),
        probe_renderings: 0,
        points: set.samples.len(),
        resolution: [set.resolution.0, set.resolution.1],
        raw_image_bytes: raw,
        bytes,
        master_bytes: 0,
        master_exact: None,
        texture_bytes,
        ratio: raw as f64 / bytes.max(1) as f64,
        ratio_without_geometry: raw as f64 / texture_bytes.max(1) as f64,
        target_ratio: req.target.ratio().filter(|_| req.codec.is_lossy()),
        target_psnr_db: req.target.psnr(),
        target_within_db: req.target.within().filter(|_| req.codec.is_lossy()),
        played: packed.played.as_ref().map(|p| PlayedReport {
            goal_db: p.found.goal.goal_db,
            reached: p.found.reached,
            trials: p.found.trials.clone(),
            held: p.held.clone(),
            searches: p.searches,
        }),
        psnr_db: q.overall,
        psnr_db_solved: q.overall_solved,
        max_texel_error: q.max_texel_error,
        half_float_psnr_db: None,
        level16_psnr_db: None,
        lossless_exact: exact,
        fragments: None,
        max_mse_ratio: packed.container.provenance.as_ref().and_then(|p| p.setting("max_mse_ratio")).map(str::to_string),
        max_mse_psnr_db: packed.max_mse.as_ref().map(|c| MaxMsePsnr { constrained: c.psnr_db_constrained, free: c.psnr_db_free }),
        objects,
        stage_ms: stages.ms.into_iter().collect(),
        stage_peak_mib: stages.peak_mib,
        memory: MemoryReport {
            budget_bytes: set.memory.budget,
            budget_asked: set.memory.asked,
            held_estimate_bytes: set.memory.held,
            streamed: set.memory.stream,
            scratch_bytes: set.scratch.as_ref().map_or(0, |s| s.len()),
            peak_bytes: pis_trace::memory::peak_resident(),
            why: set.memory.describe(),
        },
        notes: vec![
            "PSNR through the render matrices (hardware model, or measured through the GPU in probe mode): decoded textures (MIP chain rebuilt by decimation) rendered with A, against the traced diffuse + specular layers over covered pixels, display values (sRGB, peak 1)".into(),
            format!("geometry, tables and headers: {} bytes", packed.overhead),
        ],
    }
}

impl PackReport {
    /// Records the lossless master: its bytes leave `ratio` counting what a player uses.
    pub fn set_master(&mut self, master_bytes: u64, exact: bool) {
        self.master_bytes = master_bytes;
        self.master_exact = Some(exact);
        self.ratio =
            self.raw_image_bytes as f64 / self.bytes.saturating_sub(master_bytes).max(1) as f64;
    }
}

/// Human-readable lines of the report.
pub fn print_report(r: &PackReport, out: &mut impl std::io::Write) -> std::io::Result<()> {
    writeln!(
        out,
        "{}: {} points of {}x{}, codec {}",
        r.output, r.points, r.resolution[0], r.resolution[1], r.codec
    )?;
    let anisotropy = r.anisotropy.map(|n| format!(" {n}x")).unwrap_or_default();
    let probe = if r.matrix == "probe" {
        format!(", {} probe renderings", r.probe_renderings)
    } else {
        String::new()
    };
    let own: Vec<&str> =
        r.objects.iter().filter(|o| o.filter != r.filter).map(|o| o.name.as_str()).collect();
    let own = match own.as_slice() {
        [] => String::new(),
        names => format!(" (bilinear for {}, chosen by held-out views)", names.join(", ")),
    };
    writeln!(
        out,
        "  filter {}{anisotropy}{own}, render matrices from the {}{probe}",
        r.filter,
        if r.matrix == "probe" { "GPU (probe mode)" } else { "hardware model" }
    )?;
    if let Some(line) = denser_line(r) {
        writeln!(out, "{line}")?;
    }
    writeln!(out, "  {} bytes (level images {}), raw {} bytes: ratio {:.1} (level images alone {:.1}, the ratio --ratio aims at)",
             r.bytes, r.texture_bytes, r.raw_image_bytes, r.ratio, r.ratio_without_geometry)?;
    if let Some(e) = r.master_exact {
        writeln!(out, "  lossless master: {} bytes, not counted by the ratio; decodes to the solved textures bit-exactly: {e}", r.master_bytes)?;
    }
    writeln!(
        out,
        "  predicted PSNR {:.2} dB (textures as solved {:.2} dB)",
        r.psnr_db, r.psnr_db_solved
    )?;
    writeln!(out, "  16-bit textures: {}", half_float_note(r.half_float_psnr_db, r.psnr_db))?;
    writeln!(out, "  16-bit level images: {}", level16_note(r.level16_psnr_db, r.psnr_db))?;
    if let Some(p) = &r.played {
        let within = r.target_within_db.unwrap_or_default();
        let how = if p.reached {
            format!("met with the fewest bytes of {} allocations tried", p.trials.len())
        } else {
            format!("out of reach: the richest of {} allocations tried kept", p.trials.len())
        };
        writeln!(
            out,
            "  target: within {within} dB of the textures as solved, {:.2} dB played: {how}",
            p.goal_db
        )?;
        if !p.held.is_empty() {
            let limit = within * super::played::OBJECT_WITHIN_FACTOR;
            writeln!(out, "  held within {limit} dB of their solved figure by a raised allocation weight ({} searches): {}", p.searches, p.held.join(", "))?;
        }
    }
    match (&r.max_mse_ratio, &r.max_mse_psnr_db) {
        (Some(a), Some(p)) => writeln!(out, "  allocation: max-MSE constraint {} (predicted {:.2} dB with the constraint, {:.2} dB free: the higher kept)", if a == "off" { "dropped" } else { "kept" }, p.constrained, p.free)?,
        (Some(a), None) if a == "off" => writeln!(out, "  allocation: free (no max-MSE constraint)")?,
        (Some(a), None) => writeln!(out, "  allocation: max-MSE constraint at alpha {a}")?,
        _ => {}
    }
    if let Some(e) = r.lossless_exact {
        writeln!(out, "  lossless: file decodes to the solved textures bit-exactly: {e} (max texel error {:.3e})", r.max_texel_error)?;
    }
    if let Some(f) = &r.fragments {
        writeln!(
            out,
            "  fragments: {} files, {} solutions; {} solves read from them, {} solved here",
            f.files, f.solutions, f.read, f.solved
        )?;
    }
    for o in &r.objects {
        let layers: Vec<String> = o.layer_bytes.iter().map(|(k, b)| format!("{k} {b}")).collect();
        let sizes = if o.placements.len() > 1 {
            format!(" up to, {} placements", o.placements.len())
        } else {
            String::new()
        };
        writeln!(out, "  {:<10} {:<17} {:>8} bytes ({}), {:.2} dB (solved {:.2}), {}x{}{sizes} (reduction {:.2}), stagger {:?}, {} blocks, {} level images",
                 o.name, o.representation, o.bytes, layers.join(", "), o.psnr_db, o.psnr_db_solved, o.texture[0], o.texture[1],
                 o.reduction, o.stagger, o.blocks, o.level_images)?;
        writeln!(out, "             why: {}", o.why)?;
    }
    let stages: Vec<String> = r.stage_ms.iter().map(|(k, v)| format!("{k} {v:.0}")).collect();
    writeln!(out, "  stages (ms): {}", stages.join(", "))?;
    if r.memory.streamed {
        writeln!(
            out,
            "  memory: {}; scratch file {:.0} MiB",
            r.memory.why,
            r.memory.scratch_bytes as f64 / (1 << 20) as f64
        )?;
    }
    if r.memory.over_budget() {
        let gib = |b: Option<u64>| b.unwrap_or(0) as f64 / (1u64 << 30) as f64;
        writeln!(out, "  memory: the peak of {:.2} GiB is above --memory {:.2} GiB: what a streamed pack still holds (meshes, placements, the codestreams, shell render matrices, a lens object's layers) did not fit", gib(r.memory.peak_bytes), gib(r.memory.budget_bytes))?;
    }
    if !r.stage_peak_mib.is_empty() {
        let peaks: Vec<String> =
            r.stage_peak_mib.iter().map(|(k, v)| format!("{k} {v:.0}")).collect();
        writeln!(out, "  peak memory after each stage (MiB): {}", peaks.join(", "))?;
    }
    Ok(())
}

/// The report's line naming the objects whose texel budget was raised (`--texels-per-pixel
/// auto`), where there are any.
fn denser_line(r: &PackReport) -> Option<String> {
    let raised: Vec<String> = r
        .objects
        .iter()
        .filter(|o| o.texels_per_pixel != r.texels_per_pixel)
        .filter_map(|o| Some(format!("{} for {}", o.texels_per_pixel?, o.name)))
        .collect();
    let k = r.texels_per_pixel?;
    (!raised.is_empty()).then(|| {
        format!("  texels per pixel {k} ({}, chosen by held-out views)", raised.join(", "))
    })
}

/// What 16-bit level images cost a file of predicted PSNR `coding_db`, and what a player
/// that rebuilds its textures on the GPU makes of it.
pub fn level16_note(level16_db: Option<f64>, coding_db: f64) -> String {
    use pis_format::precision::HALF_FLOAT_MARGIN_DB;
    match level16_db {
        None => "a value is not finite: players rebuilding on the GPU keep 32-bit level images".into(),
        Some(h) if h - coding_db >= HALF_FLOAT_MARGIN_DB => format!("frames {h:.2} dB from full precision, {:.1} dB below the coding error: players rebuilding on the GPU hold them in 16 bits", h - coding_db),
        Some(h) => format!("frames {h:.2} dB from full precision, {:.1} dB below the coding error ({HALF_FLOAT_MARGIN_DB} needed): players rebuilding on the GPU keep 32-bit floats", h - coding_db),
    }
}

/// What half floats cost a file of predicted PSNR `coding_db`, and what a player makes of it.
pub fn half_float_note(half_db: Option<f64>, coding_db: f64) -> String {
    use pis_format::precision::HALF_FLOAT_MARGIN_DB;
    match half_db {
        None => "a texel lies beyond the half-float range: players keep 32-bit floats".into(),
        Some(h) if h - coding_db >= HALF_FLOAT_MARGIN_DB => format!("frames {h:.2} dB from full precision, {:.1} dB below the coding error: players hold the textures in half floats", h - coding_db),
        Some(h) => format!("frames {h:.2} dB from full precision, {:.1} dB below the coding error ({HALF_FLOAT_MARGIN_DB} needed): players keep 32-bit floats", h - coding_db),
    }
}
