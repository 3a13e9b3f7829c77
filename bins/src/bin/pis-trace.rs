//! pis-trace: ray-trace a scene over its parameter space into a ray-traced set
//! (format-spec/RAYSET.md).
//!
//! Exit codes: 0 ok, 1 bad arguments, 2 I/O, 3 invalid input file, 4 runtime error.

use anyhow::Context;
use clap::Parser;
use indicatif::{ProgressBar, ProgressStyle};
use pis::cli::{parse_shading_cells, parse_shading_seed};
use pis_scene::lens_tree::LensModel;
use pis_scene::LoadOptions;
use pis_trace::set::{denoise_halves, merge_set, MergeReport, Shard};
use pis_trace::{
    render_shard, DenoiseMode, Progress, SetReport, TraceError, TraceRun, TraceSettings,
};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Ray-trace SCENE.toml at every point of its parameter space into the set directory OUT.
///
/// A trace can be split over processes or machines that share OUT: each runs with
/// `--shard I/N` (points whose index modulo N is I), and the one that finds every point
/// traced writes set.json; `pis-trace merge OUT` does the same on demand. `--resume`
/// continues an interrupted trace from the points it recorded.
#[derive(Parser, Debug)]
#[command(
    name = "pis-trace",
    version,
    about,
    args_conflicts_with_subcommands = true,
    subcommand_negates_reqs = true
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    /// The scene manifest (scene.toml naming a glTF file).
    #[arg(required = true)]
    scene: Option<PathBuf>,
    /// Output directory of the ray-traced set (created if missing).
    #[arg(short, long, required = true)]
    output: Option<PathBuf>,
    /// Render only shard I of N (counted from 0): the points whose linear index modulo N is
    /// I. Shards of one trace share OUT; the last to finish writes set.json.
    #[arg(long, value_name = "I/N")]
    shard: Option<Shard>,
    /// Skip the points an earlier run of the same trace (same scene, settings and points)
    /// recorded in OUT/shards/; a complete set of the same trace is left as it is.
    #[arg(long)]
    resume: bool,
    /// Image size WIDTHxHEIGHT, overriding scene.toml and the preset.
    #[arg(long, value_parser = parse_resolution)]
    resolution: Option<(u32, u32)>,
    /// Camera samples per pixel, overriding scene.toml and the preset: with adaptive
    /// sampling (--noise-threshold above 0) each pixel's most.
    #[arg(long)]
    spp: Option<u32>,
    /// Adaptive sampling: a pixel stops taking samples once its estimated relative error
    /// (two halves of its samples, samples 0 and 3 of every four against 1 and 2, over the
    /// combined image and every object layer the inference reads, on display values) is below
    /// this. 0 turns it off: every pixel takes --spp samples.
    #[arg(long, value_name = "T", default_value_t = 0.0, value_parser = parse_threshold)]
    noise_threshold: f32,
    /// Adaptive sampling: the samples every pixel takes before its error is first estimated
    /// (rounded up to even; then rounds double it up to --spp). The denoiser judges its own
    /// error from halves of the samples a pixel stopped at: from 4, halves of 2 read so noisy
    /// that it keeps most layers raw (measured on five scenes, docs/benchmarks/clean-sets.md).
    #[arg(long, value_name = "N", default_value_t = pis_trace::adaptive::MIN_SPP)]
    min_spp: u32,
    /// Denoise the layers with Open Image Denoise, guided by albedo and normal at the
    /// first non-specular hit; the raw layers stay in the set beside the `denoised.` ones.
    /// `auto`: when the library is found (`pip install pyoidn`, a system OIDN 2.x, or
    /// PIS_OIDN_LIBRARY naming it), else a warning and raw layers only. `on`: an error
    /// without it. `off`: raw layers only.
    #[arg(long, default_value = "auto", value_parser = pis::cli::one_of(&DenoiseMode::ALL, DenoiseMode::name))]
    denoise: DenoiseMode,
    /// A `[preset.NAME]` of scene.toml (e.g. `paper`).
    #[arg(long)]
    preset: Option<String>,
    /// Worker threads (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
    /// Render only the first N parameter points (in linear order, last dimension fastest).
    #[arg(long, value_name = "N")]
    points: Option<usize>,
    /// What seeds the shading's random numbers. `cell` (default): the quantized surface
    /// point, so a surface's noise is the same in every image of the space and the solved
    /// textures agree across it; more samples average more cells, but a cell's own estimate
    /// never improves. `sample`: each camera sample, so the noise falls as 1/spp: for a gold
    /// standard to measure files against, not for a set to pack.
    #[arg(long, value_name = "cell|sample", default_value = "cell", value_parser = parse_shading_seed)]
    shading_seed: pis_trace::ShadingSeed,
    /// With --shading-seed cell: the surface cells across the scene's bounding-box diagonal.
    /// `auto` (default): 4096 for images up to 160 pixels on their longer side, more in
    /// proportion beyond (16384 at 640×480), so that a pixel spans about as many cells, and its
    /// noise stays as much its own, at every size. Recorded in set.json where given.
    #[arg(long, value_name = "auto|N", default_value = "auto", value_parser = parse_shading_cells)]
    shading_cells: pis::cli::ShadingCells,
    /// Stream of the camera samples' random numbers (0 default). Two traces that differ only
    /// in --seed, with --shading-seed sample, have independent noise: their difference
    /// measures it. Recorded in set.json; the shards of one set share it.
    #[arg(long, value_name = "N", default_value_t = 0)]
    seed: u64,
    /// How the paths through lens (refractive) objects are followed and grouped into terms,
    /// for the `reflection`, `refraction` (and `refraction_1`, `refraction_2`) layers and the
    /// ray records. `greedy`: the reflection-first and the refraction-first path, each taking
    /// the larger Fresnel branch at every interface (thesis 6.2). `tree`: both branches at
    /// every interface while a path carries at least --lens-min-weight of the light; the
    /// exit rays grouped into reflection-first and refraction-first with 0, 1, 2 internal
    /// reflections (--lens-terms), the heaviest path of each standing for it.
    #[arg(long, value_name = "greedy|tree", default_value = "greedy", value_parser = ["greedy", "tree"])]
    lens_model: String,
    /// Tree model: the least weight (largest channel of a path's Fresnel × attenuation
    /// product) of a path still followed.
    #[arg(long, value_name = "W", default_value_t = 0.01, value_parser = parse_weight)]
    lens_min_weight: f32,
    /// Tree model: the number of terms, 2 to 4 (reflection-first, refraction-first with no
    /// internal reflection, then with one, then with two).
    #[arg(long, value_name = "N", default_value_t = 4, value_parser = clap::value_parser!(u8).range(2..=4))]
    lens_terms: u8,
    /// Print the closing report as JSON on stdout.
    #[arg(long)]
    json: bool,
}

