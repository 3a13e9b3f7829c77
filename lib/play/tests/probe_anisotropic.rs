//! Anisotropic filtering through probe mode (thesis 3.4.3): the hardware model does not
//! describe it, so A is measured through the pipeline; for a random texture x, A·x equals the
//! pipeline's anisotropic rendering of x (≥ 50 dB) on an oblique floor, where the footprint is
//! long and thin. Also prints how far the adapter's anisotropic A (clamp 4) is from clamp 1
//! (no anisotropy) and from the model's trilinear A: an adapter that ignores the clamp gives
//! the same matrix for 1 and 4.

mod common;

use common::*;
use glam::Vec3;
use pis_compile::transform::{look_at, perspective};
use pis_compile::{
    render_matrix, Address, DrawMesh, Filter, Sampler, TextureLayout, TextureTransform,
    TexturedObject, Viewport,
};
use pis_play::{probe, render_object, TexturedPipeline};

#[test]
fn anisotropic_probe_predicts_the_anisotropic_draw() {
    let Some(gpu) = gpu_or_skip("anisotropic_probe_predicts_the_anisotropic_draw") else { return };
    let pipeline = TexturedPipeline::new(&gpu);
    let vp = Viewport { width: 48, height: 36 };
    // A floor (z = 0 plane, 8 × 8 units) seen from just above it: texels per pixel grow
    // along the view direction much faster than across it.
    let floor = quad(-4.0, 4.0, -4.0, 4.0, 0.0);
    let clip = perspective(0.8, 4.0 / 3.0, 0.1, 50.0)
        * look_at(Vec3::new(0.0, -4.0, 1.0), Vec3::new(0.0, 0.5, 0.0), Vec3::Z);
    let layout = TextureLayout::full(64, 64);
    let x = random_rgba(layout.texel_count(), 5);
    let object = |filter| TexturedObject {
        mesh: DrawMesh {
            positions: &floor.positions,
            uvs: &floor.uvs,
            indices: &floor.indices,
            clip_from_object: clip,
        },
        transform: TextureTransform::affine([1.0, 0.0, 0.0, 1.0, 0.0, 0.0]),
        layout,
        sampler: Sampler { filter, address: [Address::ClampToEdge; 2] },
    };
    let t = std::time::Instant::now();
    let aniso = probe(&gpu, &pipeline, vp, &[], &object(Filter::Anisotropic(4))).unwrap();
    let ms = t.elapsed().as_secs_f64() * 1e3;
    let drawn =
        render_object(&gpu, &pipeline, vp, &[], &object(Filter::Anisotropic(4)), &x).unwrap();
    let c = compare(&predict(&aniso.matrix, &x), &drawn);
    eprintln!(
        "anisotropic 4: A·x vs draw {:.2} dB over {} pixels, {} coverage mismatches; reach {:?}, {} renderings, check error {:.1e}, nnz {}, {ms:.0} ms",
        c.psnr_db, c.both, c.coverage_mismatch, aniso.reach, aniso.renderings, aniso.check_error, aniso.matrix.cols.len()
    );
    assert!(c.both > 300, "the floor covers too few pixels: {c:?}");
    if c.psnr_db < 50.0 || c.coverage_mismatch > 0 {
        let dir = write_failure_images("probe_anisotropic", &predict(&aniso.matrix, &x), &drawn);
        panic!("anisotropic probe A·x differs from the draw: {c:?} (images in {})", dir.display());
    }
    // What anisotropy changes on this adapter (figures, not assertions: the footprint is the
    // adapter's choice).
    let iso = probe(&gpu, &pipeline, vp, &[], &object(Filter::Anisotropic(1))).unwrap();
    let model = render_matrix(vp, &object(Filter::Trilinear), None).unwrap();
    let vs_iso = compare(&predict(&iso.matrix, &x), &predict(&aniso.matrix, &x));
    let vs_model = compare(&predict(&model, &x), &predict(&aniso.matrix, &x));
    eprintln!(
        "anisotropic 4 vs clamp 1: {:.2} dB (nnz {} vs {}); vs the model's trilinear: {:.2} dB (nnz {})",
        vs_iso.psnr_db, aniso.matrix.cols.len(), iso.matrix.cols.len(), vs_model.psnr_db, model.cols.len()
    );
}
