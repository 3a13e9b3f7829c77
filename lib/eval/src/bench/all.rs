//! `pis-bench all`: every chart from scratch on demo1 (trace → pack → evaluate) at a
//! preset: `ci` (80×60, 1 spp, demo1's 16 points: under a minute on 2 cores) or `paper` (demo1's
//! paper preset: 640×480, 16 spp, 64 points).

use std::path::{Path, PathBuf};

use anyhow::anyhow;
use pis_scene::LoadOptions;

use super::rd::{self, RdRequest};
use super::reference::ReferenceTrace;
use super::speed::{self, SpeedRequest};
use super::stability::{self, StabilityRequest};
use pis_pack::{Exit, Failure};

/// A preset of `all`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Preset {
    Ci,
    Paper,
}

impl Preset {
    /// Every preset, in the order the tools list them.
    pub const ALL: [Preset; 2] = [Preset::Ci, Preset::Paper];

    /// The name `pis-bench all --preset` takes.
    pub fn name(self) -> &'static str {
        match self {
            Preset::Ci => "ci",
            Preset::Paper => "paper",
        }
    }
}

/// Settings of one preset.
struct Settings {
    preset: Option<&'static str>,
    resolution: Option<(u32, u32)>,
    spp: Option<u32>,
    rd_ratios: Vec<f64>,
    caps: Vec<u32>,
    stability_ratios: Vec<f64>,
    frames: usize,
    reference_spp: u32,
}

fn settings(p: Preset) -> Settings {
    match p {
        Preset::Ci => Settings {
            preset: None,
            resolution: Some((80, 60)),
            spp: Some(1),
            rd_ratios: vec![24.0, 48.0, 96.0, 192.0],
            caps: vec![10, 50, 400],
            stability_ratios: vec![96.0, 384.0, 2000.0],
            frames: 9,
            reference_spp: 4,
        },
        Preset::Paper => Settings {
            preset: Some("paper"),
            resolution: None,
            spp: None,
            rd_ratios: vec![96.0, 192.0, 384.0, 768.0],
            caps: vec![25, 100, 400],
            stability_ratios: vec![96.0, 384.0, 2000.0],
            frames: 33,
            reference_spp: 16,
        },
    }
}

/// demo1's scene.toml in the source tree this binary was built from.
pub fn demo1() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../samples/demo1/scene.toml")
}

/// Removes the traced set of an earlier run so that the charts start from tracing.
fn clear_cache(scene: &Path, s: &Settings) -> Result<(), Failure> {
    let options =
        LoadOptions { preset: s.preset.map(str::to_string), resolution: s.resolution, spp: s.spp };
    let loaded =
        pis_scene::load_with(scene, &options).map_err(|e| Failure::new(Exit::Invalid, e))?;
    let trace = pis_pack::scene_trace_settings(&loaded, super::TRACE_DENOISE)?;
    let dir = pis_pack::cache_dir(scene, &loaded, &trace);
    if dir.exists() {
        std::fs::remove_dir_all(&dir)
            .map_err(|e| Failure::new(Exit::Io, anyhow!("removing {}: {e}", dir.display())))?;
    }
    Ok(())
}

/// Runs rd, speed and stability; the reports print as they finish.
pub fn run(preset: Preset, scene: &Path, out: &Path, record: bool) -> Result<(), Failure> {
    if !scene.is_file() {
        return Err(Failure::new(Exit::Io, anyhow!("{}: no such scene file", scene.display())));
    }
    let s = settings(preset);
    clear_cache(scene, &s)?;
    let preset_name = s.preset.map(str::to_string);
    let rd_req = RdRequest {
        input: scene.to_path_buf(),
        scene: None,
        ratios: s.rd_ratios.clone(),
        out: out.to_path_buf(),
        resolution: s.resolution,
        spp: s.spp,
        max_texture: pis_pack::DEFAULT_MAX_TEXTURE,
        preset: preset_name.clone(),
        record,
        methods: vec![],
        max_mse: pis_pack::PackSettings::new().max_mse,
        stagger: pis_pack::Stagger::Auto,
    };
    let r = rd::run(&rd_req)?;
    rd::print(&r, &mut std::io::stderr()).map_err(|e| Failure::new(Exit::Io, e))?;
    let speed_req = SpeedRequest {
        input: scene.to_path_buf(),
        scene: None,
        caps: s.caps.clone(),
        ratio: 384.0,
        out: out.to_path_buf(),
        resolution: s.resolution,
        spp: s.spp,
        preset: preset_name.clone(),
        max_texture: pis_pack::DEFAULT_MAX_TEXTURE,
        record,
    };
    let r = speed::run(&speed_req)?;
    speed::print(&r, &mut std::io::stderr()).map_err(|e| Failure::new(Exit::Io, e))?;
    let st_req = StabilityRequest {
        input: scene.to_path_buf(),
        scene: None,
        ratios: s.stability_ratios.clone(),
        frames: s.frames,
        reference: ReferenceTrace::new(s.reference_spp, pis_trace::ShadingSeed::Cell),
        out: out.to_path_buf(),
        resolution: s.resolution,
        trace_spp: s.spp,
        max_texture: pis_pack::DEFAULT_MAX_TEXTURE,
        preset: preset_name,
        record,
    };
    let r = stability::run(&st_req)?;
    stability::print(&r, &mut std::io::stderr()).map_err(|e| Failure::new(Exit::Io, e))?;
    Ok(())
}
