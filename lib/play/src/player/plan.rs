//! What a frame draws, decided from the request before anything is decoded: the objects'
//! transforms, the camera, and per object the textures of its surface layers and the shells
//! of its reflection or lens terms at the weighted parameter samples, each texture named by
//! the pyramid level images it sums.

use pis_compile::shell::Shell;
use pis_compile::TextureTransform;
use pis_format::blocks::{level_image_index, BlockGrid};
use pis_format::{DepMask, PisReader, Placement, StreamRef};

use super::objects::{content, ObjectGpu};
use super::options::FrameRequest;
use super::relight::Relight;
use crate::blend::{check_point, merge_for_mask, nearest_sample, weighted_samples, Blend};
use crate::camera::{mat4_from_rows, projection, CameraChoice};
use crate::error::PlayError;

/// A rebuilt texture: object, layer, block, the image of every pyramid level it sums.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub(super) struct TextureKey {
    pub(super) object: u32,
    pub(super) layer: u32,
    pub(super) block: u32,
    pub(super) images: Vec<u32>,
}

/// One texture a frame draws.
pub(super) struct Wanted {
    pub(super) draw: usize,
    pub(super) key: TextureKey,
    pub(super) weight: f32,
    /// Per channel, a relightable layer's coefficient weight for the frame's lights.
    pub(super) tint: [f32; 3],
    pub(super) transform: TextureTransform,
    pub(super) repeat: [bool; 2],
    /// A relightable layer's coefficient: the layer it sums into with the other
    /// coefficients of its term, order, block and parameter sample (object, term, order,
    /// block, then the sample), drawn as their sum (`relit.rs`).
    pub(super) relit: Option<Vec<u32>>,
}

/// One reflection term a frame draws: an object's shells at one parameter sample.
pub(super) struct WantedReflection {
    pub(super) draw: usize,
    pub(super) weight: f32,
    /// Per shell of the term, in order: its texture, its geometry and its lookups per pixel
    /// side (SPEC.md 8.2).
    pub(super) shells: Vec<(TextureKey, Shell, u32)>,
}

/// What a frame draws: per object its clip and world transforms, the frame's camera
/// position, and the textures and reflection terms of the parameter samples.
pub(super) struct Plan {
    pub(super) clips: Vec<glam::Mat4>,
    pub(super) worlds: Vec<glam::Mat4>,
    pub(super) eye: glam::Vec3,
    pub(super) surfaces: Vec<Wanted>,
    pub(super) reflections: Vec<WantedReflection>,
    /// Lens objects' shells per parameter sample (both terms look them up).
    pub(super) lenses: Vec<WantedReflection>,
    pub(super) clip_from_world: glam::Mat4,
}

impl Plan {
    /// What a frame draws: the objects' transforms, the camera position, and per object the
    /// textures of its surface layers and its reflection terms at the parameter samples.
    pub(super) fn new(
        reader: &PisReader,
        objects: &[ObjectGpu],
        blend: Blend,
        req: &FrameRequest,
        size: (u32, u32),
        relight: Option<&Relight>,
    ) -> Result<Plan, PlayError> {
        let c = reader.container();
        let dims = &c.space.dims;
        check_point(dims, &req.point).map_err(PlayError::Request)?;
        let samples = weighted_samples(dims, &req.point, blend);
        let nearest = nearest_sample(dims, &req.point);
        let (clip_from_world, eye) = match req.camera {
            CameraChoice::Sample => {
                let cam = camera_record(reader, &nearest);
                let world_from_camera = mat4_from_rows(&cam.world_from_camera);
                (
                    projection(cam.yfov, cam.znear, cam.zfar, size.0, size.1)
                        * world_from_camera.inverse(),
                    world_from_camera.w_axis.truncate(),
                )
            }
            CameraChoice::Free(cam) => {
                cam.check().map_err(PlayError::Request)?;
                (cam.projection(size) * cam.view_matrix(), cam.eye)
            }
        };
        let mut plan = Plan {
            clips: Vec::with_capacity(c.objects.len()),
            worlds: Vec::with_capacity(c.objects.len()),
            eye,
            surfaces: Vec::new(),
            reflections: Vec::new(),
            lenses: Vec::new(),
            clip_from_world,
        };
        let lit = relight.map(|r| r.lit(&samples));
        for (oi, (o, og)) in c.objects.iter().zip(objects).enumerate() {
            let t = &o.transforms;
            let world = t
                .transforms
                .get(c.space.table_index(t.depends_on, &nearest))
                .map_or(glam::Mat4::IDENTITY, mat4_from_rows);
            plan.clips.push(clip_from_world * world);
            plan.worlds.push(world);
            for &li in &og.layers {
                let basis = o.layers[li].basis;
                for (s, w) in merge_for_mask(&samples, o.layers[li].depends_on) {
                    let (key, block) = texture_key(reader, oi, li, &s)?;
                    let Placement::Surface { affine, repeat, cut } = block.placement else {
                        continue;
                    };
                    let mask = o.layers[li].depends_on;
                    let tint = match (&lit, basis) {
                        (Some(lit), 1..) => {
                            let members: Vec<&(Vec<u32>, f32)> = samples
                                .iter()
                                .filter(|(t, _)| mask.dims().all(|k| t[k] == s[k]))
                                .collect();
                            lit.weight(basis as usize - 1, &members)
                        }
                        _ => [1.0; 3],
                    };
                    let layer = &o.layers[li];
                    let relit = (basis > 0).then(|| {
                        let head = [oi as u32, layer.term.code() as u32, layer.order as u32];
                        head.into_iter().chain([key.block]).chain(s.iter().copied()).collect()
                    });
                    plan.surfaces.push(Wanted {
                        draw: oi,
                        key,
                        weight: w,
                        tint,
                        transform: TextureTransform { values: affine, cut },
                        repeat,
                        relit,
                    });
                }
            }
            plan.reflections.extend(shell_terms(reader, (oi, og), &og.reflection, &samples)?);
            if let Some(lens) = &og.lens {
                plan.lenses.extend(shell_terms(reader, (oi, og), &lens.layers, &samples)?);
            }
        }
        Ok(plan)
    }

