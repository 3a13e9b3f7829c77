//! pis-play without a window: frames drawn offscreen, written as sRGB PNGs, timed; or every
//! sample point of a set compared with the gold standard.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::compare::{compare_with_set, CompareOptions, Comparison};
use anyhow::{anyhow, Context};
use pis_play::{CameraChoice, FrameRequest, FrameStats, Gpu, PlayError, Player, ViewCamera};
use serde::Serialize;

use pis_pack::{Exit, Failure};

/// The camera and parameter path of a headless run.
#[derive(Clone, Debug, PartialEq)]
pub enum PathChoice {
    /// A new parameter sample every frame along the diagonal of the space (thesis table
    /// 4.2), wrapping onto shifted diagonals once one is done; the file's camera at each.
    Diagonal,
    /// A free camera circling the scene around the sample camera's target, the parameter
    /// point fixed (`--at`).
    Orbit,
    /// A file with one parameter point per line (values separated by commas or spaces; `#`
    /// starts a comment); the file's camera at each.
    File(PathBuf),
}

pub fn parse_path(s: &str) -> Result<PathChoice, String> {
    Ok(match s {
        "diagonal" => PathChoice::Diagonal,
        "orbit" => PathChoice::Orbit,
        f => PathChoice::File(PathBuf::from(f)),
    })
}

/// What a headless run draws: one frame, a path of frames, or (with [`run_compare`]) every
/// sample point of a set.
#[derive(Clone, Debug)]
pub struct HeadlessRequest {
    /// The container to play.
    pub file: PathBuf,
    /// The parameter point (default: the middle sample of each dimension).
    pub at: Option<Vec<f32>>,
    /// A path of frames instead of one.
    pub path: Option<PathChoice>,
    /// Frames of the path (default: every point for `Diagonal`, 36 for `Orbit`, every line
    /// of a path file).
    pub frames: Option<usize>,
    /// Write every frame as an 8-bit sRGB PNG into this folder.
    pub out: Option<PathBuf>,
    /// Frame size (default: the file's image size).
    pub size: Option<(u32, u32)>,
    /// No progress lines on stderr.
    pub quiet: bool,
    /// Along a path: how many of the next frames' points the player is told of, to decode
    /// their textures ahead while a frame draws (0: none).
    pub prefetch: usize,
    /// The player's settings.
    pub options: pis_play::PlayerOptions,
}

/// The display filter of the ray-traced set at `dir` (`set.json` `filter`, RAYSET.md section
/// 4), which the player resolves multisampled frames with when the file records none; `None`
/// where the set cannot be read (the comparison then says why) or records an invalid one.
pub fn set_display_filter(dir: &std::path::Path) -> Option<pis_format::DisplayFilter> {
    let f = pis_trace::set::RaySet::open(dir).ok()?.meta.filter;
    pis_format::DisplayFilter::new(f.sigma_px, f.radius_px).ok()
}

/// The exit code of a player error, the one table every tool that plays uses: a request
/// that does not fit the file is a usage error, a file the player cannot draw is invalid,
/// what this machine cannot do (no adapter, a texture or render target beyond its limits,
/// textures beyond the cache budget or the adapter's largest buffer) is not supported, and
/// the rest is a runtime error.
pub fn play_exit(e: &PlayError) -> Exit {
    match e {
        PlayError::File(f) => pis_pack::format_exit(f),
        PlayError::Request(_) => Exit::Usage,
        PlayError::Content { .. } | PlayError::RepeatSize { .. } => Exit::Invalid,
        PlayError::NoAdapter(_)
        | PlayError::TextureSize { .. }
        | PlayError::TargetSize { .. }
        | PlayError::Memory(_) => Exit::NotSupported,
        _ => Exit::Runtime,
    }
}

/// A player error as a failure with its exit code ([`play_exit`]).
pub fn play_failure(e: PlayError) -> Failure {
    Failure::new(play_exit(&e), e)
}

