//! pis-play: the player's command line. Headless mode draws offscreen (`headless`); the
//! arguments (`args`) and the lights of a relightable file (`lights`) are shared with a
//! window mode.

pub mod args;
pub mod lights;

use std::path::{Path, PathBuf};

use crate::cli::{Exit, Failure};
use crate::pack_args::PackOptions;
pub use args::PlayArgs;

/// Whether a path names a scene (scene.toml) rather than a container.
fn is_scene(path: &Path) -> bool {
    path.extension().is_some_and(|e| e.eq_ignore_ascii_case("toml"))
}

/// Traces (when not cached) and packs a scene.toml with `options` (pis-pack's); returns the
/// container, kept in `.pis-cache/` beside the scene and reused while it is newer than the
/// scene.toml and records the target asked for. Options other than the defaults pack into a file of their own, named by a
/// hash of the options.
fn pack_scene(scene_toml: &Path, options: &PackOptions) -> Result<PathBuf, Failure> {
    let load = pis_scene::LoadOptions {
        preset: options.preset.clone(),
        resolution: options.resolution,
        spp: options.spp,
    };
    let scene = pis_scene::load_with(scene_toml, &load).map_err(Failure::from)?;
    let trace = pis_pack::scene_trace_settings(&scene, options.denoise)?;
    let set_dir = pis_pack::cache_dir(scene_toml, &scene, &trace);
    let mut name = set_dir.file_name().map(|n| n.to_os_string()).unwrap_or_default();
    let fingerprint = options.fingerprint();
    if fingerprint != PackOptions::defaults().fingerprint() {
        name.push(format!("-{:016x}", fnv1a(fingerprint.as_bytes())));
    }
    name.push(".pis");
    let output = set_dir.with_file_name(name);
    let modified = |p: &Path| std::fs::metadata(p).and_then(|m| m.modified()).ok();
    let target = options.request(scene_toml.to_path_buf(), None, output.clone())?.target;
    if let (Some(pis), Some(toml)) = (modified(&output), modified(scene_toml)) {
        if pis >= toml && packed_for(&output, &target.describe()) {
            eprintln!(
                "pis-play: playing {} (packed from {})",
                output.display(),
                scene_toml.display()
            );
            return Ok(output);
        }
    }
    std::fs::create_dir_all(set_dir.parent().unwrap_or(Path::new(".")))
        .map_err(|e| Failure::new(Exit::Io, anyhow::anyhow!("{}: {e}", set_dir.display())))?;
    eprintln!(
        "pis-play: tracing and packing {} into {} (once)",
        scene_toml.display(),
        output.display()
    );
    let req = options.request(scene_toml.to_path_buf(), None, output.clone())?;
    let report = pis_pack::pack_request(&req, &pis_pack::StderrProgress)?;
    pis_pack::print_report(&report, &mut std::io::stderr())
        .map_err(|e| Failure::new(Exit::Io, e))?;
    Ok(output)
}

/// Whether the file at `path` records the target `target` (a cached pack made under an
/// earlier default is packed again).
fn packed_for(path: &Path, target: &str) -> bool {
    let Ok(reader) = pis_format::PisReader::open(path) else { return false };
    reader.container().provenance.as_ref().and_then(|p| p.setting(pis_pack::TARGET_SETTING))
        == Some(target)
}

/// 64-bit FNV-1a: a stable name for a set of options.
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes
        .iter()
        .fold(0xcbf2_9ce4_8422_2325u64, |h, &b| (h ^ b as u64).wrapping_mul(0x0100_0000_01b3))
}

/// Whether a display server is reachable through the environment (X11 or Wayland).
pub fn has_display() -> bool {
    ["DISPLAY", "WAYLAND_DISPLAY"]
        .iter()
        .any(|v| std::env::var_os(v).is_some_and(|s| !s.is_empty()))
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
        packed = PlayArgs { file: pack_scene(&args.file, &args.pack)?, path, ..args.clone() };
        &packed
    } else if args.pack.fingerprint() != PackOptions::defaults().fingerprint() {
        return Err(Failure::new(Exit::Usage, anyhow::anyhow!("{}: pis-pack's options (--ratio, --codec, --preset, …) apply to a scene.toml; a .pis file plays as it was packed (pis-reencode codes it again)", args.file.display())));
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
            eprintln!(
                "pis-play: note: no display (DISPLAY / WAYLAND_DISPLAY unset); drawing headless"
            );
        }
    } else if args.screenshot.is_some() || (args.set.is_some() && !args.headless) {
        return Err(Failure::new(Exit::Usage, anyhow::anyhow!("--screenshot and --set (without --headless) are window options; they do not go with --headless, --out or --compare")));
    }
    if let Some(set) = &args.set {
        // Headless, the set gives the display filter: it must be readable.
        pis_trace::set::RaySet::open(set).map_err(|e| {
            let exit = pis_pack::trace_exit(&e);
            Failure::new(exit, anyhow::anyhow!("--set {}: {e}", set.display()))
        })?;
    }
    headless(args)
}

/// The headless player: a frame, a path of frames, or a comparison with a set; the report
/// on stderr (and as JSON on stdout with `--json`).
fn headless(args: &PlayArgs) -> Result<Exit, Failure> {
    use pis_eval::headless::{
        open, print_compare_report, print_path_report, run_compare, run_frames,
    };
    let req = args.headless();
    let (gpu, mut player) = open(&req)?;
    let relightable = player.light_directions().is_some();
    if let Some(lights) = args.lights.relight(&args.file, relightable)? {
        player.set_lights(Some(lights)).map_err(pis_eval::headless::play_failure)?;
    }
    match &args.compare {
        Some(set) => {
            let r = run_compare(&req, set, &gpu, &mut player)?;
            emit(args.json, &r, print_compare_report)
        }
        None => {
            let r = run_frames(&req, &gpu, &mut player)?;
            emit(args.json, &r, print_path_report)
        }
    }
}

/// Prints a report on stderr, and as JSON on stdout when asked.
fn emit<T: serde::Serialize>(
    json: bool,
    report: &T,
    print: impl Fn(&T, &mut std::io::Stderr) -> std::io::Result<()>,
) -> Result<Exit, Failure> {
    print(report, &mut std::io::stderr()).map_err(|e| Failure::new(Exit::Io, e))?;
    if json {
        let s = serde_json::to_string_pretty(report).map_err(|e| Failure::new(Exit::Runtime, e))?;
        println!("{s}");
    }
    Ok(Exit::Ok)
}