    /// Every texture the frame draws (a texture drawn twice is listed twice).
    pub(super) fn keys(&self) -> Vec<&TextureKey> {
        let shells = self
            .reflections
            .iter()
            .chain(&self.lenses)
            .flat_map(|r| r.shells.iter().map(|(k, _, _)| k));
        self.surfaces.iter().map(|w| &w.key).chain(shells).collect()
    }
}

/// The texture of object `oi`'s layer `li` at parameter sample `sample`: its key and its
/// block.
fn texture_key<'r>(
    reader: &'r PisReader,
    oi: usize,
    li: usize,
    sample: &[u32],
) -> Result<(TextureKey, &'r pis_format::Block<StreamRef>), PlayError> {
    let c = reader.container();
    let (o, layer) = (&c.objects[oi], &c.objects[oi].layers[li]);
    let pos = BlockGrid::new(&c.space, layer.depends_on, &o.stagger).locate(sample);
    let block = layer.blocks.get(pos.block).ok_or_else(|| {
        content(reader, format!("object {oi} layer {li}: block {} missing", pos.block))
    })?;
    let images = block
        .levels
        .iter()
        .map(|l| level_image_index(&l.counts, &pos.local, &pos.extent) as u32)
        .collect();
    Ok((TextureKey { object: oi as u32, layer: li as u32, block: pos.block as u32, images }, block))
}

/// Object `oi`'s terms of shell layers `term` (in order) at the weighted parameter
/// samples: one per class of samples the term's shells cannot tell apart (equal on the
/// union of their dependency masks), with the class's summed weight, as the surface
/// layers are blended.
fn shell_terms(
    reader: &PisReader,
    (oi, og): (usize, &ObjectGpu),
    term: &[usize],
    samples: &[(Vec<u32>, f32)],
) -> Result<Vec<WantedReflection>, PlayError> {
    let o = &reader.container().objects[oi];
    if term.is_empty() {
        return Ok(Vec::new());
    }
    let mask = DepMask(term.iter().fold(0, |m, &li| m | o.layers[li].depends_on.0));
    let mut out = Vec::new();
    for (s, weight) in merge_for_mask(samples, mask) {
        let mut shells = Vec::with_capacity(term.len());
        for &li in term {
            let (key, block) = texture_key(reader, oi, li, &s)?;
            let depth = og.depth.get(&(li, key.block)).map(|d| d.0.clone());
            let (shell, lookups) = shell_of(&block.placement, depth).ok_or_else(|| {
                content(
                    reader,
                    format!("object {oi} layer {li} block {}: not a closed shell", key.block),
                )
            })?;
            shells.push((key, shell, lookups));
        }
        out.push(WantedReflection { draw: oi, weight, shells });
    }
    Ok(out)
}

/// The file's camera record at parameter sample `sample` (the first camera where the
/// table has none; a default one where the file has no camera).
pub(super) fn camera_record(reader: &PisReader, sample: &[u32]) -> pis_format::Camera {
    let c = reader.container();
    let i = c.space.table_index(c.cameras.depends_on, sample);
    c.cameras.cameras.get(i).or(c.cameras.cameras.first()).copied().unwrap_or(pis_format::Camera {
        world_from_camera: pis_format::IDENTITY_3X4,
        yfov: 0.8,
        znear: 0.1,
        zfar: 100.0,
    })
}

/// The cube-map geometry of a shell block's placement (SPEC.md 7.3) and its lookups per
/// pixel side (8.2): `depth` for a depth shell (its cube cast when the file was opened);
/// `None` for a quad or a surface placement.
fn shell_of(placement: &Placement, depth: Option<Shell>) -> Option<(Shell, u32)> {
    let Placement::Shell { shape, origin, params, lookups } = placement else { return None };
    if let Some(shell) = depth {
        return Some((shell, *lookups));
    }
    let mut values = [0.0f32; 12];
    values[..3].copy_from_slice(origin);
    values[3..9].copy_from_slice(params);
    Shell::from_placement(shape.code() as u16, &values).map(|s| (s, *lookups))
}
