//! Multisampled frames through the frame pipelines directly: two flat textured quads, one
//! turned in front of the other, drawn with 1 and 4 samples per pixel. A flat quad's texture
//! coordinates are one affine function over both its triangles, so a pixel all of whose
//! samples lie on one quad is shaded exactly as with one sample (once, at its centre, the
//! same derivatives and LOD): inside the quads 4 samples change nothing beyond float
//! rounding (of the interpolation along a quad's diagonal, where the other triangle shades
//! some samples, and of the resolve). On the front quad's silhouette pixels mix the two quads (or a
//! quad and the empty background) by the covered fraction.

mod common;

use common::*;
use pis_compile::{Address, Filter, Sampler, TextureLayout, Viewport};
use pis_play::frame::{offscreen_format, FramePipelines, MeshGpu, NO_OBJECT};
use pis_play::multisample::choose;
use pis_play::textured::create_sampler;
use pis_play::ObjectTexture;

const SIZE: (u32, u32) = (80, 60);

#[test]
fn frame_multisampling_keeps_interiors_exactly() {
    let test = "frame_multisampling_keeps_interiors_exactly";
    let Some(gpu) = gpu_or_skip(test) else { return };
    let ms = choose(&gpu, 4, offscreen_format(&gpu));
    if ms.samples != 4 {
        assert!(std::env::var("CI").map_or(true, |v| v != "true"), "{test}: {ms:?}");
        eprintln!("{test}: skipped: {}", ms.note.unwrap_or_default());
        return;
    }
    let mut pipes = FramePipelines::new(&gpu);
    let clip =
        camera(Viewport { width: SIZE.0, height: SIZE.1 }, [0.3, 0.4, 3.0], [0.0, 0.0, 0.0], 0.8);
    // Behind: a wide quad at z = −0.5, seen at an angle. In front: a smaller one turned
    // 25° about z so that its edges cross the pixel grid at every phase.
    let back = quad(-1.6, 1.6, -1.2, 1.2, -0.5);
    let front = quad(-0.6, 0.6, -0.5, 0.5, 0.4);
    let turn = glam::Mat4::from_rotation_z(25f32.to_radians());
    let layout = TextureLayout::new(16, 16, 1);
    let texture = |seed| {
        let t = ObjectTexture::new(&gpu, layout);
        t.upload(&gpu, &random_rgba(16 * 16, seed)).unwrap();
        t
    };
    let mesh = |m: &Mesh| MeshGpu::new(&gpu, &m.positions, None, &m.uvs, &m.indices);
    let scene = [(mesh(&back), clip, texture(1)), (mesh(&front), clip * turn, texture(2))];
    let sampler = create_sampler(
        &gpu,
        &Sampler { filter: Filter::Bilinear, address: [Address::ClampToEdge; 2] },
    );
    let (a, ids_a) = draw_scene(&gpu, &mut pipes, SIZE, 1, None, &scene, &sampler);
    let (b, ids_b) = draw_scene(&gpu, &mut pipes, SIZE, 4, None, &scene, &sampler);
    assert_eq!(ids_a, ids_b, "object indices at pixel centres");
    let (w, h) = (SIZE.0 as usize, SIZE.1 as usize);
    let (mut interior, mut silhouette, mut mixed) = ([0usize; 2], 0usize, 0usize);
    let mut worst = 0.0f32;
    for y in 1..h - 1 {
        for x in 1..w - 1 {
            let p = y * w + x;
            let uniform = (0..9).all(|k| ids_a[(y + k / 3 - 1) * w + x + k % 3 - 1] == ids_a[p]);
            let differ =
                (0..4).map(|c| (a.rgba[p * 4 + c] - b.rgba[p * 4 + c]).abs()).fold(0.0, f32::max);
            if uniform && ids_a[p] != NO_OBJECT {
                interior[ids_a[p] as usize] += 1;
                // On a quad's diagonal the other triangle interpolates (s, t) at the centre
                // with its own barycentrics: a rounding of ~2^-23 in (s, t), times a texture
                // that changes by up to 1 per texel over 16 texels, bounds the change by
                // 16 · 2^-23 · a few ≈ 1e-5.
                worst = worst.max(differ);
                assert!(
                    differ <= 1e-5,
                    "pixel ({x}, {y}) inside object {}: 1 sample {:?}, 4 samples {:?}",
                    ids_a[p],
                    &a.rgba[p * 4..p * 4 + 4],
                    &b.rgba[p * 4..p * 4 + 4]
                );
            }
            if !uniform {
                silhouette += 1;
                mixed += (differ > 1e-3) as usize;
            }
        }
    }
    eprintln!("{test}: interior pixels {interior:?} (largest change {worst:e}), silhouette {silhouette} ({mixed} changed by multisampling)");
    assert!(interior[0] > 300 && interior[1] > 300, "interior pixels per quad: {interior:?}");
    assert!(silhouette > 100, "{silhouette} silhouette pixels");
    // Two random textures meet, or a quad meets the empty background: where a pixel's
    // samples are split, its colour is a mix; where all four fall on the centre's side, it
    // is not. The silhouette band (another object in the 3×3 neighbourhood) is about three
    // pixels wide and an edge splits about one of them per row or column it crosses: about
    // a third change; at least a quarter must.
    assert!(mixed * 4 > silhouette, "{mixed} of {silhouette} silhouette pixels changed");
}

/// A colour format the device cannot resolve (integer formats never resolve) falls back to
/// one sample per pixel with a note naming it; one sample asked for is one sample drawn.
#[test]
fn a_format_that_cannot_be_resolved_falls_back_to_one_sample() {
    let Some(gpu) = gpu_or_skip("a_format_that_cannot_be_resolved_falls_back_to_one_sample") else {
        return;
    };
    let m = choose(&gpu, 4, wgpu::TextureFormat::Rgba32Uint);
    assert_eq!((m.requested, m.samples), (4, 1));
    let note = m.note.expect("a note says why");
    assert!(note.contains("Rgba32Uint") && note.contains("1 sample per pixel"), "{note}");
    let one = choose(&gpu, 1, offscreen_format(&gpu));
    assert_eq!((one.requested, one.samples, one.note), (1, 1, None));
}
