//! The player's reflection term (SPEC.md 8.2, 9; thesis ch. 5) on files written with
//! pis-format's writer: a reflective sphere with a local shell (RGBA, premultiplied, order
//! 0) over a distant shell (RGB, order 1).
//!
//! - Constant shells, f0 = 1 (F ≡ 1): every pixel of the sphere is local.rgb + (1 − α)·
//!   distant.rgb, within 1e-3; between two parameter samples of different colours, their
//!   blend by the multilinear weight; multisampled, every pixel is its covered fraction of
//!   that colour.
//! - Random cube maps (every face and stored MIP level), f0 = (0.2, 0.5, 0.9), a moved and
//!   turned object, the file's camera and an off-manifold one: the frame against the hardware
//!   model, F ⊙ (A_L·p + (1 − A_L·α) ⊙ A_D·d) with A_L, A_D from
//!   `pis_compile::shell::shell_render_matrix` and F from `pis_compile::shell::fresnel` at
//!   the surface point each pixel centre sees, ≥ 50 dB over the object's pixels; again with
//!   the mesh's first triangles marked as on the convex hull (SPEC.md 6.5), where the model
//!   draws the distant shell alone.
//! - A reflection term of three shells is not supported: opening the file says so.

mod common;

use std::path::{Path, PathBuf};
use std::sync::Arc;

use common::*;
use glam::{DVec3, Mat4, Vec3};
use pis_compile::shell::{fresnel, shell_render_matrix, Shell, ShellObject};
use pis_compile::{TextureLayout, Viewport};
use pis_format::samples::{encode_block, uv_sphere};
use pis_format::*;
use pis_play::camera::{mat4_from_rows, projection};
use pis_play::{
    Blend, CameraChoice, FloatImage, FrameRequest, PlayError, Player, PlayerOptions, ViewCamera,
};

const SIZE: (u32, u32) = (96, 72);
const CAMERA_EYE: [f32; 3] = [0.4, 0.6, 3.2];

/// A shell of a file: kind, channels, shape, origin, parameters, face size.
#[derive(Clone, Copy)]
struct ShellSpec {
    kind: LayerKind,
    channels: u8,
    shape: ShellShape,
    origin: [f32; 3],
    params: [f32; 6],
    size: u32,
    /// Lookups per pixel side (SPEC.md 8.2).
    lookups: u32,
}

/// The local shell: an ellipsoid around the sphere.
const LOCAL: ShellSpec = ShellSpec {
    kind: LayerKind::EnvLocal,
    channels: 4,
    shape: ShellShape::Ellipsoid,
    origin: [0.05, -0.1, 0.02],
    params: [1.6, 1.3, 1.5, 0.0, 0.0, 0.0],
    size: 12,
    lookups: 1,
};
/// The distant shell: a box.
const DISTANT: ShellSpec = ShellSpec {
    kind: LayerKind::EnvDistant,
    channels: 3,
    shape: ShellShape::Box,
    origin: [0.0, 0.2, 0.0],
    params: [-3.0, -1.5, -4.0, 4.0, 3.0, 3.5],
    size: 20,
    lookups: 1,
};

impl ShellSpec {
    fn layout(&self) -> TextureLayout {
        TextureLayout::cube(self.size)
    }

    /// The hardware model's shell.
    fn model(&self) -> Shell {
        let mut v = [0.0f32; 12];
        v[..3].copy_from_slice(&self.origin);
        v[3..9].copy_from_slice(&self.params);
        Shell::from_placement(self.shape.code() as u16, &v).expect("a closed shell")
    }
}

/// The camera of the file: at `eye`, looking at the origin.
fn file_camera(eye: [f32; 3]) -> Camera {
    let world_from_camera =
        pis_compile::transform::look_at(Vec3::from(eye), Vec3::ZERO, Vec3::Y).inverse();
    let mut rows = [0.0; 12];
    for r in 0..3 {
        rows[r * 4..r * 4 + 4].copy_from_slice(&world_from_camera.row(r).to_array());
    }
    Camera { world_from_camera: rows, yfov: 0.8, znear: 0.1, zfar: 50.0 }
}

