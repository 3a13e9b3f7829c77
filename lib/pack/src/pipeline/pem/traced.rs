//! The static environment map (thesis 5.1, figs 5.1 and 5.2c): the classic baseline for a
//! reflective object. Per parameter sample one cube map on a sphere at infinity (looked up
//! by the reflection direction alone), ray-traced from the object's centre with the object
//! itself left out of the scene — so its reflections of itself are lost, and every
//! reflection is placed as if the environment were infinitely far — not inferred from the
//! images. Each texel is the mean radiance over its patch of directions; each coarser MIP
//! level is the 2×2 box decimation of the level above it, the levels the container's
//! stored MIP mode takes its residuals from (SPEC.md 8.3), so that they are all zero.

use std::collections::BTreeMap;

use anyhow::Result;
use glam::{DVec3, Vec3};
use pis_compile::shell::cube::face_vector;
use pis_compile::TextureLayout;
use pis_format::mip::decimate;
use pis_scene::{Frame, Scene};
use pis_trace::probe::{incident_radiance, Footprint};
use pis_trace::TraceSettings;

use super::super::model::{InferredLayer, ObjectModel};
use super::super::represent::Job;
use super::fit::sphere_at_infinity;
use super::form::ShellForm;
use super::views::{face_resolution, shell_views};

/// The level-0 texels of every face of an `n × n` cube map as patches of directions, in the
/// layout's order (face after face, +X, −X, +Y, −Y, +Z, −Z; row after row): the direction
/// of texel (i, j)'s centre as the player's lookup has it ([`face_vector`] of
/// sc = 2(i + ½)/n − 1, tc = 2(j + ½)/n − 1), and half a texel along sc and tc.
pub fn texel_footprints(n: u32) -> Vec<Footprint> {
    let step = 2.0 / n as f64;
    (0..6u32)
        .flat_map(|face| {
            (0..n).flat_map(move |j| {
                (0..n).map(move |i| {
                    let (sc, tc) = (step * (i as f64 + 0.5) - 1.0, step * (j as f64 + 0.5) - 1.0);
                    let c = face_vector(face, sc, tc);
                    Footprint {
                        centre: c.as_vec3(),
                        half_u: (face_vector(face, sc + 0.5 * step, tc) - c).as_vec3(),
                        half_v: (face_vector(face, sc, tc + 0.5 * step) - c).as_vec3(),
                    }
                })
            })
        })
        .collect()
}

/// The RGB cube map of `layout` whose finest level holds `finest` (one value per level-0
/// texel, in [`texel_footprints`]' order), every coarser level of each face the 2×2 box
/// decimation of the level above it ([`decimate`]); texels × 3 values in the layout's order.
pub fn cube_map(layout: TextureLayout, finest: &[Vec3]) -> Vec<f32> {
    let (w0, h0) = layout.level_size(0);
    let per_face = w0 as usize * h0 as usize;
    assert_eq!(
        finest.len(),
        per_face * layout.faces as usize,
        "one value per level-0 texel of every face"
    );
    let mut x = vec![0.0f32; layout.texel_count() * 3];
    for face in 0..layout.faces {
        let mut level: Vec<f32> = finest[face as usize * per_face..(face as usize + 1) * per_face]
            .iter()
            .flat_map(|v| v.to_array())
            .collect();
        for m in 0..layout.levels {
            if m > 0 {
                let (w, h) = layout.level_size(m - 1);
                level = decimate(&level, w, h, 3);
            }
            let at = layout.face_texel(face, m, 0, 0) * 3;
            x[at..at + level.len()].copy_from_slice(&level);
        }
    }
    x
}

/// The static environment map of `scene` at `frame` seen from `origin`: every level-0 texel
/// of `layout` traced over its patch of directions with `settings` (their samples per
/// pixel are the samples per texel), object `omit` taken out of the scene, each channel
/// clipped at `clip`; then the MIP chain.
pub fn traced_cube(
    scene: &Scene,
    frame: &Frame,
    settings: &TraceSettings,
    origin: Vec3,
    layout: TextureLayout,
    omit: Option<u32>,
    clip: Vec3,
) -> Result<Vec<f32>> {
    let radiance =
        incident_radiance(scene, frame, settings, origin, &texel_footprints(layout.width), omit)?;
    Ok(cube_map(layout, &radiance.into_iter().map(|l| l.min(clip)).collect::<Vec<_>>()))
}

