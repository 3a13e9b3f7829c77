//! How well a set traced over light directions can be relit at all (seed 003): each pixel of
//! the traced set fitted to the spherical harmonics up to a band, losslessly (no texture, no
//! coding), and drawn at the directions of a second set traced at directions the first does
//! not hold. This is the truncation's own ceiling that any stored form of the fit stays
//! under; beside it, the sampled dimension's answer at those directions (the image of the
//! nearest sampled direction), which is what a file that samples the light can show.

use std::path::Path;

use anyhow::{anyhow, bail, Context, Result};
use glam::Vec3;
use pis_compile::relight::{basis, coefficients, Cover, LightFit};
use pis_trace::set::RaySet;
use serde::Serialize;

use crate::metrics::SquaredError;

/// One band's figure, or the nearest sampled direction's (`band` `None`).
#[derive(Clone, Debug, Serialize)]
pub struct CeilingRow {
    pub band: Option<u32>,
    pub coefficients: usize,
    /// Whole image at the held-out directions, display PSNR (dB).
    pub held_out_db: f64,
    /// Whole image at the set's own directions.
    pub samples_db: f64,
}

/// The light dimension of a set: its index and its directions.
fn light_dimension(set: &RaySet) -> Result<(usize, Vec<Vec3>)> {
    let (k, d) = set
        .meta
        .space
        .iter()
        .enumerate()
        .find(|(_, d)| d.driver == "light_direction")
        .ok_or_else(|| anyhow!("{}: no light_direction dimension", set.dir.display()))?;
    let dirs = d.directions.as_ref().ok_or_else(|| {
        anyhow!("{}: dimension `{}` records no directions", set.dir.display(), d.name)
    })?;
    Ok((k, dirs.iter().map(|&w| Vec3::from(w)).collect()))
}

/// The combined images of the points whose other samples are `others` (the light
/// dimension `k` left free), in light-sample order.
fn images_over_light(set: &RaySet, k: usize, others: &[u32]) -> Result<Vec<Vec<f32>>> {
    let mut out = Vec::new();
    for (i, p) in set.meta.points.iter().enumerate() {
        let rest: Vec<u32> =
            p.samples.iter().enumerate().filter(|(j, _)| *j != k).map(|(_, s)| *s).collect();
        if rest == others {
            let images = set.read_point(i)?;
            let c = images.layer("combined").ok_or_else(|| anyhow!("point {i}: no combined"))?;
            let n = c.planes[0].len();
            out.push((0..n * 3).map(|v| c.planes[v % 3][v / 3]).collect());
        }
    }
    Ok(out)
}

/// The ceiling table of `set` (fitted) against `held` (the same scene and other
/// dimensions, other light directions), for each band in `bands`.
pub fn ceiling(set: &Path, held: &Path, bands: &[u32], cover: Cover) -> Result<Vec<CeilingRow>> {
    let set = RaySet::open(set).context("the fitted set")?;
    let held = RaySet::open(held).context("the held-out set")?;
    let (k, dirs) = light_dimension(&set)?;
    let (hk, held_dirs) = light_dimension(&held)?;
    if k != hk || set.meta.space.len() != held.meta.space.len() {
        bail!("the two sets' parameter spaces differ");
    }
    let others: Vec<Vec<u32>> = {
        let mut o: Vec<Vec<u32>> = set
            .meta
            .points
            .iter()
            .map(|p| {
                p.samples.iter().enumerate().filter(|(j, _)| *j != k).map(|(_, s)| *s).collect()
            })
            .collect();
        o.sort();
        o.dedup();
        o
    };
    let fits: Vec<Option<LightFit>> =
        bands.iter().map(|&b| LightFit::new(b, &dirs, cover)).collect();
    let mut errors = vec![(SquaredError::default(), SquaredError::default()); bands.len() + 1];
    for rest in &others {
        let fitted = images_over_light(&set, k, rest)?;
        let truth = images_over_light(&held, k, rest)?;
        let clamp: f32 =
            std::env::var("PIS_CLAMP").ok().and_then(|v| v.parse().ok()).unwrap_or(f32::INFINITY);
        let clamped: Vec<Vec<f32>> =
            fitted.iter().map(|v| v.iter().map(|x| x.min(clamp)).collect()).collect();
        let refs: Vec<&[f32]> = clamped.iter().map(|v| v.as_slice()).collect();
        for (row, fit) in fits.iter().enumerate() {
            let Some(fit) = fit else { continue };
            let x = fit.project(&refs);
            let c = coefficients(fit.l_max);
            let mut y = vec![0.0; c];
            for (targets, ds, at) in [(&truth, &held_dirs, 0), (&fitted, &dirs, 1)] {
                for (t, w) in targets.iter().zip(ds) {
                    basis(fit.l_max, *w, &mut y);
                    let img: Vec<f32> = (0..t.len())
                        .map(|v| {
                            x.iter().zip(&y).map(|(xc, yc)| xc[v] as f64 * yc).sum::<f64>() as f32
                        })
                        .collect();
                    let e = if at == 0 { &mut errors[row].0 } else { &mut errors[row].1 };
                    e.add_slices(&img, t);
                }
            }
        }
        // The nearest sampled direction's image.
        for (t, w) in truth.iter().zip(&held_dirs) {
            let near = (0..dirs.len()).max_by(|&a, &b| dirs[a].dot(*w).total_cmp(&dirs[b].dot(*w)));
            errors[bands.len()].0.add_slices(&fitted[near.unwrap_or(0)], t);
        }
    }
    let mut rows: Vec<CeilingRow> = bands
        .iter()
        .zip(&fits)
        .zip(&errors)
        .filter(|((_, f), _)| f.is_some())
        .map(|((&b, _), (h, s))| CeilingRow {
            band: Some(b),
            coefficients: coefficients(b),
            held_out_db: h.psnr(),
            samples_db: s.psnr(),
        })
        .collect();
    rows.push(CeilingRow {
        band: None,
        coefficients: 0,
        held_out_db: errors[bands.len()].0.psnr(),
        samples_db: f64::INFINITY,
    });
    Ok(rows)
}