/// A shell layer of the reflection term at `order` whose texture at each sample of the
/// space's one dimension is `textures[k]` (one texture: the layer does not vary), linear,
/// `channels` values per texel in the cube layout's order (every face's stored MIP chain).
fn shell_layer(spec: &ShellSpec, order: u8, textures: &[Vec<f32>]) -> Layer<Codestream> {
    let varies = textures.len() > 1;
    let layer = Layer {
        kind: spec.kind,
        mapping: Mapping::Shell,
        channels: spec.channels,
        mip_mode: MipMode::Stored,
        term: Term::Reflection,
        order,
        combine: Combine::Over,
        basis: 0,
        gamma: 1.0,
        depends_on: if varies { DepMask::of(&[0]) } else { DepMask::NONE },
        blocks: vec![],
    };
    let block = Block {
        width: spec.size,
        height: spec.size,
        placement: Placement::Shell {
            shape: spec.shape,
            origin: spec.origin,
            params: spec.params,
            lookups: spec.lookups,
        },
        levels: vec![],
    };
    let (extent, counts): (Vec<u32>, Vec<Vec<u32>>) = if varies {
        (vec![textures.len() as u32], vec![vec![1], vec![textures.len() as u32]])
    } else {
        (vec![], vec![vec![]])
    };
    let block = encode_block(&layer, block, &extent, &counts, textures, CodecId::Lossless)
        .expect("encodes");
    Layer { blocks: vec![block], ..layer }
}

/// A file of one reflective unit sphere (normals from its mesh) with `f0`, placed by
/// `world`, with `layers`, over a dimension of `samples` values, seen by one camera.
fn write_file(
    dir: &Path,
    name: &str,
    f0: [f32; 3],
    world: [f32; 12],
    samples: usize,
    layers: Vec<Layer<Codestream>>,
) -> PathBuf {
    write_mesh_file(dir, name, f0, world, samples, layers, uv_sphere(1.0, 48, 24))
}

/// [`write_file`] with `mesh` for the sphere.
fn write_mesh_file(
    dir: &Path,
    name: &str,
    f0: [f32; 3],
    world: [f32; 12],
    samples: usize,
    layers: Vec<Layer<Codestream>>,
    mesh: pis_format::Mesh,
) -> PathBuf {
    let space = ParameterSpace {
        dims: vec![Dimension {
            name: "light".into(),
            kind: DimensionKind::Light,
            periodic: false,
            unit: String::new(),
            block_size: 2,
            values: (0..samples).map(|k| k as f32).collect(),
        }],
    };
    let cameras = CameraTable {
        width: SIZE.0,
        height: SIZE.1,
        depends_on: DepMask::NONE,
        cameras: vec![file_camera(CAMERA_EYE)],
    };
    let object = Object {
        name: "mirror".into(),
        role: ObjectRole::Reflective,
        shading: Shading { f0, ior: 1.5, absorption: [0.0; 3] },
        stagger: vec![0],
        transforms: TransformTable::fixed(world),
        mesh,
        layers,
    };
    let path = dir.join(name);
    write(&path, &Container { space, cameras, objects: vec![object], provenance: None })
        .expect("writes");
    path
}

/// A cube texture of one colour: `colour` for every texel of every face and level.
fn constant(spec: &ShellSpec, colour: &[f32]) -> Vec<f32> {
    assert_eq!(colour.len(), spec.channels as usize);
    (0..spec.layout().texel_count()).flat_map(|_| colour.iter().copied()).collect()
}

fn open(gpu: &Arc<pis_play::Gpu>, path: &Path, blend: Blend, msaa: u32) -> Player {
    Player::open(gpu.clone(), path, PlayerOptions { workers: 1, blend, msaa, ..Default::default() })
        .expect("opens")
}

fn at(point: f32, camera: CameraChoice) -> FrameRequest {
    FrameRequest { point: vec![point], camera }
}

/// The largest difference from `want` over the pixels the object covers (alpha 1), and how
/// many it covers.
fn worst_inside(img: &FloatImage, ids: &[u32], want: [f32; 3]) -> (f32, usize) {
    let mut worst = 0.0f32;
    let mut n = 0;
    for (p, &id) in ids.iter().enumerate() {
        if id == 0 {
            n += 1;
            let px = img.pixel(p);
            assert_eq!(px[3], 1.0, "pixel {p}: alpha");
            worst = (0..3).map(|c| (px[c] - want[c]).abs()).fold(worst, f32::max);
        } else {
            assert_eq!(img.pixel(p), [0.0; 4], "pixel {p} off the sphere");
        }
    }
    (worst, n)
}