/// Timings of a run of frames.
#[derive(Clone, Debug, Serialize)]
pub struct PathReport {
    pub file: String,
    pub adapter: String,
    pub textures: TextureFormats,
    pub size: [u32; 2],
    pub blend: String,
    pub reduction: u32,
    /// Samples per pixel drawn with (multisample antialiasing; 1: none).
    pub msaa_samples: u32,
    /// Samples per pixel asked for (`--msaa`).
    pub msaa_requested: u32,
    /// How multisampled frames are resolved.
    pub resolve: Resolve,
    pub workers: usize,
    /// Where textures were rebuilt from their level images: `gpu` or `workers`.
    pub rebuild: &'static str,
    /// Where lens objects' vertex rays were traced: `gpu` or `workers`.
    pub lens_rays: &'static str,
    /// Frames ahead whose textures were decoded while a frame drew (`--prefetch`).
    pub prefetch: usize,
    pub frames: usize,
    /// Frames that waited on decoding: a level image decoded when the frame asked for it,
    /// or still being decoded ahead.
    pub frames_waited: usize,
    /// Level images found decoded ahead, and dropped from decoding ahead because the
    /// prediction changed before they started.
    pub prefetched: u64,
    pub prefetch_dropped: u64,
    /// Textures found rebuilt ahead on the workers.
    pub rebuilt_ahead: u64,
    pub frame_ms_mean: f64,
    pub frame_ms_worst: f64,
    pub fps_mean: f64,
    pub fps_worst: f64,
    pub decode_ms_mean: f64,
    pub decode_ms_worst: f64,
    pub upload_ms_mean: f64,
    pub upload_ms_worst: f64,
    pub upload_bytes_mean: f64,
    /// The GPU's rebuilds of textures from their level images (0 on the workers).
    pub rebuild_ms_mean: f64,
    pub rebuild_ms_worst: f64,
    /// Recording the draws and waiting for the GPU to finish them.
    pub draw_ms_mean: f64,
    pub draw_ms_worst: f64,
    /// Copying each frame to memory: 0 unless the frames are written (`--out`).
    pub readback_ms_mean: f64,
    /// Draws per frame of surface layers (object × layer × parameter sample).
    pub surface_draws_mean: f64,
    /// Draws per frame of reflection terms (object × parameter sample, each looking up the
    /// term's environment-map shells).
    pub shell_draws_mean: f64,
    /// Lens objects (hybrid rendering): ms per frame tracing their vertex rays, refining the
    /// tessellation and building the terms' vertex buffers; rays, triangles and draws of
    /// lens terms per frame.
    pub lens_ms_mean: f64,
    pub lens_ms_worst: f64,
    pub lens_rays_mean: f64,
    pub lens_triangles_mean: f64,
    pub lens_draws_mean: f64,
    /// Lens objects' tessellations found made ahead, and dropped because the prediction
    /// changed.
    pub lens_traced_ahead: u64,
    pub lens_ahead_dropped: u64,
    pub cache_hits: u64,
    pub cache_misses: u64,
    pub cache_bytes_max: u64,
    pub codestreams_read: u64,
    /// Per frame: the parameter point and its timings.
    pub per_frame: Vec<FrameRow>,
}

#[derive(Clone, Debug, Serialize)]
pub struct FrameRow {
    pub point: Vec<f32>,
    pub frame_ms: f64,
    pub decode_ms: f64,
    pub upload_ms: f64,
    pub rebuild_ms: f64,
    pub draw_ms: f64,
    pub readback_ms: f64,
    pub codestreams_read: u64,
    /// Level images the frame waited for, and found decoded ahead.
    pub decode_waits: u64,
    pub prefetched: u64,
    pub surface_draws: u64,
    pub shell_draws: u64,
    pub lens_ms: f64,
    pub lens_rays: u64,
}

