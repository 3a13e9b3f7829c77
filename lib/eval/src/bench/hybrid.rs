//! `pis-bench hybrid`: the CPU half of hybrid rendering's frame (thesis 6.4, table 6.1) on a
//! scene's lens objects along the camera path between its sampled views: per τ, the
//! vertex rays of the greedy two-path model traced through the lens object alone, the
//! vertices and triangles of the adaptive tessellation, the milliseconds for tracing,
//! tessellating and generating one shell's cube vectors per term; against the same model
//! traced at every pixel centre the lens object covers (the same code, one path pair per
//! pixel), in rays and milliseconds; and how far the interpolated vectors of a far sphere
//! shell are from those traced at each pixel (the 90th percentile of the angle). Given a
//! file packed from the scene, also the whole frame as the player draws it at each τ on the
//! same cameras: its lens objects' CPU work, the draw (recorded, submitted and finished on
//! the GPU) and the frame.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{anyhow, Result};
use glam::{DVec3, Vec2, Vec3};
use pis_compile::hybrid::{
    hybrid_pixels, lens_paths, shell_vector, tessellate_timed, vertex_vectors, HybridView,
    LensModel, LensObject, Missing, TessellationSettings, TERMS,
};
use pis_compile::shell::geometry::{Shell, ShellShape};
use pis_compile::Viewport;
use pis_play::lens_rays::{vertex_tracer, GpuRays, LensRayPipeline};
use pis_scene::{LoadOptions, ObjectRole};
use pis_trace::camera::{projection_matrix, PerspectiveCamera};
use rayon::prelude::*;
use serde::Serialize;
use std::sync::Arc;

use super::camera_path::{paths, PathKind};
use crate::report::Stamp;
use pis_pack::{Exit, Failure};

/// What to measure.
#[derive(Clone, Debug)]
pub struct HybridRequest {
    pub scene: PathBuf,
    pub preset: Option<String>,
    pub resolution: Option<(u32, u32)>,
    /// τ values (pixels) to tessellate with.
    pub taus: Vec<f32>,
    /// Frames on the path between the sampled views.
    pub frames: usize,
    /// A file packed from the scene (its lens objects by hybrid rendering), played at each τ.
    pub file: Option<PathBuf>,
    /// The player's samples per pixel for `file`.
    pub msaa: u32,
    /// Where the vertex rays are traced (the tessellation table and the played frames).
    pub lens_rays: pis_play::LensRays,
}

/// The player's frame at one τ, means over the frames.
#[derive(Clone, Debug, Serialize)]
pub struct PlayedRow {
    pub tau_px: f32,
    /// Lens objects' vertex rays, tessellation and vertex buffers.
    pub lens_ms: f64,
    pub lens_rays: f64,
    pub decode_ms: f64,
    pub draw_ms: f64,
    pub frame_ms: f64,
    /// The per-pixel tracing of the lens objects (summed) over the whole frame.
    pub frame_reduction: f64,
}

/// One lens object at one τ, means over the frames.
#[derive(Clone, Debug, Serialize)]
pub struct HybridRow {
    pub object: String,
    pub tau_px: f32,
    pub vertex_rays: f64,
    pub traced_vertices: f64,
    pub front_triangles: f64,
    pub triangles: f64,
    pub trace_ms: f64,
    pub tessellate_ms: f64,
    /// Cube vectors of one shell per term at every vertex.
    pub texgen_ms: f64,
    /// trace + tessellate + texgen.
    pub cpu_ms: f64,
    /// Against the per-pixel tracing: rays and time divided by these.
    pub ray_reduction: f64,
    pub time_reduction: f64,
    /// 90th percentile over the drawn pixels of the angle between the interpolated and the
    /// per-pixel traced vector of a far sphere shell, per term (reflection-first,
    /// refraction-first), degrees.
    pub p90_angle_deg: [f64; 2],
}

