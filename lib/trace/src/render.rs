//! Rendering one parameter point: camera samples over the Gaussian filter, rows in parallel,
//! accumulated in a fixed order so the result is byte-identical for any thread count.

use crate::adaptive::{check_half, first_round, next_round, pixel_error};
use crate::camera::PerspectiveCamera;
use crate::denoise::{DenoiseInput, PointDenoise};
use crate::error::TraceError;
use crate::integrator::{CameraSample, Integrator, PathContext};
use crate::layers::{resolve, resolve_guides, LayerImage, PixelAccum, PointImages};
use crate::records::{RayRecord, RecordHit};
use crate::sampling::{hash_keys, r2_point, Rng};
use crate::settings::TraceSettings;
use glam::Vec2;
use pis_scene::{Frame, ObjectRole, Scene};
use rayon::prelude::*;
use std::time::Instant;

/// One rendered row: its pixels, ray records, rays traced.
type RowResult = (Vec<PixelSamples>, Vec<RayRecord>, u64);

/// One pixel's camera samples.
struct PixelSamples {
    /// Every sample, summed in sample order.
    whole: PixelAccum,
    /// The even and the odd samples apart (kept for renders that denoise).
    halves: Option<[PixelAccum; 2]>,
    /// The estimated relative error when the pixel stopped ([`pixel_error`]).
    error: f32,
}

/// Seed stream of the odd half's sample positions (renders that keep their halves apart).
const ODD_HALF_STREAM: u64 = 0x0dd_5a3b1e;

/// Image rows per parallel work unit (they share the first-hit irradiance cache).
pub const BAND_ROWS: u32 = 8;

/// Counters of one render.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RenderStats {
    /// Primary rays.
    pub camera_rays: u64,
    /// All rays (primary, shadow, secondary).
    pub total_rays: u64,
    /// World triangles in the BVH.
    pub triangles: u64,
    /// Seconds spent building the BVH.
    pub build_seconds: f64,
    /// Seconds spent tracing.
    pub trace_seconds: f64,
}

/// The result of rendering one parameter point.
#[derive(Clone, Debug)]
pub struct PointRender {
    pub images: PointImages,
    /// Outgoing-ray records of refractive lens objects, in pixel and sample order.
    pub records: Vec<RayRecord>,
    pub stats: RenderStats,
    /// Adaptive renders: each pixel's camera samples (`samples.Y`) and its estimated
    /// relative error when it stopped (`error.Y`).
    pub sampling: Option<[LayerImage; 2]>,
    /// Renders that denoise: the guides (`guide.albedo`, `guide.normal`) and the images of
    /// the even and of the odd samples apart.
    pub denoise_input: Option<Box<DenoiseInput>>,
    /// What denoising did, once the point's images carry their `denoised.` twins.
    pub denoised: Option<PointDenoise>,
}

/// Channel-safe, unique object names: characters other than `[A-Za-z0-9_-]` become `_`,
/// empty names become `object<i>`, and repeats get `_<i>` appended.
pub fn channel_names(scene: &Scene) -> Vec<String> {
    let mut out: Vec<String> = Vec::with_capacity(scene.objects.len());
    for (i, o) in scene.objects.iter().enumerate() {
        let mut s: String = o
            .name
            .chars()
            .map(|c| if c.is_ascii_alphanumeric() || c == '_' || c == '-' { c } else { '_' })
            .collect();
        if s.is_empty() {
            s = format!("object{i}");
        }
        if out.contains(&s) {
            s = format!("{s}_{i}");
        }
        out.push(s);
    }
    out
}

/// Every object's channel name ([`channel_names`]) and role, in scene order.
pub fn object_channels(scene: &Scene) -> Vec<(String, ObjectRole)> {
    channel_names(scene).into_iter().zip(scene.objects.iter().map(|o| o.role)).collect()
}

/// Renders `scene` at `frame`. `row_done` is called once per finished image row (from any
/// thread), for progress display. Runs on the current rayon pool.
pub fn render_point(
    scene: &Scene,
    frame: &Frame,
    settings: &TraceSettings,
    row_done: &(dyn Fn() + Sync),
) -> Result<PointRender, TraceError> {
    let (w, h) = settings.resolution;
    if w == 0 || h == 0 {
        return Err(TraceError::InvalidInput(format!("resolution {w}x{h} has no pixels")));
    }
    if settings.spp == 0 {
        return Err(TraceError::InvalidInput("0 samples per pixel".into()));
    }
    if frame.instances.len() != scene.objects.len() {
        return Err(TraceError::InvalidInput(format!(
            "frame places {} objects, the scene has {}",
            frame.instances.len(),
            scene.objects.len()
        )));
    }
    let t0 = Instant::now();
    let integrator = Integrator::new(scene, frame, settings);
    let build_seconds = t0.elapsed().as_secs_f64();
    let camera = PerspectiveCamera::new(&frame.camera, settings.resolution);
    let t1 = Instant::now();
    // Bands of rows are the parallel unit: each band renders its rows in order with one
    // path context (and so one first-hit irradiance cache), so the result does not depend
    // on how bands are spread over threads.
    let bands: Vec<Vec<RowResult>> = (0..h.div_ceil(BAND_ROWS))
        .into_par_iter()
        .map(|b| {
            let mut ctx = PathContext::default();
            (b * BAND_ROWS..((b + 1) * BAND_ROWS).min(h))
                .map(|y| {
                    let row = render_row(&integrator, &camera, settings, y, &mut ctx);
                    row_done();
                    row
                })
                .collect()
        })
        .collect();
    let rows: Vec<RowResult> = bands.into_iter().flatten().collect();
    let trace_seconds = t1.elapsed().as_secs_f64();
    let mut pixels = Vec::with_capacity(w as usize * h as usize);
    let mut records = Vec::new();
    let mut total_rays = 0;
    for (p, r, n) in rows {
        pixels.extend(p);
        records.extend(r);
        total_rays += n;
    }
    let objects = object_channels(scene);
    let sampling = settings.adaptive().then(|| sampling_maps(&pixels, w, h));
    let (mut whole, mut even, mut odd) = (Vec::with_capacity(pixels.len()), Vec::new(), Vec::new());
    for p in pixels {
        whole.push(p.whole);
        if let Some([a, b]) = p.halves {
            even.push(a);
            odd.push(b);
        }
    }
    let terms = settings.lens_model.terms();
    let images = resolve(&whole, w, h, &objects, terms);
    let denoise_input = settings.denoise.then(|| {
        Box::new(DenoiseInput {
            guides: resolve_guides(&whole, w, h),
            halves: [resolve(&even, w, h, &objects, terms), resolve(&odd, w, h, &objects, terms)],
        })
    });
    let stats = RenderStats {
        camera_rays: whole.iter().map(|p| p.samples as u64).sum(),
        total_rays,
        triangles: integrator.geometry.triangle_count() as u64,
        build_seconds,
        trace_seconds,
    };
    Ok(PointRender { images, records, stats, sampling, denoise_input, denoised: None })
}

