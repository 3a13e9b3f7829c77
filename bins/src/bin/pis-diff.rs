//! pis-diff: how two .pis files differ, in structure and in the textures they decode to.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Parser;
use pis::cli::{self, Exit, Failure};
use pis_eval::diff::files::{diff, render, DiffRequest};
use pis_eval::diff::gold::{gold, GoldRequest};

/// Compare two .pis files: structural differences (parameter space, cameras, objects, layers,
/// shells, blocks, pyramid levels, codecs, settings, provenance; bytes per chunk kind) and
/// content differences (both decoded at every parameter sample: MSE, PSNR and largest error
/// per object, layer and parameter block, and the whole file's PSNR, on display values).
/// Says "identical" when both decode to the same textures with the same structure.
///
/// With a ray-traced set folder as the second argument, measures the file against the gold
/// standard instead: every sample point drawn through the player's offscreen path and
/// compared with the set's image (the comparison `pis-play --headless --compare` prints):
/// PSNR per point, object and parameter block, and NVIDIA FLIP on the sRGB images (mean per
/// image, per object and overall); --heatmaps writes FLIP error maps per point.
///
/// With two set folders, compares the ray-traced sets themselves at the points both hold
/// (e.g. a set against one traced with more samples per pixel: the Monte Carlo noise of the
/// gold standard, which bounds any PSNR measured against it): PSNR of the combined images
/// per point and overall, and per object over the pixels both cover. For reflective and
/// refractive objects it adds the second set's layers composed as the player's model
/// composes them (diffuse + fresnel · (local + (1 − α) · distant); diffuse + reflection +
/// refraction, the greedy two-path model) against the first set's surface radiance: the
/// ceiling of any file that stores the object in that model. A set against itself gives the
/// model's own error.
#[derive(Parser, Debug)]
#[command(
    name = "pis-diff",
    version,
    after_help = "Exit codes: 0 identical or within the gates, 1 bad arguments, 2 I/O error, 3 invalid file, 4 runtime error, 5 not supported, 7 the files differ (no gate given) or a gate failed"
)]
struct Cli {
    /// The first .pis file (the reference), or a ray-traced set folder (with a second one).
    a: PathBuf,
    /// The second .pis file, or a ray-traced set folder (gold-standard comparison).
    b: PathBuf,
    /// Print the report as JSON on stdout.
    #[arg(long)]
    json: bool,
    /// Write one error heatmap (PNG, RMS display error per texel over all samples, faces
    /// side by side) per object and layer into DIR.
    #[arg(long, value_name = "DIR")]
    heatmaps: Option<PathBuf>,
    /// Gate: pass (exit 0) when the whole-file PSNR is at least DB, else exit 7.
    #[arg(long, value_name = "DB", allow_hyphen_values = true)]
    min_psnr: Option<f64>,
    /// Gate against a gold-standard set: fail when the PSNR is more than DB below the
    /// reference: the file's recorded prediction (provenance setting predicted_psnr_db) or
    /// --reference-psnr. Needs a set folder as the second argument.
    #[arg(long, value_name = "DB", allow_hyphen_values = true)]
    max_psnr_drop: Option<f64>,
    /// The reference PSNR of --max-psnr-drop (dB), e.g. pis-pack's predicted PSNR.
    #[arg(long, value_name = "DB", allow_hyphen_values = true)]
    reference_psnr: Option<f64>,
    /// Against a set: samples per pixel of the player's frames, as `pis-play --msaa` (4
    /// antialiases silhouettes; 1 draws as pis-compile's hardware model, whose covered
    /// pixels pis-pack's prediction measures: compare with the prediction at 1). With 4 the
    /// samples are resolved with the display filter the file records, or else the set's
    /// (`set.json` `filter`): each pixel mixes the objects of its 3×3 neighbourhood's
    /// samples by their Gaussian coverage, as the gold standard's pixels are filtered.
    #[arg(long, default_value_t = pis_play::multisample::DEFAULT_SAMPLES, value_name = "1|4", value_parser = pis::play::args::parse_msaa)]
    msaa: u32,
    /// Memory budget in GiB for two files' decoded textures (a block of each at a time): a
    /// pair whose largest blocks would take more is refused before decoding (exit 5).
    /// Default: 4, or half the memory available where that is less.
    #[arg(long, value_name = "GB", value_parser = pis_eval::budget::parse_memory)]
    memory: Option<f64>,
    /// Two sets: read their raw layers where they hold denoised twins (pis-trace
    /// --denoise); by default a layer with a twin reads as the twin.
    #[arg(long)]
    raw: bool,
    /// Against a set: a second trace of the gold-standard set (the set folder a file is
    /// measured against, or the first of two sets) from an independent sample stream
    /// (`pis-trace --seed 1 --shading-seed sample`). Their difference measures the gold
    /// standard's own noise, printed beside each figure with the figure's estimate with that
    /// noise taken out (what a converged reference would measure).
    #[arg(long, value_name = "SET_DIR")]
    reference_pair: Option<PathBuf>,
}

fn run(cli: Cli) -> Result<Exit, Failure> {
    if cli.a.is_dir() && cli.b.is_dir() {
        if cli.max_psnr_drop.is_some() || cli.reference_psnr.is_some() || cli.heatmaps.is_some() {
            return Err(Failure::new(
                Exit::Usage,
                anyhow::anyhow!("two ray-traced sets compare with --min-psnr and --json only"),
            ));
        }
        let report = pis_eval::diff::sets::compare_sets(&pis_eval::diff::sets::SetsRequest {
            a: cli.a,
            b: cli.b,
            min_psnr: cli.min_psnr,
            raw: cli.raw,
            pair: cli.reference_pair,
        })?;
        if cli.json {
            let s = serde_json::to_string_pretty(&report)
                .map_err(|e| Failure::new(Exit::Runtime, e))?;
            println!("{s}");
        } else {
            print!("{}", pis_eval::diff::sets::render(&report));
        }
        return Ok(report.exit());
    }
    if cli.b.is_dir() {
        let req = GoldRequest {
            file: cli.a,
            set: cli.b,
            heatmaps: cli.heatmaps,
            min_psnr: cli.min_psnr,
            max_psnr_drop: cli.max_psnr_drop,
            reference_psnr: cli.reference_psnr,
            msaa: cli.msaa,
            pair: cli.reference_pair,
        };
        let report = gold(&req)?;
        if cli.json {
            let s = serde_json::to_string_pretty(&report)
                .map_err(|e| Failure::new(Exit::Runtime, e))?;
            println!("{s}");
        } else {
            print!("{}", pis_eval::diff::gold::render(&report));
        }
        return Ok(report.exit());
    }
    if cli.max_psnr_drop.is_some() || cli.reference_psnr.is_some() || cli.reference_pair.is_some() {
        return Err(Failure::new(Exit::Usage, anyhow::anyhow!("--max-psnr-drop and --reference-pair compare with a gold-standard set: give a set folder as the second argument")));
    }
    let memory = pis_eval::budget::budget_bytes(cli.memory);
    let req =
        DiffRequest { a: cli.a, b: cli.b, heatmaps: cli.heatmaps, min_psnr: cli.min_psnr, memory };
    let report = diff(&req)?;
    if cli.json {
        let s =
            serde_json::to_string_pretty(&report).map_err(|e| Failure::new(Exit::Runtime, e))?;
        println!("{s}");
    } else {
        print!("{}", render(&report));
    }
    Ok(report.exit())
}

fn main() -> ExitCode {
    match cli::parse::<Cli>() {
        Ok(c) => cli::finish("pis-diff", run(c)),
        Err(code) => code,
    }
}
