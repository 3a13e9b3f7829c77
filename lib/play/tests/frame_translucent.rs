//! A translucent object through the frame pipelines (SPEC.md 9): a quad whose texture holds
//! premultiplied colour and opacity, turned in front of an opaque one, must show
//! colour + (1 − opacity) · what lies behind, per pixel. The parts are measured by drawing
//! each quad alone as an opaque object: the back quad, the front quad's colour, and its
//! opacity as a grey texture (the same lookups, so the same texels and weights). With 4
//! samples per pixel the interiors (pixels whose 3×3 neighbourhood sees one front/back
//! arrangement) must match the single-sample frame.

mod common;

use common::*;
use pis_compile::{Address, Filter, Sampler, TextureLayout, Viewport};
use pis_play::frame::{offscreen_format, FramePipelines, MeshGpu, NO_OBJECT};
use pis_play::multisample::choose;
use pis_play::textured::create_sampler;
use pis_play::ObjectTexture;

const SIZE: (u32, u32) = (80, 60);

#[test]
fn a_translucent_object_is_composited_over_what_lies_behind_it() {
    let test = "a_translucent_object_is_composited_over_what_lies_behind_it";
    let Some(gpu) = gpu_or_skip(test) else { return };
    let mut pipes = FramePipelines::new(&gpu);
    let clip =
        camera(Viewport { width: SIZE.0, height: SIZE.1 }, [0.3, 0.4, 3.0], [0.0, 0.0, 0.0], 0.8);
    let back = quad(-1.6, 1.6, -1.2, 1.2, -0.5);
    let front = quad(-0.6, 0.6, -0.5, 0.5, 0.4);
    let turn = glam::Mat4::from_rotation_z(25f32.to_radians());
    let layout = TextureLayout::new(16, 16, 1);
    let texture = |rgba: &[f32]| {
        let t = ObjectTexture::new(&gpu, layout);
        t.upload(&gpu, rgba).unwrap();
        t
    };
    // The front quad: opacity from 0 to 1, colour premultiplied by it.
    let colour = random_rgba(16 * 16, 2);
    let opacity = random(16 * 16, 3);
    let premultiplied: Vec<f32> = colour
        .chunks_exact(4)
        .zip(&opacity)
        .flat_map(|(c, &a)| [c[0] * a, c[1] * a, c[2] * a, a])
        .collect();
    let colour_only: Vec<f32> =
        premultiplied.chunks_exact(4).flat_map(|c| [c[0], c[1], c[2], 1.0]).collect();
    let grey: Vec<f32> = opacity.iter().flat_map(|&a| [a, a, a, 1.0]).collect();
    let mesh = |m: &Mesh| MeshGpu::new(&gpu, &m.positions, None, &m.uvs, &m.indices);
    let sampler = create_sampler(
        &gpu,
        &Sampler { filter: Filter::Bilinear, address: [Address::ClampToEdge; 2] },
    );
    let back_texture = random_rgba(16 * 16, 1);
    let scene = [
        (mesh(&back), clip, texture(&back_texture)),
        (mesh(&front), clip * turn, texture(&premultiplied)),
    ];
    let alone = |m: &Mesh, c: glam::Mat4, t: &[f32]| {
        draw_scene(
            &gpu,
            &mut FramePipelines::new(&gpu),
            SIZE,
            1,
            None,
            &[(mesh(m), c, texture(t))],
            &sampler,
        )
        .0
    };
    let behind = alone(&back, clip, &back_texture);
    let f_colour = alone(&front, clip * turn, &colour_only);
    let f_opacity = alone(&front, clip * turn, &grey);
    let translucent = [false, true];
    let (got, ids) =
        draw_scene_with(&gpu, &mut pipes, (SIZE, 1), None, &scene, &sampler, &translucent);
    let mut worst = 0.0f32;
    let mut seen = 0;
    for (p, &id) in ids.iter().enumerate() {
        let covered = f_opacity.rgba[p * 4 + 3] > 0.0;
        assert_eq!(
            id,
            if covered {
                1
            } else if behind.rgba[p * 4 + 3] > 0.0 {
                0
            } else {
                NO_OBJECT
            },
            "pixel {p}: the nearest surface's index"
        );
        if !covered {
            (0..4).for_each(|c| {
                worst = worst.max((got.rgba[p * 4 + c] - behind.rgba[p * 4 + c]).abs())
            });
            continue;
        }
        seen += 1;
        let a = f_opacity.rgba[p * 4];
        for c in 0..3 {
            let want = f_colour.rgba[p * 4 + c] + (1.0 - a) * behind.rgba[p * 4 + c];
            worst = worst.max((got.rgba[p * 4 + c] - want).abs());
        }
        let want_alpha = a + (1.0 - a) * behind.rgba[p * 4 + 3];
        worst = worst.max((got.rgba[p * 4 + 3] - want_alpha).abs());
    }
    assert!(seen > 500, "{test}: the front quad covers {seen} pixels");
    assert!(worst < 1e-5, "{test}: largest difference {worst}");

    let ms = choose(&gpu, 4, offscreen_format(&gpu));
    if ms.samples != 4 {
        assert!(std::env::var("CI").map_or(true, |v| v != "true"), "{test}: {ms:?}");
        eprintln!("{test}: 4 samples skipped: {}", ms.note.unwrap_or_default());
        return;
    }
    let (multi, ids_ms) =
        draw_scene_with(&gpu, &mut pipes, (SIZE, 4), None, &scene, &sampler, &translucent);
    assert_eq!(ids, ids_ms, "object indices at pixel centres");
    let (w, h) = (SIZE.0 as usize, SIZE.1 as usize);
    let mut worst = 0.0f32;
    for y in 1..h - 1 {
        for x in 1..w - 1 {
            let p = y * w + x;
            if (0..9).all(|k| ids[(y + k / 3 - 1) * w + x + k % 3 - 1] == ids[p]) {
                (0..4).for_each(|c| {
                    worst = worst.max((multi.rgba[p * 4 + c] - got.rgba[p * 4 + c]).abs())
                });
            }
        }
    }
    assert!(worst < 1e-4, "{test}: 4 samples differ inside by {worst}");
}