/// `samples.Y` and `error.Y` of an adaptive render.
fn sampling_maps(pixels: &[PixelSamples], w: u32, h: u32) -> [LayerImage; 2] {
    let mut samples = LayerImage::new("samples".into(), &["Y"], w, h);
    let mut error = LayerImage::new("error".into(), &["Y"], w, h);
    for (i, p) in pixels.iter().enumerate() {
        samples.planes[0][i] = p.whole.samples as f32;
        error.planes[0][i] = p.error;
    }
    [samples, error]
}

/// The outgoing-ray records of a camera sample through image position `pos`.
fn push_records(records: &mut Vec<RayRecord>, sample: &CameraSample, pos: Vec2) {
    let (Some(o), Some(terms)) = (sample.object, &sample.lens) else { return };
    for (k, t) in terms.iter().enumerate() {
        let Some((eo, ed)) = t.exit else { continue };
        records.push(RayRecord {
            object: o,
            term: k as u8,
            pixel: pos.to_array(),
            exit_origin: eo.to_array(),
            exit_direction: ed.to_array(),
            modulation: t.modulation.to_array(),
            hits: t
                .hits
                .iter()
                .map(|h| RecordHit {
                    t: h.t,
                    position: h.position.to_array(),
                    object: h.object,
                    colour: h.colour.to_array(),
                })
                .collect(),
        });
    }
}

fn render_row(
    integrator: &Integrator,
    camera: &PerspectiveCamera,
    settings: &TraceSettings,
    y: u32,
    ctx: &mut PathContext,
) -> RowResult {
    let rays_before = ctx.rays;
    let w = settings.resolution.0;
    let mut pixels = Vec::with_capacity(w as usize);
    let mut records = Vec::new();
    for x in 0..w {
        let pixel_seed = match settings.seed {
            0 => hash_keys(&[x as u64, y as u64]),
            seed => hash_keys(&[x as u64, y as u64, seed]),
        };
        let shift = Rng::new(pixel_seed).next_2d();
        let adaptive = settings.adaptive();
        // A render that compares halves of its samples (the stopping rule's, the
        // denoiser's) takes them from two independently rotated sequences (even samples on
        // one, odd on the other), so that their difference measures the error of the
        // whole: halves of one low-discrepancy sequence differ by more than its error.
        let two_sequences = adaptive || settings.denoise;
        let odd_shift = Rng::new(hash_keys(&[pixel_seed, ODD_HALF_STREAM])).next_2d();
        let position = |s: u32| match (two_sequences, s % 2) {
            (false, _) => r2_point(s, shift),
            (true, 0) => r2_point(s / 2, shift),
            (true, _) => r2_point(s / 2, odd_shift),
        };
        let mut whole = PixelAccum::default();
        let mut halves: [PixelAccum; 2] = Default::default();
        // The stopping rule's halves, apart from the denoiser's (adaptive.rs).
        let mut checks: [PixelAccum; 2] = Default::default();
        let mut end = first_round(settings.spp, settings.min_spp, adaptive);
        let mut s = 0;
        let error = loop {
            while s < end {
                let offset = settings.filter.sample_offset(position(s));
                let pos = Vec2::new(x as f32 + 0.5, y as f32 + 0.5) + offset;
                let dir = camera.direction(pos);
                ctx.fallback_seed = hash_keys(&[pixel_seed, s as u64]);
                let record = s < settings.records_per_pixel;
                let sample = integrator.camera_sample(camera.origin, dir, record, ctx);
                if record {
                    push_records(&mut records, &sample, pos);
                }
                whole.add(&sample);
                if settings.denoise {
                    halves[(s % 2) as usize].add(&sample);
                }
                if adaptive {
                    checks[check_half(s)].add(&sample);
                }
                s += 1;
            }
            let error = if adaptive { pixel_error(&checks) } else { 0.0 };
            if end >= settings.spp || error < settings.noise_threshold {
                break error;
            }
            end = next_round(end, settings.spp);
        };
        let halves = settings.denoise.then_some(halves);
        pixels.push(PixelSamples { whole, halves, error });
    }
    (pixels, records, ctx.rays - rays_before)
}