#[derive(Clone, Debug, Serialize)]
pub struct BlockRow {
    pub block: usize,
    pub psnr_db: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct ObjectRow {
    pub name: String,
    pub psnr_db: f64,
    pub pixels: u64,
    pub blocks: Vec<BlockRow>,
}

#[derive(Clone, Debug, Serialize)]
pub struct PointRow {
    pub index: usize,
    pub point: Vec<f32>,
    pub psnr_db: f64,
}

/// PSNR against the gold standard.
#[derive(Clone, Debug, Serialize)]
pub struct CompareReport {
    pub file: String,
    pub set: String,
    pub adapter: String,
    pub textures: TextureFormats,
    pub blend: String,
    pub reduction: u32,
    /// Samples per pixel drawn with (multisample antialiasing; 1: none).
    pub msaa_samples: u32,
    /// Samples per pixel asked for (`--msaa`).
    pub msaa_requested: u32,
    /// How multisampled frames are resolved.
    pub resolve: Resolve,
    /// Whole image, every point.
    pub psnr_db: f64,
    /// Every object's covered pixels pooled (pis-pack's predicted `psnr_db` measure).
    pub covered_psnr_db: f64,
    /// The whole image at the gold standard's silhouette pixels (some object partly covers
    /// them) and elsewhere, with the silhouette pixels' share of the image.
    pub silhouette_psnr_db: f64,
    pub interior_psnr_db: f64,
    pub silhouette_fraction: f64,
    pub objects: Vec<ObjectRow>,
    pub points: Vec<PointRow>,
}

/// How a player resolves multisampled frames: `filter` `box` (each pixel's own samples
/// averaged), `gaussian` (the display-filter resolve, with `sigma_px`, `radius_px` and
/// `from`: `file`, the file's provenance settings, or `set`, the ray-traced set's filter
/// where the file records none), or `none` (one sample per pixel).
#[derive(Clone, Debug, Serialize)]
pub struct Resolve {
    pub filter: String,
    pub sigma_px: Option<f32>,
    pub radius_px: Option<f32>,
    pub from: Option<String>,
}

impl Resolve {
    pub fn of(player: &Player) -> Resolve {
        match player.display_filter() {
            _ if player.multisample().samples <= 1 => {
                Resolve { filter: "none".into(), sigma_px: None, radius_px: None, from: None }
            }
            None => Resolve { filter: "box".into(), sigma_px: None, radius_px: None, from: None },
            Some((f, file)) => Resolve {
                filter: "gaussian".into(),
                sigma_px: Some(f.sigma_px),
                radius_px: Some(f.radius_px),
                from: Some(if file { "file" } else { "set" }.into()),
            },
        }
    }

    /// "", ", box resolve", or ", Gaussian resolve σ 0.5 px R 1.5 px (the set's: the file
    /// records none)".
    pub fn label(&self) -> String {
        match (self.filter.as_str(), self.sigma_px, self.radius_px) {
            ("gaussian", Some(s), Some(r)) => {
                let from = if self.from.as_deref() == Some("file") {
                    "the file's"
                } else {
                    "the set's: the file records none"
                };
                format!(", Gaussian resolve σ {s} px R {r} px ({from})")
            }
            ("box", _, _) => ", box resolve".to_string(),
            _ => String::new(),
        }
    }
}

/// The formats a player holds the file's textures in (`Rgba32Float` or `Rgba16Float`) and
/// why (`--texture-precision`, the file's half-float measurement, the adapter).
#[derive(Clone, Debug, Serialize)]
pub struct TextureFormats {
    pub surfaces: String,
    pub cube_maps: String,
    pub why: String,
    /// The level images the GPU rebuild reads: "16 bits" or "32-bit floats".
    pub level_images: String,
    pub level_images_why: String,
    /// Whether the player rebuilds textures on the GPU (the level images' line applies).
    #[serde(skip)]
    pub gpu_rebuild: bool,
}

impl TextureFormats {
    pub fn of(player: &Player) -> TextureFormats {
        let p = player.texture_precision();
        TextureFormats {
            surfaces: format!("{:?}", p.surface),
            cube_maps: format!("{:?}", p.cube),
            why: p.why.clone(),
            level_images: if p.level16 { "16 bits" } else { "32-bit floats" }.into(),
            level_images_why: p.levels_why.clone(),
            gpu_rebuild: player.rebuild() == pis_play::Rebuild::Gpu,
        }
    }

