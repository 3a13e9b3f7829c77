//! Probe mode (thesis 3.4.3) against the hardware model: for a random texture x,
//! A_probe·x matches A_model·x at ≥ 50 dB, and the two matrices have the same pattern.

mod common;

use common::*;
use pis_compile::{
    render_matrix, scene_depth, Address, DrawMesh, Filter, RenderMatrix, Sampler, TextureLayout,
    TextureTransform, TexturedObject, Viewport,
};
use pis_play::{probe_render_matrix, TexturedPipeline};

/// Largest |A_model − A_probe| entry over the rows both have.
fn max_entry_difference(a: &RenderMatrix, b: &RenderMatrix) -> f32 {
    let mut worst = 0.0f32;
    let rows_b: std::collections::HashMap<u32, usize> =
        b.pixels.iter().enumerate().map(|(r, &p)| (p, r)).collect();
    for r in 0..a.rows() {
        let Some(&rb) = rows_b.get(&a.pixels[r]) else { continue };
        let (ca, va) = a.row(r);
        let (cb, vb) = b.row(rb);
        let mut m: std::collections::BTreeMap<u32, f32> =
            ca.iter().copied().zip(va.iter().copied()).collect();
        for (&c, &v) in cb.iter().zip(vb) {
            *m.entry(c).or_insert(0.0) -= v;
        }
        worst = m.values().fold(worst, |w, v| w.max(v.abs()));
    }
    worst
}

#[test]
fn probe_matches_model() {
    let Some(gpu) = gpu_or_skip("probe_matches_model") else { return };
    let pipeline = TexturedPipeline::new(&gpu);
    let vp = Viewport { width: 120, height: 90 };
    let sphere = uv_sphere(32, 16);
    let occluder = quad(-2.0, -0.2, -2.0, -0.3, 1.3);
    let skewed = TextureTransform::affine([0.93, 0.05, -0.04, 0.88, 0.03, 0.06]);
    let wrapped = TextureTransform::affine([1.0, 0.0, 0.0, 0.9, 0.0, 0.05]);
    // Seen across the texture seam (u = 0 and 1 at +x): contiguous after a branch cut at 0.3.
    let cut =
        TextureTransform { values: [1.6, 0.02, 0.0, 0.9, -0.68, 0.05], cut: [Some(0.3), None] };
    let cases = [
        (
            "trilinear-clamp",
            Filter::Trilinear,
            [Address::ClampToEdge; 2],
            TextureLayout::full(151, 77),
            [0.3, 0.6, 2.4],
            skewed,
        ),
        (
            "bilinear-clamp",
            Filter::Bilinear,
            [Address::ClampToEdge; 2],
            TextureLayout::full(45, 29),
            [0.3, 0.6, 2.4],
            skewed,
        ),
        (
            "trilinear-repeat-s",
            Filter::Trilinear,
            [Address::Repeat, Address::ClampToEdge],
            TextureLayout::full(128, 37),
            [-1.5, 1.0, 3.5],
            wrapped,
        ),
        (
            "trilinear-branch-cut-u",
            Filter::Trilinear,
            [Address::ClampToEdge; 2],
            TextureLayout::full(97, 61),
            [2.3, 0.5, 0.4],
            cut,
        ),
    ];
    let mut failures = vec![];
    for (name, filter, address, layout, eye, transform) in cases {
        let clip = camera(vp, eye, [0.0; 3], 0.9);
        let occ = DrawMesh {
            positions: &occluder.positions,
            uvs: &occluder.uvs,
            indices: &occluder.indices,
            clip_from_object: clip,
        };
        let object = TexturedObject {
            mesh: DrawMesh {
                positions: &sphere.positions,
                uvs: &sphere.uvs,
                indices: &sphere.indices,
                clip_from_object: clip,
            },
            transform,
            layout,
            sampler: Sampler { filter, address },
        };
        let depth = scene_depth(vp, &[occ], None).unwrap();
        let model = render_matrix(vp, &object, Some(&depth)).unwrap();
        let t = std::time::Instant::now();
        let probe = probe_render_matrix(&gpu, &pipeline, vp, &[occ], &object).unwrap();
        let ms = t.elapsed().as_secs_f64() * 1e3;
        let x = random_rgba(layout.texel_count(), 11);
        let (want, got) = (predict(&model, &x), predict(&probe, &x));
        let c = compare(&want, &got);
        let diff = max_entry_difference(&model, &probe);
        eprintln!(
            "{name}: PSNR {:.2} dB over {} pixels, {} coverage mismatches, max |ΔA| {diff:.2e}, nnz model {} probe {}, probe {ms:.0} ms",
            c.psnr_db, c.both, c.coverage_mismatch, model.cols.len(), probe.cols.len()
        );
        if c.psnr_db < 50.0 || c.coverage_mismatch * 1000 > c.both {
            let dir = write_failure_images(&format!("probe_vs_model-{name}"), &want, &got);
            failures.push(format!("{name}: {c:?} (images in {})", dir.display()));
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}