/// Premultiplied local colours (α = 0.5) and distant colours of two parameter samples.
const LOCAL_RGBA: [[f32; 4]; 2] = [[0.3, 0.1, 0.05, 0.5], [0.05, 0.25, 0.2, 0.5]];
const DISTANT_RGB: [[f32; 3]; 2] = [[0.2, 0.6, 0.9], [0.8, 0.4, 0.1]];

/// local.rgb + (1 − α)·distant.rgb of sample k.
fn over(k: usize) -> [f32; 3] {
    let (l, d) = (LOCAL_RGBA[k], DISTANT_RGB[k]);
    [0, 1, 2].map(|c| l[c] + (1.0 - l[3]) * d[c])
}

#[test]
fn constant_shells_composite_over_and_blend_by_weight() {
    let test = "constant_shells_composite_over_and_blend_by_weight";
    let Some(gpu) = gpu_or_skip(test) else { return };
    let gpu = Arc::new(gpu);
    let dir = tempfile::tempdir().unwrap();
    let local = shell_layer(
        &LOCAL,
        0,
        &[constant(&LOCAL, &LOCAL_RGBA[0]), constant(&LOCAL, &LOCAL_RGBA[1])],
    );
    let distant = shell_layer(
        &DISTANT,
        1,
        &[constant(&DISTANT, &DISTANT_RGB[0]), constant(&DISTANT, &DISTANT_RGB[1])],
    );
    let path =
        write_file(dir.path(), "constant.pis", [1.0; 3], IDENTITY_3X4, 2, vec![local, distant]);
    let mut player = open(&gpu, &path, Blend::Multilinear, 1);
    for (point, w) in [(0.0f32, 0.0f32), (1.0, 1.0), (0.3, 0.3)] {
        let (img, ids, stats) = player.render_ids(&at(point, CameraChoice::Sample), SIZE).unwrap();
        let (a, b) = (over(0), over(1));
        let want = [0, 1, 2].map(|c| (1.0 - w) * a[c] + w * b[c]);
        let (worst, covered) = worst_inside(&img, &ids, want);
        eprintln!("{test}: point {point}: {covered} pixels, worst difference {worst:.2e} from {want:?}; {} shell draws", stats.shell_draws);
        assert!(covered > 1000, "the sphere covers {covered} pixels");
        assert!(worst <= 1e-3, "point {point}: {worst}");
        let samples = if w == 0.0 || w == 1.0 { 1 } else { 2 };
        assert_eq!((stats.shell_draws, stats.surface_draws), (samples, 0));
    }
    // Multisampled (the box resolve): each pixel is its covered fraction of the colour.
    let mut four = open(&gpu, &path, Blend::Nearest, 4);
    if four.multisample().samples != 4 {
        eprintln!(
            "{test}: multisampling skipped: {}",
            four.multisample().note.clone().unwrap_or_default()
        );
        return;
    }
    let (img, _) = four.render_image(&at(0.0, CameraChoice::Sample), SIZE).unwrap();
    let want = over(0);
    let (mut partial, mut worst) = (0, 0.0f32);
    for p in 0..(SIZE.0 * SIZE.1) as usize {
        let px = img.pixel(p);
        partial += (px[3] > 0.0 && px[3] < 1.0) as usize;
        worst = (0..3).map(|c| (px[c] - px[3] * want[c]).abs()).fold(worst, f32::max);
    }
    eprintln!("{test}: 4 samples: {partial} partly covered pixels, worst difference {worst:.2e}");
    assert!(partial > 50 && worst <= 1e-3, "{partial} partly covered, worst {worst}");
}