    /// "textures Rgba16Float, cube maps Rgba16Float: WHY", and where the GPU rebuilds them,
    /// "; level images 16 bits: WHY".
    pub fn label(&self) -> String {
        let textures =
            format!("textures {}, cube maps {}: {}", self.surfaces, self.cube_maps, self.why);
        match self.gpu_rebuild {
            true => {
                format!("{textures}; level images {}: {}", self.level_images, self.level_images_why)
            }
            false => textures,
        }
    }
}

/// "msaa 4×", "msaa off", or "msaa off (4× asked, not supported)".
pub fn msaa_label(samples: u32, requested: u32) -> String {
    let used = if samples > 1 { format!("msaa {samples}×") } else { "msaa off".to_string() };
    if samples == requested {
        used
    } else {
        format!("{used} ({requested}× asked, not supported)")
    }
}

fn blend_name(b: pis_play::Blend) -> String {
    format!("{b:?}").to_lowercase()
}

/// Opens the GPU and the file.
pub fn open(args: &HeadlessRequest) -> Result<(Arc<Gpu>, Player), Failure> {
    let gpu = Arc::new(Gpu::new().map_err(play_failure)?);
    let player = Player::open(gpu.clone(), &args.file, args.options.clone()).map_err(|e| {
        let f = play_failure(e);
        let message = f.error.to_string();
        let path = args.file.display().to_string();
        // Name the file where the message does not.
        if message.contains(&path) {
            f
        } else {
            Failure::new(f.exit, f.error.context(path))
        }
    })?;
    if let Some(note) = &player.multisample().note {
        eprintln!("pis-play: note: {note}");
    }
    Ok((gpu, player))
}

/// The middle sample of every dimension.
pub fn middle_point(player: &Player) -> Vec<f32> {
    player
        .dimensions()
        .iter()
        .map(|d| d.values.get(d.values.len() / 2).copied().unwrap_or(0.0))
        .collect()
}

/// Frame `k` of the diagonal path: sample `k mod n₀` along the first dimension and
/// `(k + ⌊k / n₀⌋·d) mod n_d` along dimension d, so that every frame visits a new sample
/// until the space is covered (for equal sizes).
pub fn diagonal_point(dims: &[pis_format::Dimension], k: usize) -> Vec<f32> {
    let n0 = dims.first().map_or(1, |d| d.values.len().max(1));
    dims.iter()
        .enumerate()
        .map(|(d, dim)| {
            let n = dim.values.len().max(1);
            let i = if d == 0 { k % n } else { (k + (k / n0) * d) % n };
            dim.values.get(i).copied().unwrap_or(0.0)
        })
        .collect()
}

fn read_path_file(path: &Path, dims: usize) -> Result<Vec<Vec<f32>>, Failure> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("reading the path file {}", path.display()))
        .map_err(|e| Failure::new(Exit::Io, e))?;
    let mut out = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let p: Vec<f32> = line
            .split([',', ' ', '\t'])
            .filter(|s| !s.is_empty())
            .map(|s| s.parse::<f32>().ok().filter(|v| v.is_finite()))
            .collect::<Option<_>>()
            .ok_or_else(|| {
                Failure::new(
                    Exit::Invalid,
                    anyhow!("{}:{}: expected numbers, got {line:?}", path.display(), n + 1),
                )
            })?;
        if p.len() != dims {
            return Err(Failure::new(
                Exit::Invalid,
                anyhow!(
                    "{}:{}: {} values, the file's parameter space has {dims} dimensions",
                    path.display(),
                    n + 1,
                    p.len()
                ),
            ));
        }
        out.push(p);
    }
    if out.is_empty() {
        return Err(Failure::new(Exit::Invalid, anyhow!("{}: no points", path.display())));
    }
    Ok(out)
}

/// The frames of a run: their requests.
fn requests(args: &HeadlessRequest, player: &Player) -> Result<Vec<FrameRequest>, Failure> {
    let dims = player.dimensions();
    let at = match &args.at {
        Some(p) if p.len() != dims.len() => {
            let names: Vec<&str> = dims.iter().map(|d| d.name.as_str()).collect();
            return Err(Failure::new(
                Exit::Usage,
                anyhow!(
                    "--at gives {} values, the parameter space has {} dimensions ({})",
                    p.len(),
                    dims.len(),
                    names.join(", ")
                ),
            ));
        }
        Some(p) => p.clone(),
        None => middle_point(player),
    };
    let sample = |point: Vec<f32>| FrameRequest { point, camera: CameraChoice::Sample };
    Ok(match &args.path {
        None => vec![sample(at)],
        Some(PathChoice::Diagonal) => {
            let n =
                args.frames.unwrap_or_else(|| dims.iter().map(|d| d.values.len().max(1)).product());
            (0..n).map(|k| sample(diagonal_point(dims, k))).collect()
        }
        Some(PathChoice::File(f)) => {
            let points = read_path_file(f, dims.len())?;
            let n = args.frames.unwrap_or(points.len());
            (0..n).map(|k| sample(points[k % points.len()].clone())).collect()
        }
        Some(PathChoice::Orbit) => {
            let n = args.frames.unwrap_or(36).max(1);
            let c = player.sample_camera(&at);
            let offset = c.eye - c.target;
            (0..n)
                .map(|k| {
                    let angle = std::f32::consts::TAU * k as f32 / n as f32;
                    let eye = c.target + glam::Quat::from_rotation_y(angle) * offset;
                    FrameRequest {
                        point: at.clone(),
                        camera: CameraChoice::Free(ViewCamera { eye, up: glam::Vec3::Y, ..c }),
                    }
                })
                .collect()
        }
    })
}

