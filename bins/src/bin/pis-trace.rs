//! pis-trace: ray-trace a scene over its parameter space into a ray-traced set
//! (format-spec/RAYSET.md).
//!
//! Exit codes: 0 ok, 1 bad arguments, 2 I/O, 3 invalid input file, 4 runtime error.

use anyhow::Context;
use clap::Parser;
use indicatif::{ProgressBar, ProgressStyle};
use pis_scene::LoadOptions;
use pis_trace::{render_set, Progress, SetReport, TraceError, TraceSettings};
use std::path::PathBuf;
use std::process::ExitCode;

/// Ray-trace SCENE.toml at every point of its parameter space into the set directory OUT.
#[derive(Parser, Debug)]
#[command(name = "pis-trace", version, about)]
struct Cli {
    /// The scene manifest (scene.toml naming a glTF file).
    scene: PathBuf,
    /// Output directory of the ray-traced set (created if missing).
    #[arg(short, long)]
    output: PathBuf,
    /// Image size WIDTHxHEIGHT, overriding scene.toml and the preset.
    #[arg(long, value_parser = parse_resolution)]
    resolution: Option<(u32, u32)>,
    /// Camera samples per pixel, overriding scene.toml and the preset.
    #[arg(long)]
    spp: Option<u32>,
    /// A `[preset.NAME]` of scene.toml (e.g. `paper`).
    #[arg(long)]
    preset: Option<String>,
    /// Worker threads (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
    /// Render only the first N parameter points (in linear order, last dimension fastest).
    #[arg(long, value_name = "N")]
    points: Option<usize>,
    /// Print the closing report as JSON on stdout.
    #[arg(long)]
    json: bool,
}

fn parse_resolution(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(|| format!("expected WIDTHxHEIGHT, got {s:?}"))?;
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

fn run(cli: &Cli) -> anyhow::Result<SetReport> {
    let options = LoadOptions { preset: cli.preset.clone(), resolution: cli.resolution, spp: cli.spp };
    let scene = pis_scene::load_with(&cli.scene, &options).map_err(TraceError::from)?;
    let settings = TraceSettings::new(scene.resolution, scene.spp);
    let points = cli.points.map_or(scene.space.point_count(), |n| n.min(scene.space.point_count()));
    let bar = ProgressBar::new(points as u64 * scene.resolution.1 as u64);
    bar.set_style(
        ProgressStyle::with_template("{spinner} {msg} [{bar:40}] {percent}% {elapsed_precise} (eta {eta})")
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> "),
    );
    let mut pool = rayon::ThreadPoolBuilder::new();
    if let Some(t) = cli.threads {
        pool = pool.num_threads(t);
    }
    let pool = pool.build().context("starting worker threads")?;
    let progress = Bar(bar);
    let report = pool.install(|| render_set(&scene, &cli.output, &settings, cli.points, &progress))?;
    progress.0.finish_and_clear();
    Ok(report)
}

fn print_report(r: &SetReport) {
    let mib = r.output_bytes as f64 / (1024.0 * 1024.0);
    eprintln!(
        "pis-trace: {} — {} of {} points, {}x{}, {} spp, {} threads, {} triangles",
        r.scene, r.points, r.points_in_space, r.resolution[0], r.resolution[1], r.spp, r.threads, r.triangles
    );
    eprintln!(
        "  rays: {:.2} M camera rays/s, {:.2} M rays/s total ({} camera, {} total)",
        r.camera_rays_per_second / 1e6,
        r.rays_per_second / 1e6,
        r.camera_rays,
        r.total_rays
    );
    eprintln!(
        "  time: {:.1} ms per point ({:.1} ms tracing), {:.2} s in all; output {:.2} MiB",
        r.ms_per_point, r.trace_ms_per_point, r.seconds, mib
    );
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
    match run(&cli) {
        Ok(report) => {
            if cli.json {
                match serde_json::to_string_pretty(&report) {
                    Ok(s) => println!("{s}"),
                    Err(e) => {
                        eprintln!("pis-trace: encoding the report: {e}");
                        return ExitCode::from(4);
                    }
                }
            } else {
                print_report(&report);
            }
            ExitCode::SUCCESS
        }
        Err(err) => {
            eprintln!("pis-trace: {}", pis::cli::message(&err));
            ExitCode::from(exit_code(&err))
        }
    }
}