/// The brightest incident radiance worth storing for an object of Fresnel factor `f0`:
/// 1/F0 per channel. The player's reflection term is F times the map and F ≥ F0 (Schlick),
/// so beyond it a texel shows white on a display whatever it holds; clipped there, as the
/// inferred maps' traced samples are (thesis 5.9), a light's reflection, orders of
/// magnitude brighter than the rest, does not spread into a wide white blob on the coarser
/// MIP levels the player reads on curved parts.
pub fn radiance_clip(f0: [f32; 3]) -> Vec3 {
    Vec3::from_array(f0.map(|f| if f > 0.0 { 1.0 / f } else { f32::INFINITY }))
}

/// Object `o` as a static environment map: per point of the set (keys `keys`), the cube map
/// traced from the object's centre `origin` — where it stands at the set's first point,
/// carried along with the object at the others — with the object omitted, on a sphere at
/// infinity about `origin`, its face size chosen as the inferred maps' is; `model` already
/// holds the object's surface part.
#[allow(clippy::too_many_arguments)]
pub fn static_env(
    mut model: ObjectModel,
    job: &Job<'_>,
    o: usize,
    f0: [f32; 3],
    pixels: &[Vec<u32>],
    keys: &[Vec<u32>],
    largest: u32,
    origin: DVec3,
) -> Result<ObjectModel> {
    let set = job.set;
    let shell = sphere_at_infinity(origin);
    let n = face_resolution(set, o, &job.meshes, &shell, largest)?;
    let layout = TextureLayout::cube(n);
    let all: Vec<usize> = (0..set.frames.len()).collect();
    let views =
        shell_views(set, o, &job.meshes, &[(shell.clone(), layout, None)], 1, f0, (pixels, &all))?;
    let first = set.frames[0].instances[o].world_from_object.inverse();
    // The map does not depend on the camera: points whose objects and lights stand alike
    // (every point of a view-only space) share one trace.
    let mut textures: BTreeMap<Vec<u32>, Vec<f32>> = BTreeMap::new();
    for (p, (frame, k)) in set.frames.iter().zip(keys).enumerate() {
        let same = (0..p).find(|&q| {
            set.frames[q].instances == frame.instances && set.frames[q].lights == frame.lights
        });
        let cube = match same {
            Some(q) => textures[&keys[q]].clone(),
            None => {
                let centre = (frame.instances[o].world_from_object * first)
                    .transform_point3(origin.as_vec3());
                traced_cube(
                    &set.scene,
                    frame,
                    &set.trace,
                    centre,
                    layout,
                    Some(o as u32),
                    radiance_clip(f0),
                )?
            }
        };
        textures.insert(k.clone(), cube);
    }
    let form = Box::new(ShellForm {
        shell,
        layout,
        lookups: 1,
        channels: 3,
        order: 0,
        term: pis_format::Term::Reflection,
    });
    model.layers.push(InferredLayer::shell(
        pis_format::LayerKind::EnvDistant,
        (&job.plan.space, job.all),
        &model.stagger,
        textures,
        0,
        form,
        0,
    ));
    model.shells = Some(Box::new(super::terms::ReflectionTerms(views)));
    model.representation = "static environment map".to_string();
    model.why = format!(
        "--representation static-env: traced from the object's centre ({:.3}, {:.3}, {:.3}), {n}² per sample, {} rays per texel, object omitted, Fresnel from F0 {f0:?}",
        origin.x, origin.y, origin.z, set.trace.spp
    );
    Ok(model)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Mat4, Vec2};
    use pis_compile::filter::Taps;
    use pis_compile::shell::cube::{cube_face, cube_taps};
    use pis_scene::{Camera, Instance, Material, ObjectRole, Primitive, SceneObject};

    #[test]
    fn coarser_levels_are_the_decimation_of_the_finest() {
        let layout = TextureLayout::cube(8);
        let finest: Vec<Vec3> = (0..6 * 64)
            .map(|k| Vec3::new(k as f32, (k * 7 % 13) as f32, -(k as f32).sqrt()))
            .collect();
        let x = cube_map(layout, &finest);
        assert_eq!(x.len(), layout.texel_count() * 3);
        for face in 0..6 {
            for m in 1..layout.levels {
                let (w, _) = layout.level_size(m);
                for j in 0..w {
                    for i in 0..w {
                        for c in 0..3 {
                            let fine = |di: u32, dj: u32| {
                                x[layout.face_texel(face, m - 1, 2 * i + di, 2 * j + dj) * 3 + c]
                            };
                            let mean = 0.25 * (fine(0, 0) + fine(1, 0) + fine(0, 1) + fine(1, 1));
                            let coarse = x[layout.face_texel(face, m, i, j) * 3 + c];
                            assert!(
                                (coarse - mean).abs() <= 1e-4 * mean.abs().max(1.0),
                                "face {face} level {m} ({i}, {j})"
                            );
                        }
                    }
                }
            }
            // Level 0 is the given values, row after row.
            let t = layout.face_texel(face, 0, 3, 5);
            assert_eq!(x[t * 3], finest[face as usize * 64 + 5 * 8 + 3].x);
        }
        // The 1×1 level of a face is its mean.
        let mean: f32 = finest[..64].iter().map(|v| v.x).sum::<f32>() / 64.0;
        assert!((x[layout.face_texel(0, layout.levels - 1, 0, 0) * 3] - mean).abs() < 1e-3);
    }

    /// A quad emitting `l` with corners `c ± u ± v`.
    fn quad(c: Vec3, u: Vec3, v: Vec3, material: usize) -> Primitive {
        Primitive {
            positions: vec![c - u - v, c + u - v, c + u + v, c - u + v],
            normals: vec![u.cross(v).normalize(); 4],
            uvs: vec![Vec2::ZERO; 4],
            indices: vec![0, 1, 2, 0, 2, 3],
            material,
            ..Primitive::default()
        }
    }

    fn emitter(l: Vec3) -> Material {
        Material {
            base_color: [0.0, 0.0, 0.0, 1.0],
            metallic: 0.0,
            roughness: 1.0,
            specular: 0.0,
            emissive: l.to_array(),
            ..Default::default()
        }
    }

    /// The colour of wall half `k` (0..12) of the room below.
    fn colour(k: usize) -> Vec3 {
        Vec3::new(1.0 + k as f32, (k * 7 % 5) as f32 * 0.5, (k * 3 % 11) as f32 * 0.25)
    }

    /// The half of the room's walls that direction `d` from the centre meets: the cube face
    /// of `d`, split by the sign of the next axis' component.
    fn wall(d: Vec3) -> usize {
        let face = cube_face(d.as_dvec3()) as usize;
        let next = d[(face / 2 + 1) % 3];
        face * 2 + usize::from(next > 0.0)
    }

    /// A cubic room of side 2 about the origin, each wall two emitting halves of their own
    /// colour ([`wall`] numbers them), and a black square in front of the centre towards +Z,
    /// object 1.
    fn room() -> (Scene, Frame) {
        let mut walls = Vec::new();
        for face in 0..6 {
            let (a, sign) = (face / 2, if face % 2 == 0 { 1.0 } else { -1.0 });
            let (b, c) = ((a + 1) % 3, (a + 2) % 3);
            let axis = |k: usize, s: f32| {
                Vec3::from_array(std::array::from_fn(|i| if i == k { s } else { 0.0 }))
            };
            for half in 0..2 {
                let centre = axis(a, sign) + axis(b, if half == 1 { 0.5 } else { -0.5 });
                walls.push(quad(centre, axis(b, 0.5), axis(c, 1.0), face * 2 + half));
            }
        }
        let mut materials: Vec<Material> = (0..12).map(|k| emitter(colour(k))).collect();
        materials.push(emitter(Vec3::ZERO));
        let block = quad(Vec3::Z * 0.5, Vec3::X * 0.3, Vec3::Y * 0.3, 12);
        let objects = vec![
            SceneObject {
                name: "room".into(),
                role: ObjectRole::Diffuse,
                reflector: None,
                primitives: walls,
            },
            SceneObject {
                name: "mirror".into(),
                role: ObjectRole::Reflective,
                reflector: None,
                primitives: vec![block],
            },
        ];
        let scene = Scene {
            name: "room".into(),
            resolution: (1, 1),
            spp: 4,
            objects,
            materials,
            ..Default::default()
        };
        let camera = Camera {
            world_from_camera: Mat4::IDENTITY,
            yfov: 1.0,
            znear: 0.01,
            zfar: f32::INFINITY,
        };
        (
            scene,
            Frame {
                camera,
                lights: vec![],
                instances: vec![Instance { world_from_object: Mat4::IDENTITY }; 2],
            },
        )
    }

    /// What the player reads from the traced map in direction `d` at level of detail λ.
    fn lookup(layout: &TextureLayout, x: &[f32], d: Vec3, lambda: f64) -> Vec3 {
        let mut taps = Taps::default();
        cube_taps(layout, d.as_dvec3(), lambda, &mut taps);
        (0..taps.len).fold(Vec3::ZERO, |s, k| {
            s + Vec3::from_slice(&x[taps.cols[k] as usize * 3..taps.cols[k] as usize * 3 + 3])
                * taps.weights[k]
        })
    }

    /// The player's lookup of the traced map in a direction reads what the room shows in
    /// that direction: the faces, their orientation and the texel centres agree with the
    /// hardware model's cube map (SPEC.md 8.2). The black square is the object the map is
    /// made for, and is left out.
    #[test]
    fn the_lookup_reads_what_was_traced_in_its_direction() {
        let (scene, frame) = room();
        let layout = TextureLayout::cube(16);
        let x = traced_cube(
            &scene,
            &frame,
            &TraceSettings::new((1, 1), 4),
            Vec3::ZERO,
            layout,
            Some(1),
            Vec3::INFINITY,
        )
        .unwrap();
        let mut checked = 0;
        for k in 0..400 {
            let a = k as f32 * 0.713;
            let d = Vec3::new(a.sin() * (a * 1.3).cos(), (a * 0.7).cos(), (a * 2.1).sin() - 0.3)
                .normalize();
            // Directions a texel and a half or more from a colour edge read one wall half.
            let face = cube_face(d.as_dvec3()) as usize;
            let m = d.abs().max_element();
            let (sc, tc) = (d[(face / 2 + 1) % 3] / m, d[(face / 2 + 2) % 3] / m);
            let margin = 3.0 / 16.0;
            if sc.abs() < margin || 1.0 - sc.abs() < margin || 1.0 - tc.abs() < margin {
                continue;
            }
            let got = lookup(&layout, &x, d, 0.0);
            assert!(
                (got - colour(wall(d))).abs().max_element() < 1e-4,
                "{d}: read {got}, the room shows {}",
                colour(wall(d))
            );
            checked += 1;
        }
        assert!(checked > 100, "{checked} directions checked");
        let seen = traced_cube(
            &scene,
            &frame,
            &TraceSettings::new((1, 1), 4),
            Vec3::ZERO,
            layout,
            None,
            Vec3::INFINITY,
        )
        .unwrap();
        assert!(
            lookup(&layout, &seen, Vec3::new(0.01, 0.02, 1.0), 0.0).max_element() < 1e-6,
            "the square, not left out, is black"
        );
    }

    #[test]
    fn a_constant_environment_gives_a_constant_cube_map() {
        let (mut scene, frame) = room();
        let l = Vec3::new(0.3, 0.6, 1.2);
        scene.materials.iter_mut().take(12).for_each(|m| *m = emitter(l));
        let layout = TextureLayout::cube(8);
        let x = traced_cube(
            &scene,
            &frame,
            &TraceSettings::new((1, 1), 2),
            Vec3::new(0.1, -0.2, 0.3),
            layout,
            Some(1),
            Vec3::INFINITY,
        )
        .unwrap();
        assert_eq!(x.len(), layout.texel_count() * 3);
        for t in x.chunks_exact(3) {
            assert!((Vec3::from_slice(t) - l).abs().max_element() < 1e-5, "{t:?}");
        }
        // Clipped at 1/F0 per channel: F0 = 0.95 leaves 0.3 and 0.6, clips 1.2; F0 = 0 clips
        // nothing.
        let clip = radiance_clip([0.95, 0.95, 0.0]);
        assert_eq!(clip, Vec3::new(1.0 / 0.95, 1.0 / 0.95, f32::INFINITY));
        let x = traced_cube(
            &scene,
            &frame,
            &TraceSettings::new((1, 1), 2),
            Vec3::ZERO,
            layout,
            Some(1),
            Vec3::new(clip.x, clip.y, 1.0 / 0.95),
        )
        .unwrap();
        assert!(x
            .chunks_exact(3)
            .all(|t| (Vec3::from_slice(t) - Vec3::new(0.3, 0.6, 1.0 / 0.95)).abs().max_element()
                < 1e-5));
    }
}