fn write_frame(dir: &Path, name: &str, img: &pis_play::FloatImage) -> Result<PathBuf, Failure> {
    let path = dir.join(name);
    pis_pack::images::write_png(&path, img.width, img.height, 4, &img.rgba)
        .map_err(|e| Failure::new(Exit::Io, e))?;
    Ok(path)
}

fn out_dir(args: &HeadlessRequest) -> Result<Option<&Path>, Failure> {
    if let Some(d) = &args.out {
        std::fs::create_dir_all(d)
            .with_context(|| format!("creating {}", d.display()))
            .map_err(|e| Failure::new(Exit::Io, e))?;
    }
    Ok(args.out.as_deref())
}

/// Draws the frames of `args` and reports their timings.
pub fn run_frames(
    args: &HeadlessRequest,
    gpu: &Gpu,
    player: &mut Player,
) -> Result<PathReport, Failure> {
    let size = args.size.unwrap_or_else(|| player.image_size());
    let reqs = requests(args, player)?;
    let out = out_dir(args)?;
    let progress = reqs.len() > 1 && !args.quiet;
    let mut rows = Vec::with_capacity(reqs.len());
    let mut all = Vec::with_capacity(reqs.len());
    for (k, req) in reqs.iter().enumerate() {
        player.prefetch(&reqs[k + 1..(k + 1 + args.prefetch).min(reqs.len())]);
        // Frames that are not written are not read back: their time is the frame's cost
        // where it is shown.
        let stats = match out {
            Some(dir) => {
                let (img, stats) = player.render_image(req, size).map_err(play_failure)?;
                write_frame(dir, &format!("frame-{k:04}.png"), &img)?;
                stats
            }
            None => player.render_timed(req, size).map_err(play_failure)?,
        };
        if progress && (k + 1) % 10 == 0 {
            eprintln!("pis-play: frame {}/{}", k + 1, reqs.len());
        }
        rows.push(FrameRow {
            point: req.point.clone(),
            frame_ms: stats.frame_ms,
            decode_ms: stats.decode_ms,
            upload_ms: stats.upload_ms,
            rebuild_ms: stats.rebuild_ms,
            draw_ms: stats.draw_ms,
            readback_ms: stats.readback_ms,
            codestreams_read: stats.codestreams_read,
            decode_waits: stats.decode_waits,
            prefetched: stats.prefetched,
            surface_draws: stats.surface_draws,
            shell_draws: stats.shell_draws,
            lens_ms: stats.lens_ms,
            lens_rays: stats.lens_rays,
        });
        all.push(stats);
    }
    let n = all.len().max(1) as f64;
    let mean = |f: fn(&FrameStats) -> f64| all.iter().map(f).sum::<f64>() / n;
    let worst = |f: fn(&FrameStats) -> f64| all.iter().map(f).fold(0.0, f64::max);
    let (fm, fw) = (mean(|s| s.frame_ms), worst(|s| s.frame_ms));
    let o = player.options();
    Ok(PathReport {
        file: args.file.display().to_string(),
        adapter: gpu.describe(),
        textures: TextureFormats::of(player),
        size: [size.0, size.1],
        blend: blend_name(o.blend),
        reduction: o.reduction,
        msaa_samples: player.multisample().samples,
        msaa_requested: player.multisample().requested,
        resolve: Resolve::of(player),
        workers: o.workers,
        rebuild: player.rebuild().name(),
        lens_rays: player.lens_rays().name(),
        prefetch: args.prefetch,
        frames: all.len(),
        frames_waited: all.iter().filter(|s| s.decode_waits > 0).count(),
        prefetched: all.iter().map(|s| s.prefetched).sum(),
        prefetch_dropped: player.prefetch_dropped(),
        rebuilt_ahead: all.iter().map(|s| s.rebuilt_ahead).sum(),
        frame_ms_mean: fm,
        frame_ms_worst: fw,
        fps_mean: 1e3 / fm.max(1e-9),
        fps_worst: 1e3 / fw.max(1e-9),
        decode_ms_mean: mean(|s| s.decode_ms),
        decode_ms_worst: worst(|s| s.decode_ms),
        upload_ms_mean: mean(|s| s.upload_ms),
        upload_ms_worst: worst(|s| s.upload_ms),
        rebuild_ms_mean: mean(|s| s.rebuild_ms),
        rebuild_ms_worst: worst(|s| s.rebuild_ms),
        upload_bytes_mean: mean(|s| s.upload_bytes as f64),
        draw_ms_mean: mean(|s| s.draw_ms),
        draw_ms_worst: worst(|s| s.draw_ms),
        readback_ms_mean: mean(|s| s.readback_ms),
        surface_draws_mean: mean(|s| s.surface_draws as f64),
        shell_draws_mean: mean(|s| s.shell_draws as f64),
        lens_ms_mean: mean(|s| s.lens_ms),
        lens_ms_worst: worst(|s| s.lens_ms),
        lens_rays_mean: mean(|s| s.lens_rays as f64),
        lens_triangles_mean: mean(|s| s.lens_triangles as f64),
        lens_draws_mean: mean(|s| s.lens_draws as f64),
        lens_traced_ahead: all.iter().map(|s| s.lens_traced_ahead).sum(),
        lens_ahead_dropped: player.lens_ahead_dropped(),
        cache_hits: all.iter().map(|s| s.cache_hits).sum(),
        cache_misses: all.iter().map(|s| s.cache_misses).sum(),
        cache_bytes_max: all.iter().map(|s| s.cache_bytes).max().unwrap_or(0),
        codestreams_read: all.iter().map(|s| s.codestreams_read).sum(),
        per_frame: rows,
    })
}

