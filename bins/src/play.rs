//! pis-play: the player's command line. Headless mode draws offscreen (`headless`); the
//! arguments (`args`) are shared with a window mode.

pub mod args;
pub mod headless;

use std::path::{Path, PathBuf};

use crate::cli::{Exit, Failure};
pub use args::PlayArgs;

/// Whether a path names a scene (scene.toml) rather than a container.
fn is_scene(path: &Path) -> bool {
    path.extension().is_some_and(|e| e.eq_ignore_ascii_case("toml"))
}

/// Traces (when not cached) and packs a scene.toml with pis-pack's defaults; returns the
/// container, kept in `.pis-cache/` beside the scene and reused while it is newer than the
/// scene.toml.
fn pack_scene(scene_toml: &Path) -> Result<PathBuf, Failure> {
    let scene = pis_scene::load(scene_toml, None).map_err(|e| Failure::new(Exit::Invalid, e))?;
    let set_dir = crate::pack::cache_dir(scene_toml, &scene);
    let mut name = set_dir.file_name().map(|n| n.to_os_string()).unwrap_or_default();
    name.push(".pis");
    let output = set_dir.with_file_name(name);
    let modified = |p: &Path| std::fs::metadata(p).and_then(|m| m.modified()).ok();
    if let (Some(pis), Some(toml)) = (modified(&output), modified(scene_toml)) {
        if pis >= toml {
            eprintln!("pis-play: playing {} (packed from {})", output.display(), scene_toml.display());
            return Ok(output);
        }
    }
    std::fs::create_dir_all(set_dir.parent().unwrap_or(Path::new("."))).map_err(|e| Failure::new(Exit::Io, anyhow::anyhow!("{}: {e}", set_dir.display())))?;
    eprintln!("pis-play: tracing and packing {} into {} (once; pis-pack's defaults)", scene_toml.display(), output.display());
    let req = crate::pack::PackRequest {
        input: scene_toml.to_path_buf(),
        scene: None,
        output: output.clone(),
        ratio: None,
        psnr: None,
        codec: pis_codec::CodecId::Wavelet,
        block: vec![8],
        filter: pis_compile::Filter::Trilinear,
        matrix: crate::pack::MatrixSource::Model,
        max_texture: crate::pack::DEFAULT_MAX_TEXTURE,
        texels_per_pixel: crate::pack::DEFAULT_TEXELS_PER_PIXEL,
        gamma: 2.2,
        resolution: None,
        spp: None,
        pyramid: crate::pack::PyramidMode::Adaptive,
        layers: crate::pack::LayerMode::Separate,
        max_iterations: None,
        allocation: crate::pack::Allocation::Screen, placement: crate::pack::PlacementMode::Block,
        preset: None,
    };
    let report = crate::pack::pack(&req)?;
    crate::pack::print_report(&report, &mut std::io::stderr()).map_err(|e| Failure::new(Exit::Io, e))?;
    Ok(output)
}

/// Whether a display server is reachable through the environment (X11 or Wayland).
pub fn has_display() -> bool {
    ["DISPLAY", "WAYLAND_DISPLAY"].iter().any(|v| std::env::var_os(v).is_some_and(|s| !s.is_empty()))
}

/// Runs pis-play: in a window where a display is set and no headless output (--out,
/// --compare) is asked for; else without a window: with `--headless`, or (with a note on
/// stderr) when no window can be opened.
pub fn run(args: &PlayArgs) -> Result<Exit, Failure> {
    let packed;
    let args = if is_scene(&args.file) {
        // The one-command tour: play along the diagonal unless a point or path is given.
        let tour = args.path.is_none() && args.at.is_none() && args.compare.is_none();
        let path = if tour { Some(args::PathChoice::Diagonal) } else { args.path.clone() };
        packed = PlayArgs { file: pack_scene(&args.file)?, path, ..args.clone() };
        &packed
    } else {
        args
    };
    // `--set` also names the display filter of headless runs, given with --headless.
    let window_only = args.screenshot.is_some() || (args.set.is_some() && !args.headless);
    if !args.headless && args.out.is_none() && args.compare.is_none() {
        if has_display() {
            match crate::play_window::try_run(args) {
                Ok(()) => return Ok(Exit::Ok),
                Err(crate::play_window::WindowFailure::NoDisplay(m)) if !window_only => {
                    eprintln!("pis-play: note: {m}; drawing headless");
                }
                Err(e) => return Err(e.into()),
            }
        } else if window_only {
            return Err(Failure::new(Exit::Runtime, anyhow::anyhow!("--screenshot and --set need a window, and no display is set (DISPLAY / WAYLAND_DISPLAY): run under `xvfb-run -a`")));
        } else {
            eprintln!("pis-play: note: no display (DISPLAY / WAYLAND_DISPLAY unset); drawing headless");
        }
    } else if args.screenshot.is_some() || (args.set.is_some() && !args.headless) {
        return Err(Failure::new(Exit::Usage, anyhow::anyhow!("--screenshot and --set (without --headless) are window options; they do not go with --headless, --out or --compare")));
    }
    if let Some(set) = &args.set {
        // Headless, the set gives the display filter: it must be readable.
        pis_trace::set::RaySet::open(set).map_err(|e| {
            let exit = if matches!(e, pis_trace::TraceError::Io { .. }) { Exit::Io } else { Exit::Invalid };
            Failure::new(exit, anyhow::anyhow!("--set {}: {e}", set.display()))
        })?;
    }
    headless::run(args)
}
