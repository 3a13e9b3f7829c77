//! pis-play's command line, shared by the headless player and a window mode.

use std::path::PathBuf;

use clap::Parser;

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

fn parse_path(s: &str) -> Result<PathChoice, String> {
    Ok(match s {
        "diagonal" => PathChoice::Diagonal,
        "orbit" => PathChoice::Orbit,
        f => PathChoice::File(PathBuf::from(f)),
    })
}

fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let v: Vec<u32> = s.split(['x', 'X']).map(|p| p.trim().parse::<u32>().ok().filter(|&n| n > 0)).collect::<Option<_>>().ok_or_else(|| format!("expected WIDTHxHEIGHT, got {s:?}"))?;
    match v.as_slice() {
        [w, h] => Ok((*w, *h)),
        _ => Err(format!("expected WIDTHxHEIGHT, got {s:?}")),
    }
}

fn parse_blend(s: &str) -> Result<pis_play::Blend, String> {
    match s {
        "nearest" => Ok(pis_play::Blend::Nearest),
        "multilinear" => Ok(pis_play::Blend::Multilinear),
        _ => Err(format!("unknown blend {s:?} (nearest or multilinear)")),
    }
}

fn parse_reduction(s: &str) -> Result<u32, String> {
    s.parse::<u32>().ok().filter(|r| r.is_power_of_two()).ok_or_else(|| format!("--reduction {s:?}: expected a power of two (1, 2, 4, …)"))
}

/// Play a `.pis` file: draw frames of its parameterized textures on the GPU (thesis 4.7).
///
/// Headless, frames are drawn offscreen: one frame at `--at`, a path of frames (`--path`), or
/// every sample point of a ray-traced set compared with its gold standard (`--compare`).
/// Frames are written as sRGB PNGs with `--out`; timings go to stderr (and stdout with
/// `--json`).
#[derive(Parser, Debug, Clone)]
#[command(name = "pis-play", version, about, after_help = crate::cli::EXIT_CODES_HELP)]
pub struct PlayArgs {
    /// The .pis file to play.
    pub file: PathBuf,
    /// Draw offscreen, without a window.
    #[arg(long)]
    pub headless: bool,
    /// The parameter point: one value per dimension, in the dimension's own values
    /// (default: the middle sample of each dimension).
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
    pub at: Option<Vec<f32>>,
    /// A path of frames: `diagonal`, `orbit` or a file of points.
    #[arg(long, value_parser = parse_path)]
    pub path: Option<PathChoice>,
    /// Frames of the path (default: every point of the space for `diagonal`, 36 for
    /// `orbit`, every line of a path file).
    #[arg(long)]
    pub frames: Option<usize>,
    /// Write every frame as an 8-bit sRGB PNG into this directory.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Frame size WIDTHxHEIGHT (default: the file's image size).
    #[arg(long, value_parser = parse_size)]
    pub size: Option<(u32, u32)>,
    /// Between parameter samples: `nearest` sample, or `multilinear` blend of the 2^d
    /// nearest.
    #[arg(long, default_value = "nearest", value_parser = parse_blend)]
    pub blend: pis_play::Blend,
    /// Texture resolution reduction (power of two): 2 draws textures at half resolution.
    #[arg(long, default_value = "1", value_parser = parse_reduction)]
    pub reduction: u32,
    /// Memory for decoded level images, MiB.
    #[arg(long, default_value_t = 512)]
    pub cache_mb: u64,
    /// Decoding threads (default: cores − 1, at least 1).
    #[arg(long)]
    pub workers: Option<usize>,
    /// Draw every sample point of this ray-traced set and report PSNR against its gold
    /// standard, per object and for the whole image.
    #[arg(long, conflicts_with_all = ["path", "at"])]
    pub compare: Option<PathBuf>,
    /// Print the report as JSON on stdout.
    #[arg(long)]
    pub json: bool,
}

impl PlayArgs {
    /// The player's options from the arguments.
    pub fn player_options(&self) -> pis_play::PlayerOptions {
        let d = pis_play::PlayerOptions::default();
        pis_play::PlayerOptions {
            cache_budget_bytes: self.cache_mb.saturating_mul(1 << 20),
            workers: self.workers.unwrap_or(d.workers).max(1),
            reduction: self.reduction,
            blend: self.blend,
            ..d
        }
    }
}