pub fn print_path_report(r: &PathReport, w: &mut impl std::io::Write) -> std::io::Result<()> {
    writeln!(
        w,
        "pis-play {} ({}x{}, blend {}, reduction {}, {}{}, {} decoding threads, textures rebuilt on the {})",
        r.file,
        r.size[0],
        r.size[1],
        r.blend,
        r.reduction,
        msaa_label(r.msaa_samples, r.msaa_requested),
        r.resolve.label(),
        r.workers,
        if r.rebuild == "gpu" { "GPU" } else { "workers" }
    )?;
    writeln!(w, "  adapter: {}", r.adapter)?;
    writeln!(w, "  {}", r.textures.label())?;
    writeln!(w, "  frames: {}", r.frames)?;
    writeln!(
        w,
        "  frame ms: mean {:.2} ({:.1} fps), worst {:.2} ({:.1} fps)",
        r.frame_ms_mean, r.fps_mean, r.frame_ms_worst, r.fps_worst
    )?;
    writeln!(
        w,
        "  decode ms: mean {:.2}, worst {:.2}; upload ms: mean {:.2}, worst {:.2} ({:.0} KiB per frame)",
        r.decode_ms_mean,
        r.decode_ms_worst,
        r.upload_ms_mean,
        r.upload_ms_worst,
        r.upload_bytes_mean / 1024.0
    )?;
    if r.rebuild == "gpu" {
        writeln!(
            w,
            "  GPU rebuild ms (compute passes, submitted and finished): mean {:.2}, worst {:.2}",
            r.rebuild_ms_mean, r.rebuild_ms_worst
        )?;
    }
    write!(
        w,
        "  draw ms (recorded, submitted, finished on the GPU): mean {:.2}, worst {:.2}",
        r.draw_ms_mean, r.draw_ms_worst
    )?;
    if r.readback_ms_mean > 0.0 {
        write!(w, "; readback ms (frames written): mean {:.2}", r.readback_ms_mean)?;
    }
    writeln!(w)?;
    writeln!(w, "  draws per frame: {:.1} surface layers, {:.1} reflection terms (environment-map shells), {:.1} lens terms", r.surface_draws_mean, r.shell_draws_mean, r.lens_draws_mean)?;
    if r.lens_draws_mean > 0.0 {
        let on = if r.lens_rays == "gpu" { "GPU" } else { "workers" };
        writeln!(w, "  lens objects (vertex rays on the {on}, tessellation, vertex buffers): mean {:.2} ms, worst {:.2}; {:.0} rays, {:.0} triangles per frame; {} tessellations found traced ahead, {} dropped", r.lens_ms_mean, r.lens_ms_worst, r.lens_rays_mean, r.lens_triangles_mean, r.lens_traced_ahead, r.lens_ahead_dropped)?;
    }
    writeln!(
        w,
        "  level-image cache: {} hits, {} misses, at most {:.1} MiB; codestreams read: {}",
        r.cache_hits,
        r.cache_misses,
        r.cache_bytes_max as f64 / (1 << 20) as f64,
        r.codestreams_read
    )?;
    writeln!(
        w,
        "  frames that waited on decoding: {} of {}; decoding {} frames ahead: {} level images found decoded, {} dropped, {} textures found rebuilt",
        r.frames_waited, r.frames, r.prefetch, r.prefetched, r.prefetch_dropped, r.rebuilt_ahead
    )
}

