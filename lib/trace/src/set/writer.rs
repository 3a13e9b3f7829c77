//! Writing a ray-traced set. Every file is written to a temporary name and renamed into
//! place, so an interrupted run never leaves a half-written file under a final name.

use super::atomic::write_atomic;
use super::exr_io::encode_exr;
use super::meta::*;
use super::shards::{all_recorded, merge_set, Begin, Records};
use super::{SET_FORMAT, SET_VERSION};
use crate::camera::projection_matrix;
use crate::error::TraceError;
use crate::layers::LayerKind;
use crate::records::encode_records;
use crate::render::{channel_names, PointRender};
use crate::settings::TraceSettings;
use pis_scene::{DimensionKind, Driver, Frame, LightKind, ObjectRole, Scene};
use std::fs;
use std::path::{Path, PathBuf};

fn role_name(role: ObjectRole) -> &'static str {
    match role {
        ObjectRole::Diffuse => "diffuse",
        ObjectRole::Reflective => "reflective",
        ObjectRole::Refractive => "refractive",
    }
}

fn kind_name(kind: DimensionKind) -> &'static str {
    match kind {
        DimensionKind::View => "view",
        DimensionKind::Light => "light",
        DimensionKind::ObjectMotion => "object_motion",
        DimensionKind::Time => "time",
        DimensionKind::Other => "other",
    }
}

/// Writes a ray-traced set point by point, each point recorded once its files are written
/// ([`Records`]), then `set.json` from the records.
pub struct SetWriter {
    dir: PathBuf,
    meta: SetMeta,
    records: Records,
}

impl SetWriter {
    /// Creates the directory `dir` (if needed) for a set of every point of `scene` rendered
    /// with `settings`, by this process alone.
    pub fn create(
        dir: &Path,
        scene: &Scene,
        settings: &TraceSettings,
    ) -> Result<SetWriter, TraceError> {
        SetWriter::begin(dir, scene, settings, scene.space.point_count(), Begin::Fresh)
    }

    /// The set meta (without points) of `scene` rendered with `settings` into `dir`.
    pub fn meta(dir: &Path, scene: &Scene, settings: &TraceSettings) -> SetMeta {
        let names = channel_names(scene);
        let objects = scene
            .objects
            .iter()
            .zip(names)
            .map(|(o, channel_name)| ObjectMeta {
                name: o.name.clone(),
                channel_name,
                role: role_name(o.role).into(),
                layers: LayerKind::for_role(o.role, settings.lens_model.terms())
                    .iter()
                    .map(|l| l.name().to_string())
                    .collect(),
                records: o.role == ObjectRole::Refractive,
                reflector: o.reflector.clone(),
            })
            .collect();
        let space = scene
            .space
            .dims
            .iter()
            .map(|d| DimensionMeta {
                name: d.name.clone(),
                kind: kind_name(d.kind).into(),
                driver: match d.driver {
                    Driver::Orbit { .. } => "orbit",
                    Driver::Animation { .. } => "animation",
                    Driver::LightPath { .. } => "light_path",
                    Driver::LightDirection { .. } => "light_direction",
                    Driver::Still => "still",
                }
                .into(),
                periodic: d.periodic,
                unit: d.unit.clone(),
                values: d.values.clone(),
                directions: match &d.driver {
                    Driver::LightDirection { directions, .. } => {
                        Some(directions.iter().map(|w| w.to_array()).collect())
                    }
                    _ => None,
                },
            })
            .collect();
        SetMeta {
            format: SET_FORMAT.into(),
            version: SET_VERSION,
            scene: scene.name.clone(),
            resolution: [settings.resolution.0, settings.resolution.1],
            spp: settings.spp,
            filter: settings.filter,
            renderer: Some(RendererMeta {
                name: "pis-trace".into(),
                version: env!("CARGO_PKG_VERSION").into(),
                settings: Some(settings.clone()),
            }),
            space,
            objects,
            points: Vec::new(),
            scene_file: scene.source.as_deref().map(|s| relative_to(s, dir)),
            denoiser: crate::denoise::denoiser(settings),
        }
    }

    /// Creates the directory `dir` (if needed) for a set of the first `points` points of
    /// `scene` rendered with `settings`, taking up the records there as `begin` says
    /// (several processes may write one set, each its own points).
    pub fn begin(
        dir: &Path,
        scene: &Scene,
        settings: &TraceSettings,
        points: usize,
        begin: Begin,
    ) -> Result<SetWriter, TraceError> {
        fs::create_dir_all(dir).map_err(|e| TraceError::io(dir, e))?;
        let meta = SetWriter::meta(dir, scene, settings);
        let records = Records::begin(dir, &meta, points, begin)?;
        Ok(SetWriter { dir: dir.to_path_buf(), meta, records })
    }

