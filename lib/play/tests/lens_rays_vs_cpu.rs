//! Vertex rays traced on the GPU (`lens_rays.wgsl`) against the CPU walk they are written
//! from (pis-compile's `trace_vertex`): for the vertices of whole tessellations of a glass
//! ball, a glass torus and samples/glass's teapot, under the greedy model and the ray tree,
//! every vertex must have the same visibility and the same terms, and every term the same
//! topology, with exit directions within 10⁻³ rad and F·G within 10⁻³ of the CPU's, but for
//! a few vertices in a thousand (a ray that grazes an edge between two triangles may take the
//! other one at the last bit). The tessellation made with the GPU's paths must be the CPU's
//! but for those. Runs on Mesa's lavapipe in CI.

mod common;

use std::sync::Arc;

use common::*;
use glam::{Mat3, Vec3};
use pis_compile::hybrid::{
    tessellate_timed, CpuVertexTracer, HybridVertex, HybridView, LensMaterial, LensModel,
    LensObject, TessellationSettings, VertexRay, VertexTracer,
};
use pis_compile::Viewport;
use pis_play::lens_rays::{GpuVertexTracer, LensRayPipeline};

fn glass(sigma: f32) -> LensMaterial {
    LensMaterial { ior: 1.5, base: Vec3::new(0.95, 0.97, 1.0), sigma_a: Vec3::splat(sigma) }
}

fn ball() -> LensObject {
    let m = uv_sphere(48, 24);
    let p: Vec<Vec3> = m.positions.iter().map(|&p| Vec3::from(p)).collect();
    LensObject::new(glass(0.3), p.clone(), p, &m.indices)
}

/// A torus of radii 1 and 0.35 about +Y: a concave lens with internal reflections.
fn torus() -> LensObject {
    let (n, k) = (64u32, 24u32);
    let (mut p, mut nrm, mut idx) = (vec![], vec![], vec![]);
    for i in 0..n {
        let u = std::f32::consts::TAU * i as f32 / n as f32;
        let c = Vec3::new(u.cos(), 0.0, u.sin());
        for j in 0..k {
            let v = std::f32::consts::TAU * j as f32 / k as f32;
            let d = c * v.cos() + Vec3::Y * v.sin();
            p.push(c + d * 0.35);
            nrm.push(d);
            let (a, b) = (i * k + j, i * k + (j + 1) % k);
            let (c2, d2) = (((i + 1) % n) * k + j, ((i + 1) % n) * k + (j + 1) % k);
            idx.extend([a, b, c2, b, d2, c2]);
        }
    }
    LensObject::new(glass(0.0), p, nrm, &idx)
}

/// samples/glass's teapot (the scene's refractive object) at its first frame, and where
/// that frame's camera stands.
fn teapot() -> (LensObject, Vec3) {
    let root =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../samples/glass/scene.toml");
    let scene = pis_scene::load(&root, None).expect("samples/glass loads");
    let frame = scene.frame_at(0).expect("frame 0");
    let o = scene
        .objects
        .iter()
        .position(|o| o.role == pis_scene::ObjectRole::Refractive)
        .expect("a refractive object");
    let m = frame.instances[o].world_from_object;
    let nm = Mat3::from_mat4(m).inverse().transpose();
    let (mut p, mut n, mut idx) = (vec![], vec![], vec![]);
    for prim in &scene.objects[o].primitives {
        let base = p.len() as u32;
        p.extend(prim.positions.iter().map(|&x| m.transform_point3(x)));
        n.extend(
            (0..prim.positions.len()).map(|k| prim.normals.get(k).map_or(Vec3::ZERO, |&x| nm * x)),
        );
        idx.extend(prim.indices.iter().map(|&i| base + i));
    }
    let eye = frame.camera.world_from_camera.transform_point3(Vec3::ZERO);
    (LensObject::new(glass(0.2), p, n, &idx), eye)
}