/// Compares every sample point of `set` with its gold standard.
pub fn run_compare(
    args: &HeadlessRequest,
    set: &Path,
    gpu: &Gpu,
    player: &mut Player,
) -> Result<CompareReport, Failure> {
    let out = out_dir(args)?;
    let options = CompareOptions { size: args.size };
    let mut write_error = None;
    let quiet = args.quiet;
    let c: Comparison = compare_with_set(player, set, &options, &mut |pair| {
        if !quiet {
            eprintln!("pis-play: point {} {:?}", pair.index, pair.point);
        }
        if let Some(dir) = out {
            if let Err(e) = write_frame(dir, &format!("point-{:04}.png", pair.index), pair.rendered)
            {
                write_error.get_or_insert(e);
            }
        }
    })
    .map_err(|e| match e.downcast::<PlayError>() {
        Ok(p) => play_failure(p),
        Err(e) => Failure::new(Exit::Invalid, e),
    })?;
    if let Some(e) = write_error {
        return Err(e);
    }
    let o = player.options();
    Ok(CompareReport {
        file: args.file.display().to_string(),
        set: set.display().to_string(),
        adapter: gpu.describe(),
        textures: TextureFormats::of(player),
        blend: blend_name(o.blend),
        reduction: o.reduction,
        msaa_samples: player.multisample().samples,
        msaa_requested: player.multisample().requested,
        resolve: Resolve::of(player),
        psnr_db: c.psnr_db,
        covered_psnr_db: c.covered_psnr_db,
        silhouette_psnr_db: c.silhouette.psnr(),
        interior_psnr_db: c.interior.psnr(),
        silhouette_fraction: c.silhouette.count as f64
            / (c.silhouette.count + c.interior.count).max(1) as f64,
        objects: c
            .objects
            .iter()
            .map(|s| ObjectRow {
                name: s.name.clone(),
                psnr_db: s.psnr_db,
                pixels: s.error.count / 3,
                blocks: s
                    .blocks
                    .iter()
                    .map(|b| BlockRow { block: b.block, psnr_db: b.psnr_db })
                    .collect(),
            })
            .collect(),
        points: c
            .points
            .iter()
            .map(|p| PointRow { index: p.index, point: p.point.clone(), psnr_db: p.psnr_db })
            .collect(),
    })
}

pub fn print_compare_report(r: &CompareReport, w: &mut impl std::io::Write) -> std::io::Result<()> {
    writeln!(
        w,
        "pis-play {} against {} (blend {}, reduction {}, {}{})",
        r.file,
        r.set,
        r.blend,
        r.reduction,
        msaa_label(r.msaa_samples, r.msaa_requested),
        r.resolve.label()
    )?;
    writeln!(w, "  adapter: {}", r.adapter)?;
    writeln!(w, "  {}", r.textures.label())?;
    writeln!(
        w,
        "  PSNR (display values): whole image {:.2} dB, objects' covered pixels {:.2} dB",
        r.psnr_db, r.covered_psnr_db
    )?;
    writeln!(w, "  whole image at silhouettes {:.2} dB ({:.1} % of the pixels: partly covered in the gold standard), elsewhere {:.2} dB", r.silhouette_psnr_db, 100.0 * r.silhouette_fraction, r.interior_psnr_db)?;
    for o in &r.objects {
        writeln!(
            w,
            "    {:<14} {:>7.2} dB  ({} pixel samples over {} blocks)",
            o.name,
            o.psnr_db,
            o.pixels,
            o.blocks.len()
        )?;
    }
    Ok(())
}