    /// The record of point `index` when an earlier run of the same trace wrote it.
    pub fn done(&self, index: usize) -> Option<PointMeta> {
        self.records.done(index)
    }

    /// The set directory.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Writes the EXR (and ray records, when any object has them) of the point with linear
    /// index `index` of `scene`, rendered at `frame`. Returns the bytes written.
    pub fn write_point(
        &mut self,
        scene: &Scene,
        index: usize,
        frame: &Frame,
        render: &PointRender,
    ) -> Result<u64, TraceError> {
        let samples = scene.space.point(index);
        let values = samples
            .iter()
            .zip(&scene.space.dims)
            .map(|(&s, d)| d.values.get(s as usize).copied().unwrap_or(f32::NAN))
            .collect();
        let image = format!("point_{index:05}.exr");
        let path = self.dir.join(&image);
        let exr = encode_exr(&render.images, &path)?;
        write_atomic(&path, &exr)?;
        let mut bytes = exr.len() as u64;
        let rays = if self.meta.objects.iter().any(|o| o.records) {
            let name = format!("point_{index:05}.rays.bin");
            let data = encode_records(&render.records);
            write_atomic(&self.dir.join(&name), &data)?;
            bytes += data.len() as u64;
            Some(name)
        } else {
            None
        };
        let res = (self.meta.resolution[0], self.meta.resolution[1]);
        let cam = &frame.camera;
        let point = PointMeta {
            index,
            samples,
            values,
            image,
            rays,
            camera: CameraMeta {
                world_from_camera: cam.world_from_camera.to_cols_array(),
                camera_from_world: cam.world_from_camera.inverse().to_cols_array(),
                projection: projection_matrix(cam, res).to_cols_array(),
                yfov: cam.yfov,
                znear: cam.znear,
                zfar: cam.zfar.is_finite().then_some(cam.zfar),
            },
            lights: frame
                .lights
                .iter()
                .map(|l| LightMeta {
                    name: l.name.clone(),
                    kind: match l.kind {
                        LightKind::Point => "point",
                        LightKind::Spot { .. } => "spot",
                        LightKind::Directional => "directional",
                    }
                    .into(),
                    position: l.position.to_array(),
                    direction: l.direction.to_array(),
                    radiance: l.radiance,
                    radius: l.radius,
                    visible_camera: l.visible_camera,
                })
                .collect(),
            objects: self
                .meta
                .objects
                .iter()
                .zip(&frame.instances)
                .map(|(o, i)| ObjectStateMeta {
                    name: o.channel_name.clone(),
                    world_from_object: i.world_from_object.to_cols_array(),
                })
                .collect(),
            denoise: render.denoised.clone(),
        };
        self.records.record(&point)?;
        Ok(bytes)
    }

    /// Writes `set.json` from the records (points sorted by index) and returns its size in
    /// bytes; an error when some point has no record yet.
    pub fn finish(self) -> Result<u64, TraceError> {
        Ok(merge_set(&self.dir)?.bytes)
    }

    /// Writes `set.json` when every point has a record (another process may still be
    /// writing its points): returns its size in bytes, `None` while points are missing.
    pub fn finish_if_complete(self) -> Result<Option<u64>, TraceError> {
        match all_recorded(&self.dir) {
            Ok(false) => Ok(None),
            // Every point recorded, or the records gone: another process merged them; the
            // merge says which (and any error).
            _ => Ok(Some(merge_set(&self.dir)?.bytes)),
        }
    }
}

/// `path` as seen from the directory `dir`: a relative path where both resolve under one
/// root, else `path` made absolute (or as given, when it cannot be resolved).
pub fn relative_to(path: &Path, dir: &Path) -> String {
    let (Ok(p), Ok(d)) = (fs::canonicalize(path), fs::canonicalize(dir)) else {
        return path.display().to_string();
    };
    let (pc, dc): (Vec<_>, Vec<_>) = (p.components().collect(), d.components().collect());
    let common = pc.iter().zip(&dc).take_while(|(a, b)| a == b).count();
    // Only the root in common: the absolute path reads better than a climb to it.
    if common <= 1 {
        return p.display().to_string();
    }
    let mut rel = std::path::PathBuf::new();
    for _ in common..dc.len() {
        rel.push("..");
    }
    for c in &pc[common..] {
        rel.push(c);
    }
    rel.display().to_string()
}