impl Cli {
    fn lens_model(&self) -> LensModel {
        match self.lens_model.as_str() {
            "tree" => LensModel::Tree {
                min_weight: self.lens_min_weight,
                internal_terms: self.lens_terms - 1,
            },
            _ => LensModel::Greedy,
        }
    }
}

#[derive(clap::Subcommand, Debug)]
enum Command {
    /// Write SET/set.json from the points the shards of a trace recorded (SET/shards/), and
    /// remove the records; an error names the points not traced yet. A complete set is
    /// left as it is.
    Merge {
        /// The set directory the shards wrote.
        set: PathBuf,
        /// Print the report as JSON on stdout.
        #[arg(long)]
        json: bool,
    },
    /// Join two sets rendered elsewhere from independent seeds at the same samples, each
    /// with the denoiser's guides (`guide.albedo`, `guide.normal`), into one set at both
    /// halves' samples with `denoised.` twins (RAYSET.md 5.4): the even and odd halves of
    /// pis-trace's own denoising. Needs Open Image Denoise (see --denoise).
    Denoise {
        /// The first half (its set.json, scene file and ray records are the joined set's).
        even: PathBuf,
        /// The second half: the same points and cameras, other seeds.
        odd: PathBuf,
        /// The joined set's directory (created if missing; not one of the halves).
        #[arg(short, long)]
        output: PathBuf,
        /// Print the report as JSON on stdout.
        #[arg(long)]
        json: bool,
    },
}

fn parse_threshold(s: &str) -> Result<f32, String> {
    match s.trim().parse::<f32>() {
        Ok(t) if t.is_finite() && t >= 0.0 => Ok(t),
        _ => Err(format!("expected a noise threshold of 0 or more (e.g. 0.02), got {s:?}")),
    }
}