/// How two traced vertices differ: 0 the same, 1 a term's direction or F·G beyond the
/// tolerance, 2 visibility, a term's existence or topology.
fn difference(a: &HybridVertex, b: &HybridVertex) -> u32 {
    if a.visible != b.visible || a.normal != b.normal || a.position != b.position {
        return 2;
    }
    let mut worst = 0;
    for (p, q) in a.paths.iter().zip(&b.paths) {
        match (p, q) {
            (None, None) => {}
            (Some(p), Some(q)) if p.topology == q.topology => {
                let angle = p.exit_direction.dot(q.exit_direction).clamp(-1.0, 1.0).acos();
                let fg = (p.modulation - q.modulation).abs().max_element();
                if angle > 1e-3 || fg > 1e-3 {
                    worst = worst.max(1);
                }
            }
            _ => return 2,
        }
    }
    worst
}

#[test]
fn gpu_vertex_rays_follow_the_cpu_paths() {
    let Some(gpu) = gpu_or_skip("gpu_vertex_rays_follow_the_cpu_paths") else { return };
    let gpu = Arc::new(gpu);
    let pipeline = Arc::new(LensRayPipeline::new(&gpu));
    let vp = Viewport { width: 160, height: 120 };
    let models = [("greedy", LensModel::Greedy), ("tree", LensModel::TREE)];
    let (pot, pot_eye) = teapot();
    let objects: [(&str, LensObject, Vec3); 3] = [
        ("ball", ball(), Vec3::new(0.6, 0.9, 3.0)),
        ("torus", torus(), Vec3::new(0.3, 1.6, 2.6)),
        // The teapot seen from where its scene's first camera stands.
        ("teapot", pot, pot_eye),
    ];
    for (name, lens, eye) in &objects {
        let (eye, target) = (*eye, lens.centroid());
        let clip = camera(vp, eye.to_array(), target.to_array(), 0.9);
        let view = HybridView { eye, clip_from_world: clip, size: (vp.width, vp.height) };
        let gpu_tracer = GpuVertexTracer::new(gpu.clone(), pipeline.clone(), lens);
        for (mname, model) in models {
            let settings = TessellationSettings { tau_px: 2.0, model, ..Default::default() };
            assert!(gpu_tracer.traces(lens, settings.max_depth), "{name}: traced on the GPU");
            let (cpu_tess, _) = tessellate_timed(lens, &view, &settings, &CpuVertexTracer);
            let rays: Vec<VertexRay> = cpu_tess
                .vertices
                .iter()
                .map(|v| VertexRay {
                    position: v.position,
                    normal: v.normal,
                    front_face: v.front_face,
                })
                .collect();
            let cpu = CpuVertexTracer.trace(lens, eye, &rays, model, settings.max_depth);
            let on_gpu = gpu_tracer.trace(lens, eye, &rays, model, settings.max_depth);
            assert_eq!(cpu.len(), on_gpu.len());
            // Per hidden and visible vertex: the same, beyond the tolerance, another topology.
            let mut counts = [[0usize; 3]; 2];
            let (mut cpu_rays, mut gpu_rays) = (0u64, 0u64);
            for ((c, cr), (g, gr)) in cpu.iter().zip(&on_gpu) {
                let differ = difference(c, g);
                counts[c.visible as usize][differ as usize] += 1;
                cpu_rays += cr;
                gpu_rays += gr;
            }
            let n = cpu.len();
            let (gpu_tess, _) = tessellate_timed(lens, &view, &settings, &gpu_tracer);
            let [hidden, seen] = counts.map(|c| (c.iter().sum::<usize>(), c[1] + c[2]));
            let (ct, gt) = (cpu_tess.triangles.len(), gpu_tess.triangles.len());
            eprintln!(
                "{name} {mname}: {n} vertices; differing (beyond 1e-3 or in topology) {} of {} visible, {} of {} hidden; rays {cpu_rays} / {gpu_rays}; triangles {ct} / {gt}",
                seen.1, seen.0, hidden.1, hidden.0
            );
            assert!(seen.0 > 500, "{name} {mname}: {seen:?} visible vertices");
            assert!((seen.1 + hidden.1) * 200 <= n, "{name} {mname}: {counts:?}");
            assert!(cpu_rays.abs_diff(gpu_rays) * 200 <= cpu_rays, "{name} {mname}: rays");
            assert!(ct.abs_diff(gt) * 100 <= ct, "{name} {mname}: triangles {ct} / {gt}");
            // The same level twice on the GPU: the same paths, bit for bit.
            let again = gpu_tracer.trace(lens, eye, &rays, model, settings.max_depth);
            assert!(again == on_gpu, "{name} {mname}: two traces differ");
        }
    }
}
