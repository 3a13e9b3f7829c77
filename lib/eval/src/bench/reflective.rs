//! `pis-bench reflective`: reflective objects on and off the sampled views, as the player
//! draws them (thesis 5.10, figs 5.9–5.10); with `role` refractive, the lens objects
//! (thesis 6.5). Given packed files of one scene — e.g. its
//! reflective objects as parameterized textures and as layered environment maps — every
//! file is played at each sampled view and at each camera of two dense paths (between the
//! sampled views on their orbit, and away from it: a larger radius, higher elevation) and
//! compared with a frame ray-traced at that exact camera (the gold standard, at its own
//! samples per pixel), on display values over the pixels the scene's reflective objects
//! cover in the traced frame. With a reference pair, each frame is traced twice from
//! independent sample streams (`pis-trace --seed`): the gold standard is their mean, and
//! their difference measures its own noise, which is then taken out of each file's error
//! ([`PairedError`]). Popping: per path, the largest
//! frame-to-frame RMS change of the played frames over the reference's change between the
//! same frames.

use std::path::PathBuf;
use std::sync::Arc;

use anyhow::{anyhow, Result};
use glam::Vec3;
use pis_play::{CameraChoice, FrameRequest, Gpu, Player, PlayerOptions, ViewCamera};
use pis_scene::{LoadOptions, ObjectRole, Scene};
use pis_trace::layers::LayerKind;
use serde::Serialize;

use super::camera_path::{paths, PathFrame, PathKind};
use super::reference::ReferenceTrace;
use crate::metrics::{display, PairedError, SquaredError};
use crate::report::{Csv, Stamp};
use pis_pack::{Exit, Failure};

/// The paths measured, in report order.
const PATHS: [PathKind; 3] = [PathKind::Samples, PathKind::Between, PathKind::Away];

/// What to measure.
#[derive(Clone, Debug)]
pub struct ReflectiveRequest {
    /// The scene.toml the files were packed from.
    pub scene: PathBuf,
    pub preset: Option<String>,
    pub resolution: Option<(u32, u32)>,
    /// The packed files, each a representation.
    pub files: Vec<PathBuf>,
    /// Frames on the between and away paths.
    pub frames: usize,
    /// How the reference frames are traced.
    pub reference: ReferenceTrace,
    /// Where reflective.csv goes.
    pub out: PathBuf,
    /// Also write every played frame beside its traced reference as an sRGB PNG.
    pub images: bool,
    /// The objects measured: the scene's reflective objects, or its refractive (lens)
    /// objects.
    pub role: ObjectRole,
    /// The player's τ for lens objects (pixels).
    pub tau_px: f32,
    /// The march steps of depth shells, where not the files' (pis-play `--depth-steps`).
    pub depth_steps: Option<u32>,
}

/// One file on one path.
#[derive(Clone, Debug, Serialize)]
pub struct ReflectiveSummary {
    pub file: String,
    pub path: PathKind,
    pub mean_psnr_db: f64,
    pub min_psnr_db: f64,
    pub popping: f64,
    /// With a reference pair: over the path's frames pooled, the PSNR against the
    /// references' mean; the same with the references' own noise taken out (an estimate of
    /// the PSNR against the converged image; infinite, `null` in JSON, when the error is
    /// within that noise); and the references' mean's own noise as a PSNR (its variance;
    /// see [`PairedError`] for the bias of clamped display values, which stays in).
    pub pooled_psnr_db: Option<f64>,
    pub noise_removed_psnr_db: Option<f64>,
    pub reference_psnr_db: Option<f64>,
}

#[derive(Clone, Debug, Serialize)]
pub struct ReflectiveReport {
    pub scene: String,
    /// The objects measured (the scene's reflective objects).
    pub objects: Vec<String>,
    pub frames: usize,
    pub reference_spp: u32,
    /// `cell` or `sample`: what seeded the reference frames' shading.
    pub reference_seed: String,
    /// Whether each reference was traced twice from independent streams (its noise taken
    /// out of the figures: [`ReflectiveSummary::noise_removed_psnr_db`]).
    pub reference_pair: bool,
    /// How the reference frames were traced (samples, seeding, adaptive sampling, denoising).
    pub reference: String,
    pub summaries: Vec<ReflectiveSummary>,
    pub csv: String,
    pub stamp: Stamp,
}