fn parse_weight(s: &str) -> Result<f32, String> {
    match s.trim().parse::<f32>() {
        Ok(w) if (0.0..1.0).contains(&w) => Ok(w),
        _ => Err(format!("expected a weight from 0 up to (not including) 1, e.g. 0.01, got {s:?}")),
    }
}

fn parse_resolution(s: &str) -> Result<(u32, u32), String> {
    let (w, h) =
        s.split_once(['x', 'X']).ok_or_else(|| format!("expected WIDTHxHEIGHT, got {s:?}"))?;
    let w: u32 = w.trim().parse().map_err(|_| format!("bad width in {s:?}"))?;
    let h: u32 = h.trim().parse().map_err(|_| format!("bad height in {s:?}"))?;
    if w == 0 || h == 0 {
        return Err(format!("resolution {s:?} has a zero side"));
    }
    Ok((w, h))
}

/// Exit code for an error, by what went wrong (the toolchain's one mapping).
fn exit_code(err: &anyhow::Error) -> u8 {
    pis_pack::exit_of(err, pis_pack::Exit::Runtime) as u8
}

struct Bar(ProgressBar);

impl Progress for Bar {
    fn start(&self, points: usize, rows: u32) {
        self.0.set_length(points as u64 * rows as u64);
    }
    fn point(&self, index: usize, count: usize) {
        self.0.set_message(format!("point {}/{count}", index + 1));
    }
    fn row(&self) {
        self.0.inc(1);
    }
    fn note(&self, text: &str) {
        self.0.suspend(|| eprintln!("pis-trace: warning: {text}"));
    }
}

fn run(cli: &Cli, scene: &Path, output: &Path) -> anyhow::Result<SetReport> {
    let options =
        LoadOptions { preset: cli.preset.clone(), resolution: cli.resolution, spp: cli.spp };
    let scene = pis_scene::load_with(scene, &options).map_err(TraceError::from)?;
    let settings = cli.denoise.apply(
        TraceSettings::new(scene.resolution, scene.spp)
            .with_shading_seed(cli.shading_seed)
            .with_shading_cells(cli.shading_cells.0)
            .with_seed(cli.seed)
            .with_adaptive(cli.noise_threshold, cli.min_spp)
            .with_lens_model(cli.lens_model()),
    )?;
    let bar = ProgressBar::new(0);
    bar.set_style(
        ProgressStyle::with_template(
            "{spinner} {msg} [{bar:40}] {percent}% {elapsed_precise} (eta {eta})",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar())
        .progress_chars("=> "),
    );
    let mut pool = rayon::ThreadPoolBuilder::new();
    if let Some(t) = cli.threads {
        pool = pool.num_threads(t);
    }
    let pool = pool.build().context("starting worker threads")?;
    let progress = Bar(bar);
    let run = TraceRun {
        limit: cli.points,
        shard: cli.shard.unwrap_or(Shard::WHOLE),
        resume: cli.resume,
    };
    let report = pool.install(|| render_shard(&scene, output, &settings, &run, &progress))?;
    progress.0.finish_and_clear();
    Ok(report)
}

fn print_report(r: &SetReport) {
    let mib = r.output_bytes as f64 / (1024.0 * 1024.0);
    eprintln!(
        "pis-trace: {} — {} points traced of the set's {} (the space has {}), {}x{}, {} spp (shading seeded per {}{}), {} threads, {} triangles",
        r.scene, r.points, r.set_points, r.points_in_space, r.resolution[0], r.resolution[1], r.spp, r.shading_seed,
        if r.seed == 0 { String::new() } else { format!(", stream {}", r.seed) }, r.threads, r.triangles
    );
    eprintln!(
        "  rays: {:.2} M camera rays/s, {:.2} M rays/s total ({} camera, {} total)",
        r.camera_rays_per_second / 1e6,
        r.rays_per_second / 1e6,
        r.camera_rays,
        r.total_rays
    );
    if r.noise_threshold > 0.0 {
        eprintln!(
            "  adaptive: {:.1} samples per pixel on average ({} to {}, noise threshold {})",
            r.mean_spp, r.min_spp, r.spp, r.noise_threshold
        );
    }
    match &r.denoiser {
        Some(d) => {
            eprintln!(
                "  denoised: {d}, {:.1} ms per point; {} layers denoised, {} kept raw (denoising estimated to be worse)",
                r.denoise_ms_per_point,
                r.denoised_layers,
                r.kept_raw.len()
            );
            const LISTED: usize = 8;
            for k in r.kept_raw.iter().take(LISTED) {
                eprintln!("    kept raw: {k}");
            }
            if r.kept_raw.len() > LISTED {
                eprintln!("    ... and {} more (--json lists them all)", r.kept_raw.len() - LISTED);
            }
        }
        None => eprintln!("  denoised: no (raw layers only)"),
    }
    eprintln!(
        "  time: {:.1} ms per point ({:.1} ms tracing), {:.2} s in all; output {:.2} MiB",
        r.ms_per_point, r.trace_ms_per_point, r.seconds, mib
    );
    if let Some(shard) = &r.shard {
        eprintln!(
            "  shard {shard}: {} points traced, {} recorded before (--resume)",
            r.points, r.resumed
        );
    } else if r.resumed > 0 {
        eprintln!("  {} points recorded before (--resume)", r.resumed);
    }
    eprintln!(
        "  set: {}",
        if r.complete {
            format!("complete, {} points (set.json written)", r.set_points)
        } else {
            "not complete yet: other shards are to trace the rest (pis-trace merge assembles it)"
                .to_string()
        }
    );
}

