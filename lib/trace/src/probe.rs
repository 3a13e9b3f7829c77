//! Radiance arriving at a point from given directions: the tracer looking out from a point
//! instead of through a camera, as a traditional environment map is made (thesis 5.1,
//! fig. 5.1: "rendering six faces of cube from an object center"). Each direction stands
//! for a small patch of directions (a cube-map texel's, say), and its radiance is the mean
//! over jittered directions in the patch. One object may be omitted from the scene, as a
//! traditional environment map omits the object it is made for ("self-reflections are lost
//! since the object itself is omitted during EM construction"): the rays neither meet it
//! nor find it in the way of the light (no shadow, no indirect light of it).

use crate::error::TraceError;
use crate::integrator::{Integrator, PathContext};
use crate::sampling::{hash_keys, r2_point, Rng};
use crate::settings::TraceSettings;
use glam::Vec3;
use pis_scene::{Frame, Scene};
use rayon::prelude::*;
use std::borrow::Cow;

/// Footprints per parallel work unit (each unit has its own path context).
pub const FOOTPRINTS_PER_TASK: usize = 256;

/// A patch of directions: `centre + a·half_u + b·half_v` for a, b ∈ [−1, 1], normalized.
/// For a cube-map texel, `centre` is the direction of its centre and `half_u`, `half_v` are
/// half a texel along the face's axes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Footprint {
    pub centre: Vec3,
    pub half_u: Vec3,
    pub half_v: Vec3,
}

impl Footprint {
    /// The direction at (a, b) ∈ [−1, 1]² of the patch, unit length.
    pub fn direction(&self, a: f32, b: f32) -> Vec3 {
        (self.centre + self.half_u * a + self.half_v * b).normalize()
    }
}

