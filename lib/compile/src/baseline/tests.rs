//! The baselines on a screen-filling quad, where texel (i, j) sits on pixel (i, j).

use glam::{Mat4, Vec3};

use super::forward::forward_map;
use super::traced::trace_into_texture;
use super::LayerImage;
use crate::transform::{DrawMesh, TextureTransform};
use crate::TextureLayout;

const POS: [[f32; 3]; 4] = [[-1.0, 1.0, 0.5], [1.0, 1.0, 0.5], [1.0, -1.0, 0.5], [-1.0, -1.0, 0.5]];
const UV: [[f32; 2]; 4] = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
const IDX: [u32; 6] = [0, 1, 2, 0, 2, 3];

fn f(x: f32, y: f32) -> [f32; 3] {
    [0.5 + 0.3 * (x * 0.3).sin(), 0.2 + 0.01 * y, 0.4]
}

fn psnr(a: &[f32], b: &[f32]) -> f64 {
    let mse = a.iter().zip(b).map(|(x, y)| ((x - y) as f64).powi(2)).sum::<f64>() / a.len() as f64;
    10.0 * (1.0 / mse.max(1e-30)).log10()
}

#[test]
fn forward_mapping_and_traced_textures_reproduce_a_smooth_layer() {
    let n = 32u32;
    let mesh =
        DrawMesh { positions: &POS, uvs: &UV, indices: &IDX, clip_from_object: Mat4::IDENTITY };
    let layout = TextureLayout::full(n, n);
    let mut rgb = vec![];
    for y in 0..n {
        for x in 0..n {
            rgb.extend(f(x as f32 + 0.5, y as f32 + 0.5));
        }
    }
    // the left quarter is not covered: hole filling must supply it
    let covered: Vec<bool> = (0..n * n).map(|k| k % n >= n / 4).collect();
    let layer = LayerImage { width: n, height: n, rgb: rgb.clone(), covered };
    let tex = forward_map(&mesh, &TextureTransform::IDENTITY, &layer, &layout).unwrap();
    assert_eq!(tex.len(), layout.texel_count() * 3);
    assert!(tex.iter().all(|v| v.is_finite()));
    let right = |img: &[f32]| -> Vec<f32> {
        (0..(n * n) as usize)
            .filter(|k| k % n as usize >= n as usize / 4 + 4)
            .flat_map(|k| img[k * 3..k * 3 + 3].to_vec())
            .collect()
    };
    assert!(psnr(&right(&tex), &right(&rgb)) > 35.0);

    // traced: the "radiance" is f at the point the ray reaches, in pixel units of the quad
    let traced = trace_into_texture(
        &mesh,
        &TextureTransform::IDENTITY,
        Mat4::IDENTITY,
        Vec3::new(0.0, 0.0, 5.0),
        &layout,
        |rays| {
            rays.iter()
                .map(|r| {
                    let p = r.origin + r.direction * r.distance;
                    f((p.x + 1.0) * 0.5 * n as f32, (1.0 - p.y) * 0.5 * n as f32)
                })
                .collect()
        },
    )
    .unwrap();
    let inner = |img: &[f32]| -> Vec<f32> {
        (0..(n * n) as usize)
            .filter(|k| {
                let (x, y) = (k % n as usize, k / n as usize);
                (3..29).contains(&x) && (3..29).contains(&y)
            })
            .flat_map(|k| img[k * 3..k * 3 + 3].to_vec())
            .collect()
    };
    assert!(psnr(&inner(&traced), &inner(&rgb)) > 35.0, "{}", psnr(&inner(&traced), &inner(&rgb)));
}