fn print_json<T: serde::Serialize>(value: &T) -> ExitCode {
    match serde_json::to_string_pretty(value) {
        Ok(s) => {
            println!("{s}");
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("pis-trace: encoding the report: {e}");
            ExitCode::from(4)
        }
    }
}

fn merge(set: &Path, json: bool) -> ExitCode {
    match merge_set(set) {
        Ok(r) => {
            let MergeReport { points, already_complete, bytes } = &r;
            if *already_complete {
                eprintln!("pis-trace: {}: complete already, {points} points", set.display());
            } else {
                eprintln!(
                    "pis-trace: {}: {points} points merged (set.json, {bytes} bytes)",
                    set.display()
                );
            }
            if json {
                return print_json(&r);
            }
            ExitCode::SUCCESS
        }
        Err(e) => {
            let err = anyhow::Error::from(e);
            eprintln!("pis-trace: {}", pis::cli::message(&err));
            ExitCode::from(exit_code(&err))
        }
    }
}

fn denoise(even: &Path, odd: &Path, out: &Path, json: bool) -> ExitCode {
    let bar = ProgressBar::new(0);
    let progress = |done: usize, points: usize| {
        bar.set_length(points as u64);
        bar.set_position(done as u64);
    };
    match denoise_halves(even, odd, out, &progress) {
        Ok(r) => {
            bar.finish_and_clear();
            eprintln!(
                "pis-trace: {}: {} points joined from {} and {}, {} spp, {:.2} MiB in {:.1} s",
                out.display(),
                r.points,
                even.display(),
                odd.display(),
                r.spp,
                r.output_bytes as f64 / (1024.0 * 1024.0),
                r.seconds
            );
            eprintln!(
                "  denoised: {}; {} layers denoised, {} kept raw (denoising estimated to be worse)",
                r.denoiser,
                r.denoised_layers,
                r.kept_raw.len()
            );
            if json {
                return print_json(&r);
            }
            ExitCode::SUCCESS
        }
        Err(e) => {
            bar.finish_and_clear();
            let err = anyhow::Error::from(e);
            eprintln!("pis-trace: {}", pis::cli::message(&err));
            ExitCode::from(exit_code(&err))
        }
    }
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(c) => c,
        Err(e) => {
            let code = if e.use_stderr() { 1 } else { 0 };
            let _ = e.print();
            return ExitCode::from(code);
        }
    };
    let (scene, output) = match (&cli.command, &cli.scene, &cli.output) {
        (Some(Command::Merge { set, json }), _, _) => return merge(set, *json),
        (Some(Command::Denoise { even, odd, output, json }), _, _) => {
            return denoise(even, odd, output, *json)
        }
        (None, Some(scene), Some(output)) => (scene.clone(), output.clone()),
        _ => {
            eprintln!(
                "pis-trace: give SCENE.toml and -o OUT, `merge SET` or `denoise EVEN ODD -o OUT`"
            );
            return ExitCode::from(1);
        }
    };
    match run(&cli, &scene, &output) {
        Ok(report) => {
            if cli.json {
                return print_json(&report);
            }
            print_report(&report);
            ExitCode::SUCCESS
        }
        Err(err) => {
            eprintln!("pis-trace: {}", pis::cli::message(&err));
            ExitCode::from(exit_code(&err))
        }
    }
}