/// A traced reference frame: linear RGB (with a pair, the mean of the two), the mask of
/// the measured objects' pixels, and with a pair the two renders.
struct Reference {
    rgb: Vec<f32>,
    mask: Vec<bool>,
    pair: Option<[Vec<f32>; 2]>,
}

/// The reference frame at `pf`, with the mask of the measured objects' pixels.
fn reference(
    req: &ReflectiveRequest,
    scene: &Scene,
    pf: &PathFrame,
    objects: &[usize],
) -> Result<Reference> {
    let f = req.reference.frame(scene, &pf.frame)?;
    let channels = pis_trace::channel_names(scene);
    let mut mask = vec![false; f.rgb.len() / 3];
    for &o in objects {
        if let Some(a) =
            f.images.object_layer(&channels[o], LayerKind::Coverage).and_then(|l| l.channel("A"))
        {
            mask.iter_mut().zip(a).for_each(|(m, &c)| *m |= c > 0.5);
        }
    }
    Ok(Reference { rgb: f.rgb, mask, pair: f.pair })
}

/// The player's camera for a path frame.
pub(crate) fn camera(scene: &Scene, pf: &PathFrame) -> ViewCamera {
    let c = &pf.frame.camera;
    let m = c.world_from_camera;
    let eye = m.w_axis.truncate();
    ViewCamera {
        eye,
        target: eye - m.z_axis.truncate(),
        up: m.y_axis.truncate().normalize_or(Vec3::Y),
        yfov_rad: c.yfov,
        near: c.znear,
        far: if c.zfar.is_finite() { c.zfar } else { 1.0e4_f32.max(scene.resolution.0 as f32) },
    }
}

/// The path frame's point in the dimensions' units: the view value between its samples,
/// the other dimensions at the frame's samples.
pub(crate) fn point(scene: &Scene, pf: &PathFrame, view_dim: usize) -> Vec<f32> {
    scene
        .space
        .dims
        .iter()
        .enumerate()
        .map(|(d, dim)| {
            if d == view_dim {
                let (k0, f) = (pf.view.floor() as usize, pf.view.fract());
                let k1 = (k0 + 1).min(dim.values.len() - 1);
                dim.values[k0] + (dim.values[k1] - dim.values[k0]) * f
            } else {
                dim.values[pf.point[d] as usize]
            }
        })
        .collect()
}

/// A played frame (left) beside its traced reference (right), sRGB.
fn side_by_side(played: &[f32], traced: &[f32], (w, h): (u32, u32)) -> image::RgbImage {
    let to8 = |v: f32| (display(v) * 255.0 + 0.5) as u8;
    image::RgbImage::from_fn(w * 2, h, |x, y| {
        let (src, x) = if x < w { (played, x) } else { (traced, x - w) };
        let p = (y * w + x) as usize * 3;
        image::Rgb([to8(src[p]), to8(src[p + 1]), to8(src[p + 2])])
    })
}

fn rms_change(a: &[f32], b: &[f32], mask: &[bool]) -> f64 {
    let (mut s, mut n) = (0.0f64, 0usize);
    for (p, _) in mask.iter().enumerate().filter(|(_, m)| **m) {
        for c in 0..3 {
            s += (display(a[p * 3 + c]) - display(b[p * 3 + c])).powi(2);
            n += 1;
        }
    }
    (s / n.max(1) as f64).sqrt()
}

/// The roles whose objects can be measured (`--role`), by [`role_name`].
pub const ROLES: [ObjectRole; 2] = [ObjectRole::Reflective, ObjectRole::Refractive];

/// The name `--role` takes.
pub fn role_name(role: ObjectRole) -> &'static str {
    match role {
        ObjectRole::Diffuse => "diffuse",
        ObjectRole::Reflective => "reflective",
        ObjectRole::Refractive => "refractive",
    }
}

fn runtime(e: impl Into<anyhow::Error>) -> Failure {
    Failure::new(Exit::Runtime, e.into())
}

