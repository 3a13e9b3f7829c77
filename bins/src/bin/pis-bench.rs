//! pis-bench: measurements of the toolchain's stages.
//!
//! `pis-bench infer SET_DIR|scene.toml [--object NAME] [--at v1,v2] [--json]`: texture
//! inference for one object at one parameter point, PSNR against the gold-standard layer for
//! least squares (bilinear, trilinear, pyramidal) and the two baselines (thesis 3.6).
//!
//! `pis-bench rd SET_DIR|scene.toml [--ratios 96,192,384,768] [--out DIR] [--json]`:
//! compression ratio against PSNR for PIS (wavelet, DCT, full pyramid, combined layers) and
//! the baselines (MPEG-texture, view-based x265 and AV1), written as rd.csv and rd.svg.
//! `pis-bench speed`: compile time per point against PSNR across solver iteration caps.
//! `pis-bench stability`: PSNR and popping off the sampled views, against pis-trace.
//! `pis-bench reflective`: packed files played on and off the sampled views, over the
//! reflective objects' pixels, against pis-trace.
//! `pis-bench all --preset ci|paper`: every chart from scratch on demo1.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Args, Parser, Subcommand};
use pis::cli::{finish, parse, parse_shading_seed, Exit, Failure, EXIT_CODES_HELP};
use pis_compile::SolveSettings;
use pis_eval::bench::all::{self, Preset};
use pis_eval::bench::hybrid::{self, HybridRequest};
use pis_eval::bench::rd::{self, RdRequest};
use pis_eval::bench::reference::ReferenceTrace;
use pis_eval::bench::reflective::{self, ReflectiveRequest};
use pis_eval::bench::speed::{self, SpeedRequest};
use pis_eval::bench::stability::{self, StabilityRequest};
use pis_pack::infer::{infer, print_report, InferRequest};

/// The PIS evaluation harness: speed charted against accuracy, PIS against the codecs a user
/// would pick instead. Each chart subcommand writes CSV and SVG into --out (default
/// reports/); `--record` adds a stamped row to docs/benchmarks/bench.md.
#[derive(Parser, Debug)]
#[command(name = "pis-bench", version, after_help = EXIT_CODES_HELP)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

/// How the reference frames are traced beyond their samples per pixel and seeding.
#[derive(Args, Debug)]
struct ReferenceArgs {
    /// Trace every reference twice from independent sample streams (needs --reference-seed
    /// sample): the gold standard is their mean, their difference measures its own noise, and
    /// the report adds each figure with that noise taken out (an estimate of the PSNR against
    /// the converged image).
    #[arg(long)]
    reference_pair: bool,
    /// Trace the reference frames with adaptive sampling: a pixel stops once its estimated
    /// relative error is below T (as pis-trace --noise-threshold); --reference-spp is then
    /// each pixel's most samples. 0: every pixel takes --reference-spp.
    #[arg(long, value_name = "T", default_value_t = 0.0)]
    reference_noise_threshold: f32,
    /// With --reference-noise-threshold: the samples every reference pixel takes first.
    #[arg(long, value_name = "N", default_value_t = 4)]
    reference_min_spp: u32,
    /// Denoise each reference frame's combined image with Open Image Denoise (albedo and
    /// normal guides at the first non-specular hit); refused where the library is not found.
    #[arg(long)]
    reference_denoise: bool,
}

