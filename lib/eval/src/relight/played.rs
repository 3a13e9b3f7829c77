//! Packed files played under the lights of each point of a held-out set: a relightable file
//! relit by superposition (one directional light from another direction, two coloured
//! lights, a sky); a file that samples the light at its sample nearest a held-out direction.
//! Where the held-out set moves its light continuously (an arc), the frames' largest change
//! from one light step to the next against the set's own: popping.

use std::path::{Path, PathBuf};

use anyhow::{anyhow, Context, Result};
use glam::Vec3;
use pis_play::{CameraChoice, FrameRequest, Gpu, Player, PlayerOptions};
use pis_trace::set::RaySet;

use super::held::{others, HeldLights, Placement};
use super::HeldOutRow;
use crate::metrics::SquaredError;

/// The decoded level images the bench's player may hold (4 GiB).
const RELIT_CACHE_BYTES: u64 = 4 << 30;

/// Each of `files` played at every point of `held`, its other dimensions at their samples;
/// `placement` places the held-out set's point or sphere lights as the files' traced light.
pub fn held_out(
    files: &[PathBuf],
    held: &Path,
    placement: Option<&Placement>,
) -> Result<Vec<HeldOutRow>> {
    let set = RaySet::open(held).context("the held-out set")?;
    let gpu = std::sync::Arc::new(Gpu::new()?);
    let mut rows = Vec::new();
    for file in files {
        // A relightable file's frame sums every coefficient texture of its layers: at
        // 640×480 with four views that is more than the player's default cache holds.
        let options = PlayerOptions {
            display_filter: crate::headless::set_display_filter(held),
            cache_budget_bytes: RELIT_CACHE_BYTES,
            ..PlayerOptions::default()
        };
        let mut player = Player::open(gpu.clone(), file, options)
            .with_context(|| format!("{}", file.display()))?;
        rows.push(play_file(&mut player, file, &set, placement)?);
    }
    Ok(rows)
}

fn play_file(
    player: &mut Player,
    file: &Path,
    set: &RaySet,
    placement: Option<&Placement>,
) -> Result<HeldOutRow> {
    let c = player.reader().container();
    let file_lights = pis_format::relight::light_directions(c.provenance.as_ref(), &c.space)
        .map_err(|e| anyhow!("{}: {e}", file.display()))?
        .ok_or_else(|| anyhow!("{}: records no light directions", file.display()))?;
    let relightable = c.objects.iter().flat_map(|o| &o.layers).any(|l| l.basis != 0);
    let k = file_lights.dim;
    let values = c.space.dims.get(k).map(|d| d.values.clone()).unwrap_or_default();
    let lights = HeldLights::of(set, file_lights.radiance, placement)?;
    let mut row = HeldOutRow {
        file: file.display().to_string(),
        bytes: std::fs::metadata(file)?.len(),
        relightable,
        psnr_db: None,
        points_db: Vec::new(),
        largest_step_db: None,
    };
    let continuous = continuous(&lights);
    let mut steps = Steps::default();
    if !relightable && lights.dim.is_none() {
        // One sampled light cannot show the held-out set's lights.
        return Ok(row);
    }
    let size = player.image_size();
    let mut whole = SquaredError::default();
    for (i, p) in set.meta.points.iter().enumerate() {
        let mut point = p.values.clone();
        if lights.dim.is_none() {
            point.insert(k.min(point.len()), values.first().copied().unwrap_or(0.0));
        }
        if relightable {
            player.set_lights(Some(lights.points[i].clone()))?;
        } else {
            let w = lights.points[i].directional[0].direction;
            let near = (0..file_lights.directions.len())
                .max_by(|&a, &b| {
                    let d = |j: usize| Vec3::from(file_lights.directions[j]).dot(w);
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
        row.points_db.push(one.psnr());
        if continuous {
            let rgb: Vec<f32> = img.rgba.chunks_exact(4).flat_map(|p| [p[0], p[1], p[2]]).collect();
            steps.next(others(&p.samples, lights.dim.as_ref().map(|d| d.0)), rgb);
        }
    }
    row.psnr_db = Some(whole.psnr());
    row.largest_step_db = continuous.then_some(steps.largest_db);
    Ok(row)
}

/// Whether the held-out set's light moves continuously: a light dimension whose
/// consecutive directions lie within 10° of each other.
pub fn continuous(lights: &HeldLights) -> bool {
    lights.dim.as_ref().is_some_and(|(_, dirs)| {
        dirs.len() > 1 && dirs.windows(2).all(|w| w[0].angle_between(w[1]) < 10f32.to_radians())
    })
}

/// The largest change from one frame to the next of the same other samples (the smallest
/// PSNR between consecutive frames, dB).
struct Steps {
    last: Option<(Vec<u32>, Vec<f32>)>,
    largest_db: f64,
}

impl Default for Steps {
    fn default() -> Steps {
        Steps { last: None, largest_db: f64::INFINITY }
    }
}

impl Steps {
    fn next(&mut self, group: Vec<u32>, rgb: Vec<f32>) {
        if let Some((g, prev)) = &self.last {
            if *g == group {
                let mut e = SquaredError::default();
                e.add_slices(&rgb, prev);
                self.largest_db = self.largest_db.min(e.psnr());
            }
        }
        self.last = Some((group, rgb));
    }
}

/// The held-out set's own largest step where its light moves continuously.
pub fn reference_step(held: &Path) -> Result<Option<f64>> {
    let set = RaySet::open(held).context("the held-out set")?;
    if super::held::light_dimension(&set)?.is_none() {
        return Ok(None);
    }
    let lights = HeldLights::of(&set, [1.0; 3], None)?;
    if !continuous(&lights) {
        return Ok(None);
    }
    let mut steps = Steps::default();
    for (i, p) in set.meta.points.iter().enumerate() {
        let images = set.read_point(i)?;
        let c = images.layer("combined").ok_or_else(|| anyhow!("point {i}: no combined"))?;
        let n = c.planes[0].len();
        let rgb = (0..n * 3).map(|v| c.planes[v % 3][v / 3]).collect();
        steps.next(others(&p.samples, lights.dim.as_ref().map(|d| d.0)), rgb);
    }
    Ok(Some(steps.largest_db))
}