/// One played file's frames along each path against the references: a CSV row per frame
/// and a summary per path.
fn measure(
    req: &ReflectiveRequest,
    name: &str,
    frames: &[PathFrame],
    refs: &[Reference],
    played: &[Vec<f32>],
    csv: &mut Csv,
    summaries: &mut Vec<ReflectiveSummary>,
) {
    for kind in PATHS {
        let idx: Vec<usize> = (0..frames.len()).filter(|&i| frames[i].kind == kind).collect();
        let (mut psnrs, mut popping, mut pooled) = (Vec::new(), 0.0f64, PairedError::default());
        for (j, &i) in idx.iter().enumerate() {
            // Against the gold standard (with a pair, the pair's mean), and between the
            // pair's renders: together the pair's error (`PairedError`).
            let (mut e, mut between) = (SquaredError::default(), SquaredError::default());
            for (p, _) in refs[i].mask.iter().enumerate().filter(|(_, m)| **m) {
                let k = p * 3..p * 3 + 3;
                e.add_slices(&played[i][k.clone()], &refs[i].rgb[k.clone()]);
                if let Some([a, b]) = &refs[i].pair {
                    between.add_slices(&a[k.clone()], &b[k]);
                }
            }
            let paired = PairedError { against_mean: e, between };
            pooled.merge(&paired);
            let paired_cells = match refs[i].pair {
                Some(_) => [
                    format!("{:.3}", paired.psnr_noise_removed()),
                    format!("{:.3}", paired.reference_psnr()),
                ],
                None => [String::new(), String::new()],
            };
            let change = (j > 0).then(|| {
                let prev = idx[j - 1];
                let both: Vec<bool> =
                    refs[i].mask.iter().zip(&refs[prev].mask).map(|(a, b)| *a && *b).collect();
                [
                    rms_change(&played[i], &played[prev], &both),
                    rms_change(&refs[i].rgb, &refs[prev].rgb, &both),
                ]
            });
            if let Some([p, r]) = change {
                popping = popping.max(p / r.max(0.5 / 255.0));
            }
            psnrs.push(e.psnr());
            csv.push(vec![
                name.to_string(),
                kind.name().into(),
                j.to_string(),
                format!("{:.3}", frames[i].view),
                format!("{:.3}", e.psnr()),
                change.map_or(String::new(), |c| format!("{:.5}", c[0])),
                change.map_or(String::new(), |c| format!("{:.5}", c[1])),
                paired_cells[0].clone(),
                paired_cells[1].clone(),
            ]);
        }
        let mean = psnrs.iter().sum::<f64>() / psnrs.len().max(1) as f64;
        let min = psnrs.iter().copied().fold(f64::INFINITY, f64::min);
        let pair = |v: f64| req.reference.pair.then_some(v);
        summaries.push(ReflectiveSummary {
            file: name.to_string(),
            path: kind,
            mean_psnr_db: mean,
            min_psnr_db: min,
            popping,
            pooled_psnr_db: pair(pooled.against_mean.psnr()),
            noise_removed_psnr_db: pair(pooled.psnr_noise_removed()),
            reference_psnr_db: pair(pooled.reference_psnr()),
        });
    }
}