/// The same model traced at every pixel centre the lens object covers.
#[derive(Clone, Debug, Serialize)]
pub struct PixelTracing {
    pub object: String,
    pub pixels: f64,
    pub rays: f64,
    pub ms: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct HybridReport {
    pub scene: String,
    pub size: [u32; 2],
    pub frames: usize,
    pub threads: usize,
    pub per_pixel: Vec<PixelTracing>,
    pub rows: Vec<HybridRow>,
    /// With a file: the played frame per τ, its adapter and samples per pixel.
    pub played: Vec<PlayedRow>,
    pub adapter: Option<String>,
    pub msaa: u32,
    /// Where the vertex rays were traced: `gpu` (and on which adapter) or `workers`.
    pub lens_rays: String,
    pub stamp: Stamp,
}

/// Per pixel covered by the lens object, the two terms' paths through its centre; with the
/// rays cast.
fn trace_pixels(
    lens: &LensObject,
    camera: &PerspectiveCamera,
    size: (u32, u32),
    max_depth: u32,
) -> (Vec<Option<[Option<pis_compile::hybrid::LensPath>; 2]>>, u64) {
    let out: Vec<(Option<[Option<pis_compile::hybrid::LensPath>; 2]>, u64)> = (0..size.0 * size.1)
        .into_par_iter()
        .map(|p| {
            let centre = Vec2::new((p % size.0) as f32 + 0.5, (p / size.0) as f32 + 0.5);
            let dir = camera.direction(centre);
            let Some(hit) = lens.closest(camera.origin, dir, f32::INFINITY) else {
                return (None, 1);
            };
            let first = lens.surface(&hit, camera.origin, dir);
            let [r, t, ..] = lens_paths(lens, &first, dir, LensModel::Greedy, max_depth);
            let paths = [r, t];
            let rays = 1 + paths
                .iter()
                .map(|p| p.map_or(0, |p| p.topology.interfaces as u64))
                .sum::<u64>();
            (Some(paths), rays)
        })
        .collect();
    let rays = out.iter().map(|o| o.1).sum();
    (out.into_iter().map(|o| o.0).collect(), rays)
}

fn percentile(mut v: Vec<f64>, f: f64) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    v[((v.len() - 1) as f64 * f).round() as usize]
}

/// The device and pipeline that trace the vertex rays where `choice` resolves to the GPU
/// for this machine's adapter; `None`: on the workers. The pipeline is compiled and run
/// once here, so that no tessellation pays for it.
fn gpu_tracing(choice: pis_play::LensRays) -> Result<Option<GpuRays>, Failure> {
    if choice == pis_play::LensRays::Workers {
        return Ok(None);
    }
    let gpu = match pis_play::Gpu::new() {
        Ok(g) => Arc::new(g),
        Err(e) if choice == pis_play::LensRays::Gpu => {
            return Err(Failure::new(Exit::NotSupported, anyhow!("--lens-rays gpu: {e}")))
        }
        Err(_) => return Ok(None),
    };
    if choice.on(gpu.info.device_type) != pis_play::LensRays::Gpu {
        return Ok(None);
    }
    let pipeline = Arc::new(LensRayPipeline::new(&gpu));
    // One vertex of a tetrahedron traced: the driver compiles the shader here.
    let corners = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z];
    let material =
        pis_compile::hybrid::LensMaterial { ior: 1.5, base: Vec3::ONE, sigma_a: Vec3::ZERO };
    let tetra = LensObject::new(material, corners, vec![], &[0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3]);
    let ray =
        pis_compile::hybrid::VertexRay { position: Vec3::X, normal: Vec3::ONE, front_face: true };
    let gpu_rays = (gpu, pipeline);
    vertex_tracer(Some(&gpu_rays), &tetra).trace(
        &tetra,
        Vec3::splat(2.0),
        &[ray],
        LensModel::Greedy,
        8,
    );
    Ok(Some(gpu_rays))
}

/// The scene's lens objects (at least one), once the request's τ are checked.
fn lenses(scene: &pis_scene::Scene, req: &HybridRequest) -> Result<Vec<usize>, Failure> {
    let lenses: Vec<usize> = scene
        .objects
        .iter()
        .enumerate()
        .filter(|(_, o)| o.role == ObjectRole::Refractive)
        .map(|(i, _)| i)
        .collect();
    if lenses.is_empty() {
        return Err(Failure::new(
            Exit::Usage,
            anyhow!("{}: no refractive (lens) object to measure", req.scene.display()),
        ));
    }
    if req.taus.is_empty() || req.taus.iter().any(|t| !(t.is_finite() && *t > 0.0)) {
        return Err(Failure::new(Exit::Usage, anyhow!("--tau: give positive values in pixels")));
    }
    Ok(lenses)
}

