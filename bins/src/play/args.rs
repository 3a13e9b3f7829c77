//! pis-play's command line, shared by the headless player and a window mode.

use std::path::PathBuf;

use clap::Parser;
pub use pis_eval::headless::{parse_path, set_display_filter, PathChoice};

fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let v: Vec<u32> = s
        .split(['x', 'X'])
        .map(|p| p.trim().parse::<u32>().ok().filter(|&n| n > 0))
        .collect::<Option<_>>()
        .ok_or_else(|| format!("expected WIDTHxHEIGHT, got {s:?}"))?;
    match v.as_slice() {
        [w, h] => Ok((*w, *h)),
        _ => Err(format!("expected WIDTHxHEIGHT, got {s:?}")),
    }
}

pub fn parse_tau(s: &str) -> Result<f32, String> {
    match s.parse::<f32>() {
        Ok(t) if t.is_finite() && t >= 0.25 => Ok(t),
        _ => Err(format!("--tau {s:?}: expected a number of pixels, at least 0.25")),
    }
}

pub fn parse_msaa(s: &str) -> Result<u32, String> {
    let n = s.parse::<u32>().map_err(|_| format!("--msaa {s:?}: expected 1 or 4"))?;
    pis_play::multisample::check_samples(n).map(|()| n)
}

fn parse_reduction(s: &str) -> Result<u32, String> {
    s.parse::<u32>()
        .ok()
        .filter(|r| r.is_power_of_two())
        .ok_or_else(|| format!("--reduction {s:?}: expected a power of two (1, 2, 4, …)"))
}