/// Plays every file along both paths and measures it against the traced references.
pub fn run(req: &ReflectiveRequest) -> Result<ReflectiveReport, Failure> {
    if req.files.is_empty() || req.frames < 2 || req.reference.spp == 0 {
        return Err(Failure::new(
            Exit::Usage,
            anyhow!("give at least one file, --frames ≥ 2 and --spp ≥ 1"),
        ));
    }
    req.reference.check()?;
    let options = LoadOptions { preset: req.preset.clone(), resolution: req.resolution, spp: None };
    let scene = pis_scene::load_with(&req.scene, &options).map_err(|e| {
        Failure::new(pis_pack::scene_exit(&e), anyhow!("{}: {e}", req.scene.display()))
    })?;
    let objects: Vec<usize> = scene
        .objects
        .iter()
        .enumerate()
        .filter(|(_, o)| o.role == req.role)
        .map(|(i, _)| i)
        .collect();
    if objects.is_empty() {
        return Err(Failure::new(
            Exit::Usage,
            anyhow!("scene {} has no {} object", scene.name, role_name(req.role)),
        ));
    }
    let (view_dim, frames) =
        paths(&scene, req.frames, &PATHS).map_err(|e| Failure::new(Exit::NotSupported, e))?;
    req.reference.announce("reflective", frames.len());
    let refs: Vec<Reference> = frames
        .iter()
        .map(|f| reference(req, &scene, f, &objects))
        .collect::<Result<_>>()
        .map_err(runtime)?;
    let gpu = Arc::new(Gpu::new().map_err(|e| Failure::new(Exit::NotSupported, anyhow!("{e}")))?);
    let size = scene.resolution;
    let mut csv = Csv::new(&[
        "file",
        "path",
        "frame",
        "view",
        "psnr_db",
        "change_played",
        "change_reference",
        "psnr_noise_removed_db",
        "reference_psnr_db",
    ]);
    let mut summaries = Vec::new();
    for file in &req.files {
        let mut player = Player::open(
            gpu.clone(),
            file,
            PlayerOptions {
                tau_px: req.tau_px,
                depth_steps: req.depth_steps,
                ..PlayerOptions::default()
            },
        )
        .map_err(|e| Failure::new(Exit::Invalid, anyhow!("{}: {e}", file.display())))?;
        if player.image_size() != size {
            return Err(Failure::new(Exit::Usage, anyhow!("{}: {}x{} frames, the scene's are {}x{} (pass the same --preset or --resolution)", file.display(), player.image_size().0, player.image_size().1, size.0, size.1)));
        }
        let played: Vec<Vec<f32>> = frames
            .iter()
            .map(|pf| {
                let req = FrameRequest {
                    point: point(&scene, pf, view_dim),
                    camera: CameraChoice::Free(camera(&scene, pf)),
                };
                let (img, _) = player.render_image(&req, size)?;
                Ok(img.rgba.chunks_exact(4).flat_map(|p| [p[0], p[1], p[2]]).collect())
            })
            .collect::<Result<_, pis_play::PlayError>>()
            .map_err(runtime)?;
        let name = file
            .file_name()
            .map_or_else(|| file.display().to_string(), |n| n.to_string_lossy().into_owned());
        if req.images {
            std::fs::create_dir_all(&req.out)
                .map_err(|e| Failure::new(Exit::Io, anyhow!("{}: {e}", req.out.display())))?;
            for (i, (pf, pl)) in frames.iter().zip(&played).enumerate() {
                let j = frames[..i].iter().filter(|f| f.kind == pf.kind).count();
                let path = req.out.join(format!("{name}-{}-{j}.png", pf.kind.name()));
                side_by_side(pl, &refs[i].rgb, size)
                    .save(&path)
                    .map_err(|e| Failure::new(Exit::Io, anyhow!("{}: {e}", path.display())))?;
            }
        }
        measure(req, &name, &frames, &refs, &played, &mut csv, &mut summaries);
    }
    std::fs::create_dir_all(&req.out)
        .map_err(|e| Failure::new(Exit::Io, anyhow!("{}: {e}", req.out.display())))?;
    let csv_path = req.out.join("reflective.csv");
    crate::report::write_atomic(&csv_path, csv.text().as_bytes())
        .map_err(|e| Failure::new(Exit::Io, e))?;
    let scene_s = format!(
        "{} ({}x{}, {} views)",
        scene.name,
        size.0,
        size.1,
        scene.space.dims[view_dim].values.len()
    );
    Ok(ReflectiveReport {
        stamp: Stamp::here(&scene_s),
        scene: scene_s,
        objects: objects.iter().map(|&o| scene.objects[o].name.clone()).collect(),
        frames: req.frames,
        reference_spp: req.reference.spp,
        reference_seed: req.reference.seed.name().into(),
        reference_pair: req.reference.pair,
        reference: req.reference.describe(),
        summaries,
        csv: csv_path.display().to_string(),
    })
}

pub fn print(r: &ReflectiveReport, out: &mut impl std::io::Write) -> std::io::Result<()> {
    let pair = if r.reference_pair {
        ", each traced twice: the gold standard is their mean, its noise measured from their difference"
    } else {
        ""
    };
    writeln!(out, "reflective: {} — played frames vs pis-trace over the pixels of {}, {} frames between and away, references at {}{pair}", r.scene, r.objects.join(", "), r.frames, r.reference)?;
    for s in &r.summaries {
        write!(
            out,
            "  {:<28} {:<8} mean {:6.2} dB  min {:6.2} dB  popping {:5.2}",
            s.file,
            s.path.name(),
            s.mean_psnr_db,
            s.min_psnr_db,
            s.popping
        )?;
        if let (Some(pooled), Some(removed), Some(reference)) =
            (s.pooled_psnr_db, s.noise_removed_psnr_db, s.reference_psnr_db)
        {
            let removed = if removed.is_finite() {
                format!("{removed:6.2} dB")
            } else {
                "within the references' noise".to_string()
            };
            write!(out, "  pooled {pooled:6.2} dB  noise removed {removed}  (gold standard's noise {reference:.2} dB)")?;
        }
        writeln!(out)?;
    }
    writeln!(out, "  wrote {}", r.csv)
}