/// The surface point the centre of pixel (x, y) sees: the nearest hit of the ray from `eye`
/// on the world-space triangles, with its position and the normal interpolated at the hit's
/// barycentric coordinates (the perspective-correct interpolation the GPU does).
fn surface_at(
    clip_from_world: Mat4,
    eye: DVec3,
    triangles: &[[(DVec3, DVec3); 3]],
    x: u32,
    y: u32,
) -> Option<(DVec3, DVec3)> {
    let ndc = glam::Vec2::new(
        (x as f32 + 0.5) / SIZE.0 as f32 * 2.0 - 1.0,
        1.0 - (y as f32 + 0.5) / SIZE.1 as f32 * 2.0,
    );
    let far = clip_from_world.inverse().project_point3(ndc.extend(0.5)).as_dvec3();
    let dir = (far - eye).normalize();
    let mut best: Option<(f64, DVec3, DVec3)> = None;
    for t in triangles {
        let (e1, e2) = (t[1].0 - t[0].0, t[2].0 - t[0].0);
        let p = dir.cross(e2);
        let det = e1.dot(p);
        if det.abs() < 1e-12 {
            continue;
        }
        let s = eye - t[0].0;
        let b1 = s.dot(p) / det;
        let q = s.cross(e1);
        let b2 = dir.dot(q) / det;
        let dist = e2.dot(q) / det;
        if b1 < -1e-9
            || b2 < -1e-9
            || b1 + b2 > 1.0 + 1e-9
            || dist <= 0.0
            || best.is_some_and(|b| b.0 <= dist)
        {
            continue;
        }
        let n = t[0].1 * (1.0 - b1 - b2) + t[1].1 * b1 + t[2].1 * b2;
        best = Some((dist, eye + dir * dist, n));
    }
    best.map(|(_, p, n)| (p, n))
}

/// The frame the hardware model predicts: per pixel the model's rows of both shells,
/// F ⊙ (A_L·p + (1 − A_L·α) ⊙ A_D·d), alpha 1; F from `fresnel` at the surface point the
/// pixel centre sees. The local shell is drawn on the triangles `object.drawn` marks; the
/// distant shell on all.
fn model_frame(object: &ShellObject, f0: [f32; 3], local: &[f32], distant: &[f32]) -> FloatImage {
    let vp = Viewport { width: SIZE.0, height: SIZE.1 };
    let a_l = shell_render_matrix(
        vp,
        &ShellObject { shell: LOCAL.model(), layout: LOCAL.layout(), ..*object },
        None,
    )
    .unwrap();
    let a_d = shell_render_matrix(
        vp,
        &ShellObject { shell: DISTANT.model(), layout: DISTANT.layout(), drawn: None, ..*object },
        None,
    )
    .unwrap();
    if object.drawn.is_none() {
        assert_eq!(a_l.pixels, a_d.pixels, "both shells are drawn on the same pixels");
    }
    let world = object.world_from_object;
    let corner = |i: u32| {
        let i = i as usize;
        (
            (world * Vec3::from(object.positions[i]).extend(1.0)).truncate().as_dvec3(),
            world.transform_vector3(Vec3::from(object.normals[i])).as_dvec3(),
        )
    };
    let triangles: Vec<[(DVec3, DVec3); 3]> = object
        .indices
        .chunks_exact(3)
        .map(|t| [corner(t[0]), corner(t[1]), corner(t[2])])
        .collect();
    let clip_from_world = object.clip_from_object * world.inverse();
    let eye = object.eye.as_dvec3();
    let mut img = FloatImage {
        width: SIZE.0,
        height: SIZE.1,
        rgba: vec![0.0; (SIZE.0 * SIZE.1 * 4) as usize],
    };
    for r in 0..a_d.rows() {
        let p = a_d.pixels[r];
        let lookup = |a: &pis_compile::RenderMatrix, x: &[f32], channels: usize| {
            let Ok(r) = a.pixels.binary_search(&p) else { return [0.0f64; 4] };
            let (cols, vals) = a.row(r);
            let mut c = [0.0f64; 4];
            for (&col, &v) in cols.iter().zip(vals) {
                for (k, ck) in c.iter_mut().enumerate().take(channels) {
                    *ck += v as f64 * x[col as usize * channels + k] as f64;
                }
            }
            c
        };
        let (l, d) = (lookup(&a_l, local, 4), lookup(&a_d, distant, 3));
        let Some((pos, n)) = surface_at(clip_from_world, eye, &triangles, p % SIZE.0, p / SIZE.0)
        else {
            continue;
        };
        let f = fresnel(DVec3::from(f0.map(f64::from)), pos, n, eye);
        for c in 0..3 {
            img.rgba[4 * p as usize + c] = (f[c] * (l[c] + (1.0 - l[3]) * d[c])) as f32;
        }
        img.rgba[4 * p as usize + 3] = 1.0;
    }
    img
}

