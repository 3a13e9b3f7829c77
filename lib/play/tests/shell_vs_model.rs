//! The player's shell pipeline against the hardware model (SPEC.md 7.3, 8.2): a random cube
//! map x drawn through wgpu matches A_model·x (PSNR ≥ 60 dB over the pixels both cover) for
//! every shell shape, on a mirror sphere and on a bumpy, non-convex object, close up
//! (magnified), far away (minified across many MIP levels, footprints across cube edges) and
//! partly occluded; and the same with the convex-hull split (a subset of triangles drawing
//! the shell), with 1, 2 × 2 and 3 × 3 lookups per pixel. Runs on Mesa's lavapipe in CI.

mod common;

use common::*;
use glam::{Mat4, Vec3};
use pis_compile::shell::{shell_render_matrix, ShellObject};
use pis_compile::{scene_depth, DrawMesh, TextureLayout, Viewport};
use pis_play::{render_shell, ShellPipeline};

/// A sphere whose radius varies as 1 + 0.2·sin(3φ)·sin(2θ), with area-weighted vertex
/// normals: concave in places, so reflection rays meet the object's own neighbourhood.
fn bumpy() -> (Vec<[f32; 3]>, Vec<[f32; 3]>, Vec<u32>) {
    let m = uv_sphere(64, 32);
    let positions: Vec<[f32; 3]> = m
        .positions
        .iter()
        .zip(&m.uvs)
        .map(|(p, uv)| {
            let (ph, th) = (uv[0] * std::f32::consts::TAU, uv[1] * std::f32::consts::PI);
            let r = 1.0 + 0.2 * (3.0 * ph).sin() * (2.0 * th).sin();
            [p[0] * r, p[1] * r, p[2] * r]
        })
        .collect();
    let mut normals = vec![Vec3::ZERO; positions.len()];
    for t in m.indices.chunks_exact(3) {
        let [a, b, c] = [t[0], t[1], t[2]].map(|i| Vec3::from(positions[i as usize]));
        let n = (b - a).cross(c - a);
        for &i in t {
            normals[i as usize] += n;
        }
    }
    // The seam's duplicated vertices and the poles: average the normals of coincident
    // positions so that the surface is smooth.
    let mut merged = normals.clone();
    for i in 0..positions.len() {
        for j in 0..positions.len() {
            if i != j && Vec3::from(positions[i]).distance(Vec3::from(positions[j])) < 1e-6 {
                merged[i] += normals[j];
            }
        }
    }
    let normals = merged.iter().map(|n| n.normalize_or_zero().to_array()).collect();
    (positions, normals, m.indices)
}

#[test]
fn shells_match_the_model() {
    let Some(gpu) = gpu_or_skip("shells_match_the_model") else { return };
    let pipeline = ShellPipeline::new(&gpu);
    let vp = Viewport { width: 200, height: 150 };
    let sphere = uv_sphere(48, 24);
    let ball = (sphere.positions.clone(), sphere.positions.clone(), sphere.indices.clone());
    let objects = [("ball", ball), ("bumpy", bumpy())];
    let occluder = quad(-2.0, -0.2, -2.0, -0.3, 1.4);
    // Views: close (the cube map magnified), far (minified: coarse levels and footprints
    // across cube edges), and one where every other triangle skips the shell.
    let views: [(&str, [f32; 3], f32, u32, bool); 3] = [
        ("close", [0.4, 0.7, 2.4], 1.0, 24, false),
        ("far", [-2.5, 1.8, 7.0], 0.45, 64, false),
        ("hull-split", [1.5, 0.3, 2.6], 0.9, 32, true),
    ];
    let mut worst = f64::INFINITY;
    let mut failures = vec![];
    for (oname, (positions, normals, indices)) in &objects {
        let drawn: Vec<bool> = (0..indices.len() / 3).map(|t| t % 2 == 0).collect();
        for (vi, (vname, eye, fovy, size, split)) in views.into_iter().enumerate() {
            let clip = camera(vp, eye, [0.0, 0.0, 0.0], fovy);
            let occ = DrawMesh {
                positions: &occluder.positions,
                uvs: &occluder.uvs,
                indices: &occluder.indices,
                clip_from_object: clip,
            };
            let depth = scene_depth(vp, &[occ], None).unwrap();
            let layout = TextureLayout::cube(size);
            let x = random_rgba(layout.texel_count(), 3 + size as u64);
            for (si, (sname, shell)) in shells().into_iter().enumerate() {
                // One lookup per pixel, 2 × 2 or 3 × 3 (SPEC.md 8.2), each shape with each.
                let lookups = 1 + ((si + vi) % 3) as u32;
                let object = ShellObject {
                    positions,
                    normals,
                    indices,
                    clip_from_object: clip,
                    world_from_object: Mat4::IDENTITY,
                    eye: Vec3::from(eye),
                    shell,
                    layout,
                    drawn: split.then_some(&drawn[..]),
                    lookups,
                };
                let a = shell_render_matrix(vp, &object, Some(&depth)).unwrap();
                let want = predict(&a, &x);
                let got = render_shell(&gpu, &pipeline, vp, &[occ], &object, &x).unwrap();
                let c = compare(&want, &got);
                let name = format!("shell-{oname}-{vname}-{sname}-lookups-{lookups}");
                eprintln!(
                    "{name}: PSNR {:.2} dB over {} pixels, {} coverage mismatches, {:.2} taps/row",
                    c.psnr_db,
                    c.both,
                    c.coverage_mismatch,
                    a.cols.len() as f64 / a.rows().max(1) as f64
                );
                worst = worst.min(c.psnr_db);
                if c.psnr_db < 60.0 || c.coverage_mismatch * 1000 > c.both || c.both < 500 {
                    let dir = write_failure_images(&name, &want, &got);
                    failures.push(format!("{name}: {c:?} (images in {})", dir.display()));
                }
            }
        }
    }
    eprintln!("worst PSNR {worst:.2} dB");
    assert!(failures.is_empty(), "{failures:#?}");
}