pub fn run(req: &HybridRequest) -> Result<HybridReport, Failure> {
    let options = LoadOptions { preset: req.preset.clone(), resolution: req.resolution, spp: None };
    let scene = pis_scene::load_with(&req.scene, &options).map_err(|e| {
        Failure::new(pis_pack::scene_exit(&e), anyhow!("{}: {e}", req.scene.display()))
    })?;
    let lenses = lenses(&scene, req)?;
    let (_, frames) = paths(&scene, req.frames.max(1), &[PathKind::Between])
        .map_err(|e| Failure::new(Exit::Usage, e))?;
    let size = scene.resolution;
    let viewport = Viewport { width: size.0, height: size.1 };
    let max_depth = pis_trace::TraceSettings::new(size, 1).max_depth;
    let n = frames.len() as f64;
    let gpu_rays = gpu_tracing(req.lens_rays)?;
    let mut per_pixel = Vec::new();
    let mut rows = Vec::new();
    for &o in &lenses {
        let name = scene.objects[o].name.clone();
        let mut base = (0.0, 0.0, 0.0);
        let mut acc: Vec<HybridRow> = req
            .taus
            .iter()
            .map(|&tau| HybridRow {
                object: name.clone(),
                tau_px: tau,
                vertex_rays: 0.0,
                traced_vertices: 0.0,
                front_triangles: 0.0,
                triangles: 0.0,
                trace_ms: 0.0,
                tessellate_ms: 0.0,
                texgen_ms: 0.0,
                cpu_ms: 0.0,
                ray_reduction: 0.0,
                time_reduction: 0.0,
                p90_angle_deg: [0.0; 2],
            })
            .collect();
        let mut angles: Vec<[Vec<f64>; 2]> =
            req.taus.iter().map(|_| [Vec::new(), Vec::new()]).collect();
        for pf in &frames {
            let lens = pis_pack::lens::lens_object(&scene, &pf.frame, o);
            let tracer = vertex_tracer(gpu_rays.as_ref(), &lens);
            let camera = PerspectiveCamera::new(&pf.frame.camera, size);
            let clip_from_world = projection_matrix(&pf.frame.camera, size)
                * pf.frame.camera.world_from_camera.inverse();
            let view = HybridView { eye: camera.origin, clip_from_world, size };
            let t = Instant::now();
            let (traced, rays) = trace_pixels(&lens, &camera, size, max_depth);
            base.2 += t.elapsed().as_secs_f64() * 1e3;
            base.0 += traced.iter().filter(|p| p.is_some()).count() as f64;
            base.1 += rays as f64;
            // A far shell: its vectors are nearly the outgoing directions.
            let (lo, hi) = lens.positions.iter().fold(
                (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
                |(lo, hi), &p| (lo.min(p), hi.max(p)),
            );
            let shell = Shell {
                origin: ((lo + hi) * 0.5).as_dvec3(),
                shape: ShellShape::Sphere { radius: 20.0 * ((hi - lo).length() as f64).max(1e-3) },
            };
            for (k, &tau) in req.taus.iter().enumerate() {
                let settings =
                    TessellationSettings { tau_px: tau, max_depth, ..Default::default() };
                let (tess, times) = tessellate_timed(&lens, &view, &settings, tracer.as_ref());
                let t = Instant::now();
                let vectors = TERMS.map(|term| vertex_vectors(&tess, term, &shell));
                let texgen = t.elapsed().as_secs_f64() * 1e3;
                let r = &mut acc[k];
                r.vertex_rays += tess.stats.rays as f64;
                r.traced_vertices += tess.stats.traced_vertices as f64;
                r.front_triangles += tess.stats.front_triangles as f64;
                r.triangles += tess.stats.triangles as f64;
                r.trace_ms += times.trace.as_secs_f64() * 1e3;
                r.tessellate_ms += times.tessellate.as_secs_f64() * 1e3;
                r.texgen_ms += texgen;
                for (term, v) in vectors.iter().enumerate() {
                    let px =
                        hybrid_pixels(viewport, &tess, clip_from_world, v, Missing::Mean, None);
                    for (&p, d) in px.pixels.iter().zip(&px.vectors) {
                        let Some(Some(path)) = traced[p as usize].map(|t| t[term]) else {
                            continue;
                        };
                        let Some(w) = shell_vector(&shell, &path) else { continue };
                        let w = DVec3::from(w.map(f64::from));
                        angles[k][term].push(
                            (2.0 * (0.5 * (d[0].normalize() - w.normalize()).length()).asin())
                                .to_degrees(),
                        );
                    }
                }
            }
        }
        per_pixel.push(PixelTracing {
            object: name.clone(),
            pixels: base.0 / n,
            rays: base.1 / n,
            ms: base.2 / n,
        });
        for (mut r, a) in acc.into_iter().zip(angles) {
            for v in [
                &mut r.vertex_rays,
                &mut r.traced_vertices,
                &mut r.front_triangles,
                &mut r.triangles,
                &mut r.trace_ms,
                &mut r.tessellate_ms,
                &mut r.texgen_ms,
            ] {
                *v /= n;
            }
            r.cpu_ms = r.trace_ms + r.tessellate_ms + r.texgen_ms;
            r.ray_reduction = base.1 / n / r.vertex_rays.max(1.0);
            r.time_reduction = base.2 / n / r.cpu_ms.max(1e-9);
            let [a0, a1] = a;
            r.p90_angle_deg = [percentile(a0, 0.9), percentile(a1, 0.9)];
            rows.push(r);
        }
    }
    let (played, adapter, msaa) = match &req.file {
        Some(file) => {
            let base_ms: f64 = per_pixel.iter().map(|p| p.ms).sum();
            let (rows, adapter, msaa) =
                play(&scene, file, &frames, &req.taus, (req.msaa, req.lens_rays), base_ms)?;
            (rows, Some(adapter), msaa)
        }
        None => (Vec::new(), None, 0),
    };
    Ok(HybridReport {
        scene: scene.name.clone(),
        size: [size.0, size.1],
        frames: frames.len(),
        threads: rayon::current_num_threads(),
        per_pixel,
        rows,
        played,
        adapter,
        msaa,
        lens_rays: match &gpu_rays {
            Some((gpu, _)) => format!("gpu ({})", gpu.describe()),
            None => "workers".into(),
        },
        stamp: Stamp::here(&scene.name),
    })
}

/// `file` played at every frame's camera with each τ; before them the last frame is drawn
/// once, not counted, so that the file is opened, its first textures decoded and uploaded
/// and its pipelines compiled (and the first counted frame, at another camera, traces its
/// own vertex rays).
fn play(
    scene: &pis_scene::Scene,
    file: &std::path::Path,
    frames: &[super::camera_path::PathFrame],
    taus: &[f32],
    (msaa, lens_rays): (u32, pis_play::LensRays),
    base_ms: f64,
) -> Result<(Vec<PlayedRow>, String, u32), Failure> {
    use pis_play::{CameraChoice, FrameRequest, Gpu, Player, PlayerOptions};
    let gpu = std::sync::Arc::new(
        Gpu::new().map_err(|e| Failure::new(Exit::NotSupported, anyhow!("{e}")))?,
    );
    let view_dim = scene
        .space
        .dims
        .iter()
        .position(|d| d.kind == pis_format::DimensionKind::View)
        .unwrap_or(0);
    let mut rows = Vec::new();
    let mut samples = msaa;
    for &tau in taus {
        let mut player = Player::open(
            gpu.clone(),
            file,
            PlayerOptions { tau_px: tau, msaa, lens_rays, ..PlayerOptions::default() },
        )
        .map_err(|e| Failure::new(Exit::Invalid, anyhow!("{}: {e}", file.display())))?;
        if player.image_size() != scene.resolution {
            return Err(Failure::new(Exit::Usage, anyhow!("{}: {}x{} frames, the scene's are {}x{} (pass the same --preset or --resolution)", file.display(), player.image_size().0, player.image_size().1, scene.resolution.0, scene.resolution.1)));
        }
        samples = player.multisample().samples;
        let mut row = PlayedRow {
            tau_px: tau,
            lens_ms: 0.0,
            lens_rays: 0.0,
            decode_ms: 0.0,
            draw_ms: 0.0,
            frame_ms: 0.0,
            frame_reduction: 0.0,
        };
        let request = |pf: &super::camera_path::PathFrame| FrameRequest {
            point: super::reflective::point(scene, pf, view_dim),
            camera: CameraChoice::Free(super::reflective::camera(scene, pf)),
        };
        if let Some(last) = frames.last() {
            player
                .render_timed(&request(last), scene.resolution)
                .map_err(|e| Failure::new(Exit::Runtime, anyhow!("{e}")))?;
        }
        for pf in frames {
            let s = player
                .render_timed(&request(pf), scene.resolution)
                .map_err(|e| Failure::new(Exit::Runtime, anyhow!("{e}")))?;
            row.lens_ms += s.lens_ms;
            row.lens_rays += s.lens_rays as f64;
            row.decode_ms += s.decode_ms;
            row.draw_ms += s.draw_ms;
            row.frame_ms += s.frame_ms;
        }
        let n = frames.len().max(1) as f64;
        for v in [
            &mut row.lens_ms,
            &mut row.lens_rays,
            &mut row.decode_ms,
            &mut row.draw_ms,
            &mut row.frame_ms,
        ] {
            *v /= n;
        }
        row.frame_reduction = base_ms / row.frame_ms.max(1e-9);
        rows.push(row);
    }
    Ok((rows, gpu.describe(), samples))
}

pub fn print(r: &HybridReport, w: &mut impl std::io::Write) -> std::io::Result<()> {
    writeln!(
        w,
        "pis-bench hybrid: {} at {}x{}, {} frames between the sampled views, {} threads, vertex rays traced on {}",
        r.scene, r.size[0], r.size[1], r.frames, r.threads, r.lens_rays
    )?;
    for p in &r.per_pixel {
        writeln!(
            w,
            "  {}: traced at every pixel centre: {:.0} pixels, {:.0} rays, {:.2} ms",
            p.object, p.pixels, p.rays, p.ms
        )?;
        writeln!(
            w,
            "    {:>6} {:>10} {:>9} {:>9} {:>9} {:>11} {:>9} {:>9} {:>8} {:>8} {:>15}",
            "τ px",
            "rays",
            "vertices",
            "triangles",
            "trace ms",
            "tessel. ms",
            "texgen ms",
            "total ms",
            "rays ÷",
            "time ÷",
            "90 % angle R/T"
        )?;
        for x in r.rows.iter().filter(|x| x.object == p.object) {
            writeln!(w, "    {:>6} {:>10.0} {:>9.0} {:>9.0} {:>9.2} {:>11.2} {:>9.2} {:>9.2} {:>8.1} {:>8.1} {:>7.2}°/{:.2}°", x.tau_px, x.vertex_rays, x.traced_vertices, x.triangles, x.trace_ms, x.tessellate_ms, x.texgen_ms, x.cpu_ms, x.ray_reduction, x.time_reduction, x.p90_angle_deg[0], x.p90_angle_deg[1])?;
        }
    }
    if let Some(a) = &r.adapter {
        writeln!(w, "  played ({a}, {} sample(s) per pixel), means per frame:", r.msaa)?;
        writeln!(
            w,
            "    {:>6} {:>10} {:>8} {:>9} {:>8} {:>9} {:>13}",
            "τ px", "lens rays", "lens ms", "decode ms", "draw ms", "frame ms", "per-pixel ÷"
        )?;
        for p in &r.played {
            writeln!(
                w,
                "    {:>6} {:>10.0} {:>8.2} {:>9.2} {:>8.2} {:>9.2} {:>13.2}",
                p.tau_px,
                p.lens_rays,
                p.lens_ms,
                p.decode_ms,
                p.draw_ms,
                p.frame_ms,
                p.frame_reduction
            )?;
        }
    }
    Ok(())
}