/// Random premultiplied RGBA texels: α in [0, 1), colour in [0, α).
fn random_premultiplied(texels: usize, seed: u64) -> Vec<f32> {
    let r = random(texels * 4, seed);
    (0..texels)
        .flat_map(|t| {
            [
                r[4 * t] * r[4 * t + 3],
                r[4 * t + 1] * r[4 * t + 3],
                r[4 * t + 2] * r[4 * t + 3],
                r[4 * t + 3],
            ]
        })
        .collect()
}

/// Random local (premultiplied, from `seed`) and distant (from `seed + 1`) cube maps, and
/// the sphere's placement: turned 30° about y and moved, as rows and as a matrix.
fn random_shells_on_a_turned_sphere(seed: u64) -> (Vec<f32>, Vec<f32>, [f32; 12], Mat4) {
    let local = random_premultiplied(LOCAL.layout().texel_count(), seed);
    let distant = random(DISTANT.layout().texel_count() * 3, seed + 1);
    let world_rows = pis_format::samples::rotate_y_translate(30.0, [0.1, -0.05, 0.0]);
    (local, distant, world_rows, mat4_from_rows(&world_rows))
}

/// The layers of one sample: the local shell `local` (order 0) over the distant `distant`.
fn local_over_distant(local: &[f32], distant: &[f32], lookups: u32) -> Vec<Layer<Codestream>> {
    vec![
        shell_layer(&ShellSpec { lookups, ..LOCAL }, 0, &[local.to_vec()]),
        shell_layer(&ShellSpec { lookups, ..DISTANT }, 1, &[distant.to_vec()]),
    ]
}

/// The file camera's clip-from-world matrix at [`SIZE`].
fn file_clip_from_world() -> Mat4 {
    let cam = file_camera(CAMERA_EYE);
    projection(cam.yfov, cam.znear, cam.zfar, SIZE.0, SIZE.1)
        * mat4_from_rows(&cam.world_from_camera).inverse()
}