impl ReferenceArgs {
    /// The reference trace at `spp` samples per pixel, shading seeded by `seed`.
    fn trace(&self, spp: u32, seed: pis_trace::ShadingSeed) -> ReferenceTrace {
        ReferenceTrace {
            pair: self.reference_pair,
            noise_threshold: self.reference_noise_threshold,
            min_spp: self.reference_min_spp,
            denoise: self.reference_denoise,
            ..ReferenceTrace::new(spp, seed)
        }
    }
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Texture inference against the gold standard at one parameter point.
    Infer {
        /// A ray-traced set directory, or a scene.toml to trace the point from.
        input: PathBuf,
        /// The object (default: the most specular one).
        #[arg(long)]
        object: Option<String>,
        /// Parameter values, one per dimension (nearest sample); default: the middle sample.
        #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
        at: Option<Vec<f32>>,
        /// scene.toml of a set (default: the scene.toml set.json records, else SET_DIR/scene.toml).
        #[arg(long)]
        scene: Option<PathBuf>,
        /// Image size WIDTHxHEIGHT when tracing a scene.toml.
        #[arg(long, value_parser = parse_resolution)]
        resolution: Option<(u32, u32)>,
        /// Samples per pixel when tracing a scene.toml.
        #[arg(long)]
        spp: Option<u32>,
        /// A `[preset.NAME]` of scene.toml.
        #[arg(long)]
        preset: Option<String>,
        /// Also time the inference of every object of the scene at this point.
        #[arg(long)]
        all_objects: bool,
        /// Largest used texture side in texels.
        #[arg(long, default_value_t = 1024)]
        max_texture: u32,
        /// ε_f of the pyramidal regularization (thesis: 0.1).
        #[arg(long, default_value_t = 0.1)]
        epsilon_f: f64,
        /// ε_b of the range regularization (eq. 3.8) of the plain LS solves (0: none, the
        /// default; the thesis used 1/32). With ε_b > 0 the report adds
        /// `ls-trilinear-unconstrained`.
        #[arg(long, default_value_t = 0.0)]
        epsilon_b: f64,
        /// ε_b of the pyramidal solve (thesis: 0, the pyramidal term alone).
        #[arg(long, default_value_t = 0.0)]
        pyramidal_epsilon_b: f64,
        /// Conjugate-gradient stopping tolerance (relative preconditioned gradient norm).
        #[arg(long, default_value_t = 1e-4)]
        tolerance: f64,
        /// Conjugate-gradient iteration limit per colour channel.
        #[arg(long, default_value_t = 400)]
        max_iterations: u32,
        /// Inference with antialiasing (thesis 3.4.4): A at N× the resolution, filtered with
        /// the set's display filter (1: pixel centres only).
        #[arg(long, default_value_t = 1)]
        antialias: u32,
        /// Also draw every texture at the neighbouring view sample and report its PSNR there.
        #[arg(long)]
        neighbour: bool,
        /// Per-object texture resolution reduction factor (thesis 3.2; 1: optimal).
        #[arg(long, default_value_t = 1.0)]
        reduction: f64,
        /// Texel budget: at most K level-0 texels per covered pixel, as `pis-pack
        /// --texels-per-pixel` (default: none, the optimal resolution).
        #[arg(long)]
        texels_per_pixel: Option<f64>,
        /// Skip the renders through wgpu (pis-play); psnr_db_wgpu is then null.
        #[arg(long)]
        no_wgpu: bool,
        /// Print the report as JSON on stdout.
        #[arg(long)]
        json: bool,
    },
    /// Compression ratio against PSNR: PIS and the baselines at matched byte budgets
    /// (writes rd.csv and rd.svg into --out).
    Rd {
        /// A ray-traced set directory, or a scene.toml to trace first (as pis-pack does).
        input: PathBuf,
        /// scene.toml of a set (default: the scene.toml set.json records, else SET_DIR/scene.toml).
        #[arg(long)]
        scene: Option<PathBuf>,
        /// Target compression ratios: every method gets raw image bytes / ratio bytes.
        #[arg(long, value_delimiter = ',', default_value = "96,192,384,768")]
        ratios: Vec<f64>,
        /// Output folder for rd.csv and rd.svg (created when missing).
        #[arg(long, default_value = "reports")]
        out: PathBuf,
        /// Image size WIDTHxHEIGHT when tracing a scene.toml.
        #[arg(long, value_parser = parse_resolution)]
        resolution: Option<(u32, u32)>,
        /// Samples per pixel when tracing a scene.toml.
        #[arg(long)]
        spp: Option<u32>,
        /// Largest used texture side of the PIS inference.
        #[arg(long, default_value_t = pis_pack::DEFAULT_MAX_TEXTURE)]
        max_texture: u32,
        /// A `[preset.NAME]` of scene.toml when tracing one.
        #[arg(long)]
        preset: Option<String>,
        /// Only these methods (comma-separated; default all): pis-wavelet, pis-dct,
        /// pis-wavelet-full-pyramid, pis-wavelet-combined-layers, mpeg-texture-x265,
        /// view-x265, view-av1.
        #[arg(long, value_delimiter = ',')]
        methods: Vec<String>,
        /// The PIS packs' max-MSE constraint, as pis-pack's --max-mse-ratio: `auto` (the
        /// better prediction of the constraint at 1.25 and the free allocation), `off`, or
        /// the constraint at ALPHA.
        #[arg(long, value_name = "auto|off|ALPHA", default_value = "auto")]
        max_mse_ratio: pis_pack::MaxMse,
        /// The PIS packs' block staggering, as pis-pack's --stagger: `auto` (the dimensions
        /// with more samples than a block) or `always` (every dimension).
        #[arg(long, value_name = "auto|always", default_value = "auto", value_parser = pis::cli::one_of(&pis_pack::Stagger::ALL, pis_pack::Stagger::name))]
        stagger: pis_pack::Stagger,
        /// Record the run (machine, scene, command, PSNR near 384:1) in
        /// docs/benchmarks/bench.md.
        #[arg(long)]
        record: bool,
        /// Print the report as JSON on stdout.
        #[arg(long)]
        json: bool,
    },
    /// Compile (inference) time per parameter point against PSNR across solver iteration
    /// caps, and playback frame times against PSNR across texture reductions and codecs
    /// (writes speed.csv and speed.svg into --out).
    Speed {
        /// A ray-traced set directory, or a scene.toml to trace first.
        input: PathBuf,
        #[arg(long)]
        scene: Option<PathBuf>,
        /// Conjugate-gradient iteration caps per colour channel.
        #[arg(long, value_delimiter = ',', default_value = "10,50,400")]
        caps: Vec<u32>,
        /// Compression ratio of the packs whose PSNR is reported.
        #[arg(long, default_value_t = 384.0)]
        ratio: f64,
        #[arg(long, default_value = "reports")]
        out: PathBuf,
        #[arg(long, value_parser = parse_resolution)]
        resolution: Option<(u32, u32)>,
        #[arg(long)]
        spp: Option<u32>,
        #[arg(long)]
        preset: Option<String>,
        #[arg(long, default_value_t = pis_pack::DEFAULT_MAX_TEXTURE)]
        max_texture: u32,
        /// Record the run in docs/benchmarks/bench.md.
        #[arg(long)]
        record: bool,
        #[arg(long)]
        json: bool,
    },
    /// PSNR and popping along dense camera paths between and away from the sampled views,
    /// against frames ray-traced at each exact camera (writes stability.csv and .svg).
    Stability {
        /// A ray-traced set directory, or a scene.toml to trace first.
        input: PathBuf,
        #[arg(long)]
        scene: Option<PathBuf>,
        /// Ratios of the coded representations (the textures as solved are always shown).
        #[arg(long, value_delimiter = ',', default_value = "96,384,2000")]
        ratios: Vec<f64>,
        /// Frames per path.
        #[arg(long, default_value_t = 17)]
        frames: usize,
        /// Samples per pixel of the ray-traced reference frames.
        #[arg(long, default_value_t = 4)]
        reference_spp: u32,
        /// What seeds the reference frames' shading: `cell`, as in a packed set (its noise
        /// stays on the surfaces however many samples), or `sample` (the noise falls as
        /// 1/spp: a gold standard).
        #[arg(long, value_name = "cell|sample", default_value = "cell", value_parser = parse_shading_seed)]
        reference_seed: pis_trace::ShadingSeed,
        #[command(flatten)]
        reference: ReferenceArgs,
        #[arg(long, default_value = "reports")]
        out: PathBuf,
        #[arg(long, value_parser = parse_resolution)]
        resolution: Option<(u32, u32)>,
        /// Samples per pixel when tracing a scene.toml.
        #[arg(long)]
        spp: Option<u32>,
        #[arg(long)]
        preset: Option<String>,
        #[arg(long, default_value_t = pis_pack::DEFAULT_MAX_TEXTURE)]
        max_texture: u32,
        /// Record the run in docs/benchmarks/bench.md.
        #[arg(long)]
        record: bool,
        #[arg(long)]
        json: bool,
    },
    /// Reflective objects as the player draws them: each packed file played at the sampled
    /// views and along dense camera paths between and away from them, against frames
    /// ray-traced at each exact camera, over the reflective objects' pixels (with --role
    /// refractive, the lens objects'; writes reflective.csv).
    Reflective {
        /// The scene.toml the files were packed from.
        scene: PathBuf,
        /// The packed files to compare (e.g. packed with --representation texture and pem).
        #[arg(required = true)]
        files: Vec<PathBuf>,
        /// Frames on the between and away paths (the samples path has one per sampled view).
        #[arg(long, default_value_t = 9)]
        frames: usize,
        /// Samples per pixel of the ray-traced reference frames.
        #[arg(long, default_value_t = 16)]
        reference_spp: u32,
        /// What seeds the reference frames' shading: `cell`, as in a packed set (its noise
        /// stays on the surfaces however many samples), or `sample` (the noise falls as
        /// 1/spp: a gold standard).
        #[arg(long, value_name = "cell|sample", default_value = "cell", value_parser = parse_shading_seed)]
        reference_seed: pis_trace::ShadingSeed,
        #[command(flatten)]
        reference: ReferenceArgs,
        #[arg(long, default_value = "reports")]
        out: PathBuf,
        #[arg(long, value_parser = parse_resolution)]
        resolution: Option<(u32, u32)>,
        #[arg(long)]
        preset: Option<String>,
        /// Also write every played frame beside its traced reference (PNG) into --out.
        #[arg(long)]
        images: bool,
        /// The objects measured: `reflective` or `refractive` (the lens objects, drawn by
        /// hybrid rendering).
        #[arg(long, default_value = "reflective", value_parser = pis::cli::one_of(&reflective::ROLES, reflective::role_name))]
        role: pis_scene::ObjectRole,
        /// The player's τ for lens objects (pis-play --tau), pixels.
        #[arg(long, default_value_t = 1.0)]
        tau: f32,
        /// March depth shells in N coarse steps (1 to 64) instead of the files' (pis-play
        /// --depth-steps): what the step count costs on and off the sampled views.
        #[arg(long, value_name = "N", value_parser = pis::cli::parse_depth_steps)]
        depth_steps: Option<u32>,
        #[arg(long)]
        json: bool,
    },
    /// Hybrid rendering's per-frame CPU work on a scene's lens objects (thesis 6.4, table
    /// 6.1): per τ, the vertex rays of the greedy two-path model, the adaptive tessellation,
    /// the milliseconds for tracing, tessellating and cube-vector generation, against the
    /// same model traced at every pixel, along the camera path between the sampled views.
    Hybrid {
        /// The scene.toml (its refractive objects are measured).
        scene: PathBuf,
        /// τ values: the screen edge length in pixels below which triangles are not split.
        #[arg(long, value_delimiter = ',', default_value = "1,3,5,10")]
        tau: Vec<f32>,
        /// Frames on the path between the sampled views.
        #[arg(long, default_value_t = 9)]
        frames: usize,
        #[arg(long, value_parser = parse_resolution)]
        resolution: Option<(u32, u32)>,
        #[arg(long)]
        preset: Option<String>,
        /// A file packed from the scene (its lens objects by hybrid rendering: pis-pack
        /// --representation pem): also played at each τ on the same cameras, for the
        /// player's whole frame (lens objects' CPU work, draw, frame).
        #[arg(long, value_name = "FILE.pis")]
        file: Option<PathBuf>,
        /// Samples per pixel of the played frames (--file), as pis-play --msaa.
        #[arg(long, default_value_t = pis_play::multisample::DEFAULT_SAMPLES, value_name = "1|4")]
        msaa: u32,
        /// Where the vertex rays are traced, in the tessellation table and the played frames:
        /// as pis-play --lens-rays (`auto`: on the GPU where the adapter is one).
        #[arg(long, default_value = "auto", value_parser = pis::cli::one_of(&pis_play::LensRays::ALL, pis_play::LensRays::name))]
        lens_rays: pis_play::LensRays,
        #[arg(long)]
        json: bool,
    },
    /// Relighting (Wong et al.): packed files played under the lights of a set traced with
    /// lights they do not hold, against it, whole image: a relightable file relit by
    /// superposition (the light from another direction, several coloured directional
    /// lights, the scene's sky), a file that samples the light at its sampled direction
    /// nearest each held-out one. With --fitted, first the ceiling of the spherical
    /// harmonics themselves: that set's pixels fitted per band and drawn under those lights.
    Relight {
        /// The packed files (e.g. with pis-pack --relight on and off).
        #[arg(required = true)]
        files: Vec<PathBuf>,
        /// The set traced under held-out lights, its other dimensions as the files': the
        /// same `light_direction` dimension with another sample count, or a scene of
        /// directional lights and an `[environment]` without that dimension (where the files'
        /// light was a placed point or sphere light: that light placed from other directions,
        /// in any colours, with --fitted).
        #[arg(long, value_name = "SET_DIR")]
        held: PathBuf,
        /// The set the files were packed from: the per-pixel fit's ceiling per band, and
        /// where its light was placed (centre + distance · ω), so that the held-out set's
        /// placed lights are read as that light from their directions.
        #[arg(long, value_name = "SET_DIR")]
        fitted: Option<PathBuf>,
        /// Bands of the ceiling.
        #[arg(long, value_delimiter = ',', default_value = "1,2,3,4,5,6")]
        bands: Vec<u32>,
        #[arg(long)]
        json: bool,
    },
    /// Every chart (rd, speed, stability) from scratch on demo1: trace, pack, evaluate.
    All {
        /// `ci` (80×60, 1 spp: minutes on 2 cores) or `paper` (demo1's paper preset).
        #[arg(long, value_parser = pis::cli::one_of(&Preset::ALL, Preset::name))]
        preset: Preset,
        /// demo1's scene.toml (default: samples/demo1/scene.toml of the source tree).
        #[arg(long)]
        scene: Option<PathBuf>,
        #[arg(long, default_value = "reports")]
        out: PathBuf,
        /// Record every run in docs/benchmarks/bench.md.
        #[arg(long)]
        record: bool,
    },
}