/// Radiance arriving at `origin` from each of `footprints`, for `scene` at `frame` with
/// object `omit`, if any, taken out of it with the other parts of its reflector: per
/// footprint the mean of `settings.spp` rays from `origin` into the patch, spread over it by the R2 sequence with a per-footprint
/// shift (as a pixel's camera samples are). The rays are traced as a reflective object's
/// reflected rays are (one scattering event deep, seeing light spheres and, where they leave
/// the scene, the environment), so the result is comparable with the set's distant layer. Footprints are traced in parallel; every random
/// number comes from the footprint's index and the surface points the paths meet, so the
/// result does not depend on the thread count.
pub fn incident_radiance(
    scene: &Scene,
    frame: &Frame,
    settings: &TraceSettings,
    origin: Vec3,
    footprints: &[Footprint],
    omit: Option<u32>,
) -> Result<Vec<Vec3>, TraceError> {
    if settings.spp == 0 {
        return Err(TraceError::InvalidInput("0 samples per direction".into()));
    }
    if frame.instances.len() != scene.objects.len() {
        return Err(TraceError::InvalidInput(format!(
            "frame places {} objects, the scene has {}",
            frame.instances.len(),
            scene.objects.len()
        )));
    }
    // The object and the other parts of its reflector keep their indices (seeds hash object
    // indices) and lose their triangles.
    let scene = match omit {
        Some(o) if (o as usize) < scene.objects.len() => {
            let reflectors = scene.reflectors();
            let mut without = scene.clone();
            for (object, &r) in without.objects.iter_mut().zip(&reflectors) {
                if r == reflectors[o as usize] {
                    object.primitives.clear();
                }
            }
            Cow::Owned(without)
        }
        Some(o) => {
            return Err(TraceError::InvalidInput(format!(
                "object {o} to omit, the scene has {}",
                scene.objects.len()
            )))
        }
        None => Cow::Borrowed(scene),
    };
    let integrator = Integrator::new(&scene, frame, settings);
    let diffuse_left = settings.diffuse_bounces.max(1);
    let spp = settings.spp;
    let chunks: Vec<Vec<Vec3>> = footprints
        .par_chunks(FOOTPRINTS_PER_TASK)
        .enumerate()
        .map(|(c, chunk)| {
            let mut ctx = PathContext::default();
            chunk
                .iter()
                .enumerate()
                .map(|(k, f)| {
                    let seed = hash_keys(&[(c * FOOTPRINTS_PER_TASK + k) as u64]);
                    let shift = Rng::new(seed).next_2d();
                    let mut sum = Vec3::ZERO;
                    for s in 0..spp {
                        let u = r2_point(s, shift) * 2.0 - 1.0;
                        ctx.fallback_seed = hash_keys(&[seed, s as u64]);
                        sum += integrator.radiance(
                            origin,
                            f.direction(u.x, u.y),
                            1,
                            diffuse_left,
                            true,
                            None,
                            &mut ctx,
                        );
                    }
                    sum / spp as f32
                })
                .collect()
        })
        .collect();
    Ok(chunks.into_iter().flatten().collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Mat4, Vec2};
    use pis_scene::{
        Camera, Instance, Light, LightKind, Material, ObjectRole, Primitive, SceneObject,
    };

    /// An axis-aligned box between `lo` and `hi` of material `material` (12 triangles).
    fn cuboid(lo: Vec3, hi: Vec3, material: usize) -> Primitive {
        let corner = |k: usize| {
            Vec3::new(
                if k & 1 == 0 { lo.x } else { hi.x },
                if k & 2 == 0 { lo.y } else { hi.y },
                if k & 4 == 0 { lo.z } else { hi.z },
            )
        };
        let quads =
            [[0, 2, 6, 4], [1, 5, 7, 3], [0, 4, 5, 1], [2, 3, 7, 6], [0, 1, 3, 2], [4, 6, 7, 5]];
        let positions: Vec<Vec3> = (0..8).map(corner).collect();
        let indices = quads
            .iter()
            .flat_map(|q| [q[0], q[1], q[2], q[0], q[2], q[3]])
            .map(|i| i as u32)
            .collect();
        let normals = positions.iter().map(|p| (*p - (lo + hi) * 0.5).normalize()).collect();
        Primitive {
            positions,
            normals,
            uvs: vec![Vec2::ZERO; 8],
            indices,
            material,
            ..Primitive::default()
        }
    }

    /// A pure emitter: black, no specular lobe, so what a ray meets is its emission exactly.
    fn emitter(l: [f32; 3]) -> Material {
        Material {
            base_color: [0.0, 0.0, 0.0, 1.0],
            metallic: 0.0,
            roughness: 1.0,
            specular: 0.0,
            emissive: l,
            ..Default::default()
        }
    }

    const ROOM: Vec3 = Vec3::new(0.25, 0.5, 1.0);
    const BLOCKER: Vec3 = Vec3::new(4.0, 0.0, 0.0);

    /// A glowing room about the origin and a glowing red block on +X between it and the walls.
    fn room() -> (Scene, Frame) {
        let objects = vec![
            SceneObject {
                name: "room".into(),
                role: ObjectRole::Diffuse,
                reflector: None,
                primitives: vec![cuboid(Vec3::splat(-2.0), Vec3::splat(2.0), 0)],
            },
            SceneObject {
                name: "blocker".into(),
                role: ObjectRole::Reflective,
                reflector: None,
                primitives: vec![cuboid(
                    Vec3::new(0.5, -0.25, -0.25),
                    Vec3::new(0.75, 0.25, 0.25),
                    1,
                )],
            },
        ];
        let scene = Scene {
            name: "probe".into(),
            resolution: (1, 1),
            spp: 4,
            objects,
            materials: vec![emitter(ROOM.to_array()), emitter(BLOCKER.to_array())],
            ..Default::default()
        };
        let camera = Camera {
            world_from_camera: Mat4::IDENTITY,
            yfov: 1.0,
            znear: 0.01,
            zfar: f32::INFINITY,
        };
        let frame = Frame {
            camera,
            lights: vec![],
            instances: vec![Instance { world_from_object: Mat4::IDENTITY }; 2],
        };
        (scene, frame)
    }

    /// A footprint about `centre` spanning `half` along two axes across it.
    fn around(centre: Vec3, half: f32) -> Footprint {
        let u = centre.any_orthonormal_vector();
        Footprint { centre, half_u: u * half, half_v: centre.cross(u) * half }
    }

    fn directions() -> Vec<Footprint> {
        [
            Vec3::X,
            Vec3::NEG_X,
            Vec3::Y,
            Vec3::NEG_Y,
            Vec3::Z,
            Vec3::NEG_Z,
            Vec3::new(0.9, 0.1, -0.1),
        ]
        .map(|d| around(d.normalize(), 0.05))
        .to_vec()
    }

    #[test]
    fn the_omitted_object_does_not_appear() {
        let (scene, frame) = room();
        let settings = TraceSettings::new((1, 1), 4);
        let seen =
            incident_radiance(&scene, &frame, &settings, Vec3::ZERO, &directions(), None).unwrap();
        let (x, rest) = (seen[0], &seen[1..6]);
        assert!((x - BLOCKER).abs().max_element() < 1e-6, "+X: {x}");
        assert!((seen[6] - BLOCKER).abs().max_element() < 1e-6, "near +X: {}", seen[6]);
        assert!(rest.iter().all(|l| (*l - ROOM).abs().max_element() < 1e-6), "{rest:?}");
        let omitted =
            incident_radiance(&scene, &frame, &settings, Vec3::ZERO, &directions(), Some(1))
                .unwrap();
        assert!(omitted.iter().all(|l| (*l - ROOM).abs().max_element() < 1e-6), "{omitted:?}");
    }

    /// A footprint over the blocker's edge is the mean of both sides, in proportion to the
    /// part of the patch each covers; the result does not depend on the thread count.
    #[test]
    fn a_footprint_averages_over_its_patch() {
        let (scene, frame) = room();
        let settings = TraceSettings::new((1, 1), 64);
        // Directions (1, y, 0) meet the blocker for |y| ≤ 0.5 (its face at x = 0.5 spans
        // y ∈ [−0.25, 0.25]): the patch y ∈ [0.3, 0.7] is half on it.
        let edge = Footprint {
            centre: Vec3::new(1.0, 0.5, 0.0),
            half_u: Vec3::new(0.0, 0.2, 0.0),
            half_v: Vec3::new(0.0, 0.0, 0.05),
        };
        let l = incident_radiance(&scene, &frame, &settings, Vec3::ZERO, &[edge], None).unwrap()[0];
        let share = (l.x - ROOM.x) / (BLOCKER.x - ROOM.x);
        assert!((share - 0.5).abs() < 0.1, "{l}: {share} of the patch on the blocker");
        let many: Vec<Footprint> = (0..1000)
            .map(|k| {
                around(
                    Vec3::new(1.0, (k as f32 * 0.37).sin(), (k as f32 * 0.11).cos()).normalize(),
                    0.1,
                )
            })
            .collect();
        let one = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
        let a = one.install(|| {
            incident_radiance(&scene, &frame, &settings, Vec3::ZERO, &many, None).unwrap()
        });
        let b = incident_radiance(&scene, &frame, &settings, Vec3::ZERO, &many, None).unwrap();
        assert_eq!(a, b);
    }

    /// The omitted object casts no shadow on what the rays see: a lit floor below a block
    /// that hides it from the light reads as it does with the block placed far away.
    #[test]
    fn the_omitted_object_casts_no_shadow() {
        let white = Material {
            base_color: [0.8, 0.8, 0.8, 1.0],
            metallic: 0.0,
            roughness: 1.0,
            specular: 0.0,
            ..Default::default()
        };
        let objects = vec![
            SceneObject {
                name: "floor".into(),
                role: ObjectRole::Diffuse,
                reflector: None,
                primitives: vec![cuboid(Vec3::new(-3.0, -1.1, -3.0), Vec3::new(3.0, -1.0, 3.0), 0)],
            },
            SceneObject {
                name: "block".into(),
                role: ObjectRole::Reflective,
                reflector: None,
                primitives: vec![cuboid(Vec3::new(-0.5, 0.5, -0.5), Vec3::new(0.5, 0.7, 0.5), 0)],
            },
        ];
        let scene = Scene {
            name: "shadow".into(),
            resolution: (1, 1),
            spp: 4,
            objects,
            materials: vec![white],
            ..Default::default()
        };
        let light = Light {
            name: "sun".into(),
            kind: LightKind::Point,
            radiance: [20.0; 3],
            radius: 0.1,
            visible_camera: true,
            position: Vec3::new(0.0, 3.0, 0.0),
            direction: Vec3::NEG_Y,
        };
        let camera = Camera {
            world_from_camera: Mat4::IDENTITY,
            yfov: 1.0,
            znear: 0.01,
            zfar: f32::INFINITY,
        };
        let place = |block: Mat4| Frame {
            camera,
            lights: vec![light.clone()],
            instances: vec![
                Instance { world_from_object: Mat4::IDENTITY },
                Instance { world_from_object: block },
            ],
        };
        let mut settings = TraceSettings::new((1, 1), 8);
        settings.coherence_cell = Some(0.01);
        let down = [around(Vec3::new(0.05, -1.0, 0.1).normalize(), 0.05)];
        let from = Vec3::new(0.0, 0.0, 0.0);
        let shadowed =
            incident_radiance(&scene, &place(Mat4::IDENTITY), &settings, from, &down, None)
                .unwrap()[0];
        let omitted =
            incident_radiance(&scene, &place(Mat4::IDENTITY), &settings, from, &down, Some(1))
                .unwrap()[0];
        let away = incident_radiance(
            &scene,
            &place(Mat4::from_translation(Vec3::new(100.0, 0.0, 0.0))),
            &settings,
            from,
            &down,
            None,
        )
        .unwrap()[0];
        assert!(
            away.x > 0.05 && shadowed.x < 0.5 * away.x,
            "in the block's shadow {shadowed}, lit {away}"
        );
        assert!((omitted - away).abs().max_element() < 1e-5, "omitted {omitted}, far away {away}");
    }

    #[test]
    fn no_samples_or_an_unknown_object_is_refused() {
        let (scene, frame) = room();
        assert!(incident_radiance(
            &scene,
            &frame,
            &TraceSettings::new((1, 1), 0),
            Vec3::ZERO,
            &directions(),
            None
        )
        .is_err());
        assert!(incident_radiance(
            &scene,
            &frame,
            &TraceSettings::new((1, 1), 4),
            Vec3::ZERO,
            &directions(),
            Some(2)
        )
        .is_err());
    }
}