/// One file played at a held-out set's light directions.
#[derive(Clone, Debug, Serialize)]
pub struct HeldOutRow {
    pub file: String,
    pub bytes: u64,
    /// Whether the file relights (its layers span the light directions), else it shows the
    /// sampled light nearest each direction.
    pub relightable: bool,
    /// Whole image against the held-out set, display PSNR (dB).
    pub psnr_db: f64,
    /// Per held-out point, display PSNR (dB).
    pub points_db: Vec<f64>,
}

/// Each of `files` played at every point of `held` (a set traced at light directions the
/// files do not hold, the other dimensions at their samples): a relightable file under one
/// directional light from the point's direction, of the file's traced radiance; a file that
/// samples the light at its sample nearest that direction.
pub fn held_out(files: &[std::path::PathBuf], held: &Path) -> Result<Vec<HeldOutRow>> {
    use pis_play::{CameraChoice, DirectionalLight, FrameRequest, Gpu, Player, PlayerOptions};
    let set = RaySet::open(held).context("the held-out set")?;
    let (k, dirs) = light_dimension(&set)?;
    let gpu = std::sync::Arc::new(Gpu::new()?);
    let mut rows = Vec::new();
    for file in files {
        let options = PlayerOptions {
            display_filter: crate::headless::set_display_filter(held),
            ..PlayerOptions::default()
        };
        let mut player = Player::open(gpu.clone(), file, options)
            .with_context(|| format!("{}", file.display()))?;
        let c = player.reader().container();
        let lights = pis_format::relight::light_directions(c.provenance.as_ref(), &c.space)
            .map_err(|e| anyhow!("{}: {e}", file.display()))?
            .ok_or_else(|| anyhow!("{}: records no light directions", file.display()))?;
        let relightable = c.objects.iter().flat_map(|o| &o.layers).any(|l| l.basis != 0);
        let values = c.space.dims.get(k).map(|d| d.values.clone()).unwrap_or_default();
        let size = player.image_size();
        let (mut whole, mut points_db) = (SquaredError::default(), Vec::new());
        for (i, p) in set.meta.points.iter().enumerate() {
            let w = dirs[p.samples[k] as usize];
            let mut point = p.values.clone();
            if relightable {
                let light = DirectionalLight { direction: w, radiance: lights.radiance };
                player.set_lights(Some(vec![light]))?;
            } else {
                let near = (0..lights.directions.len())
                    .max_by(|&a, &b| {
                        let d = |j: usize| Vec3::from(lights.directions[j]).dot(w);
                        d(a).total_cmp(&d(b))
                    })
                    .unwrap_or(0);
                point[k] = values.get(near).copied().unwrap_or(0.0);
            }
            let req = FrameRequest { point, camera: CameraChoice::Sample };
            let (img, _) = player.render_image(&req, size)?;
            let images = set.read_point(i)?;
            let gold = images.layer("combined").ok_or_else(|| anyhow!("point {i}: no combined"))?;
            let mut one = SquaredError::default();
            for (px, rgba) in img.rgba.chunks_exact(4).enumerate() {
                for (v, plane) in rgba.iter().zip(&gold.planes).take(3) {
                    one.add(*v, plane[px]);
                }
            }
            whole.merge(&one);
            points_db.push(one.psnr());
        }
        rows.push(HeldOutRow {
            file: file.display().to_string(),
            bytes: std::fs::metadata(file)?.len(),
            relightable,
            psnr_db: whole.psnr(),
            points_db,
        });
    }
    Ok(rows)
}

/// What `pis-bench relight` measured.
#[derive(Clone, Debug, Serialize)]
pub struct RelightReport {
    pub ceiling: Option<Vec<CeilingRow>>,
    pub played: Vec<HeldOutRow>,
}

/// [`ceiling`] with the cover the fitted set's directions span (the upper hemisphere, or
/// the sphere where a direction lies below the horizon).
pub fn ceiling_of(set: &Path, held: &Path, bands: &[u32]) -> Result<Vec<CeilingRow>> {
    let (_, dirs) = light_dimension(&RaySet::open(set).context("the fitted set")?)?;
    let cover =
        if dirs.iter().any(|w| w.y < -1e-6) { Cover::Sphere } else { Cover::Hemisphere(Vec3::Y) };
    ceiling(set, held, bands, cover)
}

/// The report as text.
pub fn render(r: &RelightReport) -> String {
    let mut out = String::new();
    if let Some(rows) = &r.ceiling {
        out.push_str(
            "the set's pixels fitted per band, at the held-out directions (at its own):\n",
        );
        for row in rows {
            match row.band {
                Some(b) => out.push_str(&format!(
                    "  band {b} ({:>2} coefficients)  {:6.2} dB  ({:.2} dB)\n",
                    row.coefficients, row.held_out_db, row.samples_db
                )),
                None => out.push_str(&format!(
                    "  nearest sampled direction      {:6.2} dB\n",
                    row.held_out_db
                )),
            }
        }
    }
    out.push_str("played at the held-out directions:\n");
    for row in &r.played {
        let how = if row.relightable { "relit" } else { "nearest sample" };
        out.push_str(&format!(
            "  {}  {} bytes, {how}: {:.2} dB\n",
            row.file, row.bytes, row.psnr_db
        ));
    }
    out
}