fn json_out<T: serde::Serialize>(v: &T) -> Result<(), Failure> {
    let s = serde_json::to_string_pretty(v).map_err(|e| Failure::new(Exit::Runtime, e))?;
    println!("{s}");
    Ok(())
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

fn run(cli: Cli) -> Result<Exit, Failure> {
    match cli.command {
        Command::Infer {
            input,
            object,
            at,
            scene,
            resolution,
            spp,
            preset,
            all_objects,
            max_texture,
            epsilon_f,
            epsilon_b,
            pyramidal_epsilon_b,
            tolerance,
            max_iterations,
            antialias,
            neighbour,
            reduction,
            texels_per_pixel,
            no_wgpu,
            json,
        } => {
            if !input.exists() {
                return Err(Failure::new(
                    Exit::Io,
                    anyhow::anyhow!("{} does not exist", input.display()),
                ));
            }
            if max_texture == 0 || max_texture > 16384 {
                return Err(Failure::new(
                    Exit::Usage,
                    anyhow::anyhow!("--max-texture must be in 1..=16384"),
                ));
            }
            if !(epsilon_f.is_finite()
                && epsilon_f >= 0.0
                && tolerance.is_finite()
                && tolerance > 0.0)
            {
                return Err(Failure::new(
                    Exit::Usage,
                    anyhow::anyhow!("--epsilon-f must be ≥ 0 and --tolerance > 0"),
                ));
            }
            if antialias == 0 || antialias > 16 || !(reduction.is_finite() && reduction > 0.0) {
                return Err(Failure::new(
                    Exit::Usage,
                    anyhow::anyhow!("--antialias must be in 1..=16 and --reduction > 0"),
                ));
            }
            if texels_per_pixel.is_some_and(|k| !(k.is_finite() && k > 0.0)) {
                return Err(Failure::new(
                    Exit::Usage,
                    anyhow::anyhow!("--texels-per-pixel must be > 0"),
                ));
            }
            if !(epsilon_b.is_finite()
                && epsilon_b >= 0.0
                && pyramidal_epsilon_b.is_finite()
                && pyramidal_epsilon_b >= 0.0)
            {
                return Err(Failure::new(
                    Exit::Usage,
                    anyhow::anyhow!("--epsilon-b and --pyramidal-epsilon-b must be ≥ 0"),
                ));
            }
            let mut solver = SolveSettings { epsilon_b, ..SolveSettings::default() };
            solver.cg.tolerance = tolerance;
            solver.cg.max_iterations = max_iterations;
            let req = InferRequest {
                input,
                scene,
                object,
                at,
                resolution,
                spp,
                preset,
                all_objects,
                max_texture,
                solver,
                epsilon_f,
                pyramidal_epsilon_b,
                wgpu: !no_wgpu,
                antialias,
                neighbour,
                reduction,
                texels_per_pixel,
            };
            let report = infer(&req).map_err(|e| Failure::new(Exit::Runtime, e))?;
            print_report(&report, &mut std::io::stderr()).map_err(|e| Failure::new(Exit::Io, e))?;
            if json {
                let s = serde_json::to_string_pretty(&report)
                    .map_err(|e| Failure::new(Exit::Runtime, e))?;
                println!("{s}");
            }
            Ok(Exit::Ok)
        }
        Command::Rd {
            input,
            scene,
            ratios,
            out,
            resolution,
            spp,
            max_texture,
            preset,
            methods,
            max_mse_ratio,
            stagger,
            record,
            json,
        } => {
            let req = RdRequest {
                input,
                scene,
                ratios,
                out,
                resolution,
                spp,
                max_texture,
                preset,
                record,
                methods,
                max_mse: max_mse_ratio,
                stagger,
            };
            let report = rd::run(&req)?;
            rd::print(&report, &mut std::io::stderr()).map_err(|e| Failure::new(Exit::Io, e))?;
            if json {
                json_out(&report)?;
            }
            Ok(Exit::Ok)
        }
        Command::Speed {
            input,
            scene,
            caps,
            ratio,
            out,
            resolution,
            spp,
            preset,
            max_texture,
            record,
            json,
        } => {
            let req = SpeedRequest {
                input,
                scene,
                caps,
                ratio,
                out,
                resolution,
                spp,
                preset,
                max_texture,
                record,
            };
            let report = speed::run(&req)?;
            speed::print(&report, &mut std::io::stderr()).map_err(|e| Failure::new(Exit::Io, e))?;
            if json {
                json_out(&report)?;
            }
            Ok(Exit::Ok)
        }
        Command::Stability {
            input,
            scene,
            ratios,
            frames,
            reference_spp,
            reference_seed,
            reference,
            out,
            resolution,
            spp,
            preset,
            max_texture,
            record,
            json,
        } => {
            let req = StabilityRequest {
                reference: reference.trace(reference_spp, reference_seed),
                input,
                scene,
                ratios,
                frames,
                out,
                resolution,
                trace_spp: spp,
                max_texture,
                preset,
                record,
            };
            let report = stability::run(&req)?;
            stability::print(&report, &mut std::io::stderr())
                .map_err(|e| Failure::new(Exit::Io, e))?;
            if json {
                json_out(&report)?;
            }
            Ok(Exit::Ok)
        }
        Command::Reflective {
            scene,
            files,
            frames,
            reference_spp,
            reference_seed,
            reference,
            out,
            resolution,
            preset,
            images,
            role,
            tau,
            depth_steps,
            json,
        } => {
            let req = ReflectiveRequest {
                scene,
                preset,
                resolution,
                files,
                frames,
                reference: reference.trace(reference_spp, reference_seed),
                out,
                images,
                role,
                tau_px: tau,
                depth_steps,
            };
            let report = reflective::run(&req)?;
            reflective::print(&report, &mut std::io::stderr())
                .map_err(|e| Failure::new(Exit::Io, e))?;
            if json {
                json_out(&report)?;
            }
            Ok(Exit::Ok)
        }
        Command::Hybrid { scene, tau, frames, resolution, preset, file, msaa, lens_rays, json } => {
            let report = hybrid::run(&HybridRequest {
                scene,
                preset,
                resolution,
                taus: tau,
                frames,
                file,
                msaa,
                lens_rays,
            })?;
            hybrid::print(&report, &mut std::io::stderr())
                .map_err(|e| Failure::new(Exit::Io, e))?;
            if json {
                json_out(&report)?;
            }
            Ok(Exit::Ok)
        }
        Command::Relight { files, held, fitted, bands, json } => {
            if bands.iter().any(|&b| b > pis_compile::relight::MAX_BAND) {
                return Err(Failure::new(
                    Exit::Usage,
                    anyhow::anyhow!("--bands: at most {}", pis_compile::relight::MAX_BAND),
                ));
            }
            let report = pis_eval::relight::judge(&files, &held, fitted.as_deref(), &bands)
                .map_err(|e| Failure::new(Exit::Runtime, e))?;
            eprint!("{}", pis_eval::relight::render(&report));
            if json {
                json_out(&report)?;
            }
            Ok(Exit::Ok)
        }
        Command::All { preset, scene, out, record } => {
            all::run(preset, &scene.unwrap_or_else(all::demo1), &out, record)?;
            Ok(Exit::Ok)
        }
    }
}

fn main() -> ExitCode {
    let cli = match parse::<Cli>() {
        Ok(c) => c,
        Err(code) => return code,
    };
    finish("pis-bench", run(cli))
}