#[test]
fn random_shells_match_the_hardware_model() {
    let test = "random_shells_match_the_hardware_model";
    let Some(gpu) = gpu_or_skip(test) else { return };
    let gpu = Arc::new(gpu);
    let dir = tempfile::tempdir().unwrap();
    let (local, distant, world_rows, world) = random_shells_on_a_turned_sphere(11);
    let mesh = uv_sphere(1.0, 48, 24);
    let normals = mesh.normals.clone().unwrap();
    let free = ViewCamera {
        eye: Vec3::new(-1.3, 0.9, 2.6),
        target: Vec3::new(0.1, 0.0, 0.0),
        up: Vec3::Y,
        yfov_rad: 0.9,
        near: 0.1,
        far: 50.0,
    };
    let views = [
        ("file camera", CameraChoice::Sample, file_clip_from_world(), Vec3::from(CAMERA_EYE)),
        (
            "free camera",
            CameraChoice::Free(free),
            free.projection(SIZE) * free.view_matrix(),
            free.eye,
        ),
    ];
    let mut failures = Vec::new();
    // One lookup per pixel, then 2 × 2 and 3 × 3 (SPEC.md 8.2).
    for (f0, lookups) in
        [([1.0f32; 3], 1), ([0.2, 0.5, 0.9], 1), ([1.0; 3], 2), ([0.2, 0.5, 0.9], 3)]
    {
        let path = write_file(
            dir.path(),
            &format!("random-{lookups}.pis"),
            f0,
            world_rows,
            1,
            local_over_distant(&local, &distant, lookups),
        );
        let mut player = open(&gpu, &path, Blend::Nearest, 1);
        for (vname, camera, clip_from_world, eye) in views {
            let object = ShellObject {
                positions: &mesh.positions,
                normals: &normals,
                indices: &mesh.indices,
                clip_from_object: clip_from_world * world,
                world_from_object: world,
                eye,
                shell: LOCAL.model(),
                layout: LOCAL.layout(),
                drawn: None,
                lookups,
            };
            let want = model_frame(&object, f0, &local, &distant);
            let (got, stats) = player.render_image(&at(0.0, camera), SIZE).unwrap();
            let c = compare(&want, &got);
            let name =
                format!("reflection-f0-{}-{}-lookups-{lookups}", f0[0], vname.replace(' ', "-"));
            eprintln!("{test}: f0 {f0:?}, {lookups}×{lookups} lookups, {vname}: PSNR {:.2} dB over {} pixels, {} coverage mismatches; {} shell draw(s)", c.psnr_db, c.both, c.coverage_mismatch, stats.shell_draws);
            if c.psnr_db < 50.0
                || c.coverage_mismatch * 200 > c.both
                || c.both < 1000
                || stats.shell_draws != 1
            {
                let dir = write_failure_images(&name, &want, &got);
                failures.push(format!("{name}: {c:?} (images in {})", dir.display()));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// Hull triangles (SPEC.md 6.5, thesis 5.7) draw the distant shell alone: the frame of a
/// sphere whose first half of triangles is marked as on the hull matches the model with the
/// local shell drawn on the other half only, and differs from the model without the split.
#[test]
fn hull_triangles_draw_the_distant_shell_only() {
    let test = "hull_triangles_draw_the_distant_shell_only";
    let Some(gpu) = gpu_or_skip(test) else { return };
    let gpu = Arc::new(gpu);
    let dir = tempfile::tempdir().unwrap();
    let (local, distant, world_rows, world) = random_shells_on_a_turned_sphere(21);
    let mut mesh = uv_sphere(1.0, 48, 24);
    let triangles = mesh.indices.len() / 3;
    mesh.hull_triangles = (triangles / 2) as u32;
    let drawn: Vec<bool> = (0..triangles).map(|t| t >= triangles / 2).collect();
    let normals = mesh.normals.clone().unwrap();
    let f0 = [0.2f32, 0.5, 0.9];
    let path = write_mesh_file(
        dir.path(),
        "hull.pis",
        f0,
        world_rows,
        1,
        local_over_distant(&local, &distant, 2),
        mesh.clone(),
    );
    let mut player = open(&gpu, &path, Blend::Nearest, 1);
    let object = ShellObject {
        positions: &mesh.positions,
        normals: &normals,
        indices: &mesh.indices,
        clip_from_object: file_clip_from_world() * world,
        world_from_object: world,
        eye: Vec3::from(CAMERA_EYE),
        shell: LOCAL.model(),
        layout: LOCAL.layout(),
        drawn: Some(&drawn),
        lookups: 2,
    };
    let want = model_frame(&object, f0, &local, &distant);
    let unsplit = model_frame(&ShellObject { drawn: None, ..object }, f0, &local, &distant);
    let (got, _) = player.render_image(&at(0.0, CameraChoice::Sample), SIZE).unwrap();
    let (c, u) = (compare(&want, &got), compare(&unsplit, &got));
    eprintln!("{test}: PSNR {:.2} dB over {} pixels, {} coverage mismatches; against the model without the split {:.2} dB", c.psnr_db, c.both, c.coverage_mismatch, u.psnr_db);
    if c.psnr_db < 50.0 || c.coverage_mismatch * 200 > c.both || c.both < 1000 || u.psnr_db > 40.0 {
        let dir = write_failure_images(test, &want, &got);
        panic!("{c:?}, without the split {u:?} (images in {})", dir.display());
    }
}

#[test]
fn three_reflection_shells_are_not_supported() {
    let test = "three_reflection_shells_are_not_supported";
    let Some(gpu) = gpu_or_skip(test) else { return };
    let dir = tempfile::tempdir().unwrap();
    let mut middle = LOCAL;
    middle.params = [2.0, 1.8, 2.0, 0.0, 0.0, 0.0];
    let layers = vec![
        shell_layer(&LOCAL, 0, &[constant(&LOCAL, &LOCAL_RGBA[0])]),
        shell_layer(&middle, 1, &[constant(&middle, &LOCAL_RGBA[1])]),
        shell_layer(&DISTANT, 2, &[constant(&DISTANT, &DISTANT_RGB[0])]),
    ];
    let path = write_file(dir.path(), "three.pis", [1.0; 3], IDENTITY_3X4, 1, layers);
    match Player::open(Arc::new(gpu), &path, PlayerOptions { workers: 1, ..Default::default() }) {
        Err(e @ PlayError::File(pis_format::Error::NotSupported(_))) => {
            eprintln!("{test}: {e}");
            assert!(e.to_string().contains("3 shells in the reflection term"), "{e}");
        }
        Err(e) => panic!("{test}: {e}"),
        Ok(_) => panic!("{test}: opened"),
    }
}