/// Play a `.pis` file: draw frames of its parameterized textures on the GPU (thesis 4.7).
///
/// Headless, frames are drawn offscreen: one frame at `--at`, a path of frames (`--path`), or
/// every sample point of a ray-traced set compared with its gold standard (`--compare`).
/// Frames are written as sRGB PNGs with `--out`; timings go to stderr (and stdout with
/// `--json`).
///
/// In a window (the default where a display is set and neither --headless, --out nor
/// --compare is given): a slider per dimension, play/pause along a path (`--path diagonal`
/// starts playing, `--path orbit` starts with the orbit camera), nearest or multilinear blend,
/// the sample camera or a free orbit / fly camera, a stats panel, and with `--set` the
/// ray-traced gold standard. `--frames N` exits after N frames with a frame-rate report,
/// `--screenshot` saves the last one.
///
/// A file with relightable layers plays under its own light at the parameter point, or
/// relit: with `--light` (any number) and `--sky` in headless frames and as the window's
/// start; in the window, the Lights panel adds, drags and removes lights and loads a sky.
///
/// Given a scene.toml instead of a .pis file, the whole job runs first: the scene is traced
/// (once, into `.pis-cache/` beside it) and packed with pis-pack's options (its defaults
/// unless given) into `.pis-cache/NAME-WxH-sppN.pis` (`…-sppN-HASH.pis` for other pack
/// options), reused while it is newer than the scene.toml and records the target asked for;
/// without
/// `--at`, `--path` or `--compare` it then plays along the diagonal (`--path diagonal`).
#[derive(Parser, Debug, Clone)]
#[command(name = "pis-play", version, about, after_help = crate::cli::EXIT_CODES_HELP)]
pub struct PlayArgs {
    /// The .pis file to play, or a scene.toml to trace, pack and play.
    pub file: PathBuf,
    /// Draw offscreen, without a window.
    #[arg(long)]
    pub headless: bool,
    /// The parameter point: one value per dimension, comma separated, in the dimension's own
    /// values (default: the middle sample of each dimension).
    #[arg(long, value_name = "V1,V2,...", value_delimiter = ',', allow_hyphen_values = true)]
    pub at: Option<Vec<f32>>,
    /// A path of frames: `diagonal`, `orbit` or a file of points.
    #[arg(long, value_name = "diagonal|orbit|PATHFILE", value_parser = parse_path)]
    pub path: Option<PathChoice>,
    /// Frames of the path (default: every point of the space for `diagonal`, 36 for
    /// `orbit`, every line of a path file). In a window: exit after this many frames with a
    /// frame-rate report.
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
    #[arg(long, default_value = "nearest", value_parser = crate::cli::one_of(&pis_play::Blend::ALL, pis_play::Blend::name))]
    pub blend: pis_play::Blend,
    /// Texture resolution reduction (power of two): 2 draws textures at half resolution.
    #[arg(long, default_value = "1", value_parser = parse_reduction)]
    pub reduction: u32,
    /// Samples per pixel: 4 antialiases object silhouettes (depth and object index per
    /// sample, shading once per pixel at its centre), as the ray-traced gold standard's
    /// filtered pixels are; 1 draws each pixel wholly one surface. The samples are resolved
    /// with the set's display filter where the file records it (pis-pack copies it) or,
    /// for a file that does not, where --compare or --set names a set: each pixel mixes the
    /// objects of its 3×3 neighbourhood's samples by their Gaussian coverage. Otherwise each
    /// pixel's own samples are averaged. Where the GPU cannot multisample the frame's
    /// formats, 1 with a note.
    #[arg(long, default_value_t = pis_play::multisample::DEFAULT_SAMPLES, value_name = "1|4", value_parser = parse_msaa)]
    pub msaa: u32,
    /// Lens objects (hybrid rendering): the screen edge length in pixels down to which
    /// their tessellation is refined where the vertex rays' paths differ (thesis 6.4.1's τ).
    #[arg(long, default_value_t = 1.0, value_name = "PIXELS", value_parser = parse_tau)]
    pub tau: f32,
    /// Depth shells: the march's coarse steps along each reflected ray (1 to 64), in place
    /// of the count the file records and its radiance was solved with. Fewer is faster and
    /// misses thin occluders; more finds them where the file's count stepped over them.
    #[arg(long, value_name = "N", value_parser = crate::cli::parse_depth_steps)]
    pub depth_steps: Option<u32>,
    /// Lens objects (hybrid rendering): where each tessellation level's vertex rays are
    /// traced through the object: `gpu` (a compute pass over the object's BVH, uploaded
    /// once; paths deeper than its stack go to the workers), `workers` (on the CPU), or
    /// `auto`: `gpu` on a GPU, `workers` on a CPU rasterizer such as lavapipe.
    #[arg(long, default_value = "auto", value_parser = crate::cli::one_of(&pis_play::LensRays::ALL, pis_play::LensRays::name))]
    pub lens_rays: pis_play::LensRays,
    /// Where textures are rebuilt from their decoded level images: `gpu` (compute passes;
    /// the decoding threads only decode, and each level image goes up once and stays on the
    /// GPU while the cache keeps it), `workers` (summed on the decoding threads and uploaded
    /// as RGBA), or `auto`: `gpu` on a GPU, `workers` on a CPU rasterizer such as lavapipe.
    /// A --reduction is rebuilt on the workers.
    #[arg(long, default_value = "auto", value_parser = crate::cli::one_of(&pis_play::Rebuild::ALL, pis_play::Rebuild::name))]
    pub rebuild: pis_play::Rebuild,
    /// The precision textures are held in on the GPU: `half` (16-bit floats: half the
    /// memory and upload), `full` (32-bit floats), or `auto`: half where the file records
    /// that rounding to half floats stays 20 dB or more below its coding error (pis-pack
    /// measures it), else full. The same rule, by its own measurement, sets the precision of
    /// the level images the GPU rebuild reads (--rebuild gpu): 16 bits a value over each
    /// image's range, or 32-bit floats. The report says which and why.
    #[arg(long, default_value = "auto", value_parser = crate::cli::one_of(&pis_play::TexturePrecision::ALL, pis_play::TexturePrecision::name))]
    pub texture_precision: pis_play::TexturePrecision,
    /// Along a path: decode the textures of this many next frames on the decoding threads
    /// while a frame draws, so that they need not wait (0: decode each frame's textures when
    /// it asks for them).
    #[arg(long, default_value_t = 2, value_name = "FRAMES")]
    pub prefetch: usize,
    /// Memory for decoded level images, MiB (on the GPU, as much again for the level images
    /// its rebuild reads).
    #[arg(long, default_value_t = 512)]
    pub cache_mb: u64,
    /// Decoding threads (default: one per core; the frame waits for its textures). Each keeps
    /// up to 32 MiB of the wavelet decoder's working memory between level images.
    #[arg(long)]
    pub workers: Option<usize>,
    /// Draw every sample point of this ray-traced set and report PSNR against its gold
    /// standard, per object and for the whole image.
    #[arg(long, value_name = "SET_DIR", conflicts_with_all = ["path", "at"])]
    pub compare: Option<PathBuf>,
    /// Print the report as JSON on stdout.
    #[arg(long)]
    pub json: bool,
    /// A ray-traced set of the same space. Its display filter resolves multisampled frames
    /// when the file records none (headless too). Window mode: the panel (or G) shows its
    /// gold standard at the nearest sample instead of the player's frame.
    #[arg(long, value_name = "SET_DIR")]
    pub set: Option<PathBuf>,
    /// Window mode: start showing the gold standard of --set.
    #[arg(long, requires = "set")]
    pub show_gold: bool,
    /// Window mode: save the window's frame number --frames (default 3) as an sRGB PNG, then
    /// exit.
    #[arg(long, value_name = "FILE.png")]
    pub screenshot: Option<PathBuf>,
    /// Window mode: start with the panels hidden (H shows them).
    #[arg(long)]
    pub hide_panels: bool,
    /// Window mode: do not wait for the display refresh between frames (to measure speed).
    #[arg(long)]
    pub no_vsync: bool,
    /// Relighting a file with relightable layers: directional lights and a sky.
    #[command(flatten, next_help_heading = "Relighting (files with relightable layers)")]
    pub lights: crate::play::lights::LightArgs,
    /// Given a scene.toml: how it is traced and packed (pis-pack's options; a .pis file is
    /// played as it is).
    #[command(
        flatten,
        next_help_heading = "Tracing and packing a scene.toml (pis-pack's options)"
    )]
    pub pack: crate::pack_args::PackOptions,
}

impl PlayArgs {
    /// The headless run these arguments ask for.
    pub fn headless(&self) -> pis_eval::headless::HeadlessRequest {
        pis_eval::headless::HeadlessRequest {
            file: self.file.clone(),
            at: self.at.clone(),
            path: self.path.clone(),
            frames: self.frames,
            out: self.out.clone(),
            size: self.size,
            quiet: self.json,
            prefetch: self.prefetch,
            options: self.player_options(),
        }
    }

    /// The player's options from the arguments.
    pub fn player_options(&self) -> pis_play::PlayerOptions {
        let d = pis_play::PlayerOptions::default();
        pis_play::PlayerOptions {
            cache_budget_bytes: self.cache_mb.saturating_mul(1 << 20),
            workers: self.workers.unwrap_or(d.workers).max(1),
            reduction: self.reduction,
            blend: self.blend,
            msaa: self.msaa,
            tau_px: self.tau,
            depth_steps: self.depth_steps,
            rebuild: self.rebuild,
            lens_rays: self.lens_rays,
            precision: self.texture_precision,
            display_filter: self
                .compare
                .as_deref()
                .or(self.set.as_deref())
                .and_then(set_display_filter),
            ..d
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `--blend` takes the names the player gives its blends, and refuses any other.
    #[test]
    fn blend_parses_by_its_name() {
        let parse = |blend: &str| PlayArgs::try_parse_from(["pis-play", "f.pis", "--blend", blend]);
        for blend in pis_play::Blend::ALL {
            assert_eq!(parse(blend.name()).unwrap().blend, blend);
        }
        let err = parse("linear").unwrap_err().to_string();
        assert!(err.contains("possible values"), "{err}");
        assert_eq!(
            PlayArgs::try_parse_from(["pis-play", "f.pis"]).unwrap().blend,
            Default::default()
        );
    }

    /// `--light` repeats and takes a negative azimuth; the sky's rotation and strength need
    /// `--sky`; lights do not go with `--compare` (its gold standard is the file's light).
    #[test]
    fn lights_parse_from_the_command_line() {
        let parse = |extra: &[&str]| {
            PlayArgs::try_parse_from(["pis-play", "f.pis"].iter().chain(extra).copied())
        };
        let args =
            parse(&["--light", "40,50,2.5,1.9,1.2", "--light", "-120,30,0.7,0.9,1.5"]).unwrap();
        assert_eq!(args.lights.lights.len(), 2);
        assert_eq!(args.lights.lights[1].azimuth_deg, -120.0);
        assert!(!parse(&[]).unwrap().lights.given());
        let sky = parse(&["--sky", "s.hdr", "--sky-rotation", "-90", "--sky-strength", "0.5"]);
        let sky = sky.unwrap().lights;
        assert_eq!((sky.sky_rotation, sky.sky_strength), (-90.0, 0.5));
        assert!(sky.given());
        let err = parse(&["--light", "40,50,1"]).unwrap_err().to_string();
        assert!(err.contains("expected AZ,EL,R,G,B"), "{err}");
        assert!(parse(&["--sky-rotation", "10"]).is_err());
        assert!(parse(&["--sky", "s.hdr", "--sky-strength", "-1"]).is_err());
        assert!(parse(&["--light", "0,45,1,1,1", "--compare", "set"]).is_err());
    }
}
