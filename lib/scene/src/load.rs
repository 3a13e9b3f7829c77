//! The public entry: load scene.toml and the glTF it names into a [`Scene`].

use std::path::Path;

use glam::Vec3;

use crate::gltf_load::read_gltf;
use crate::manifest::{Manifest, RoleSpec};
use crate::model::Scene;
use crate::orbit::look_at;
use crate::rig::{CameraPlacement, CameraRig};
use crate::space::build_space;
use crate::{ObjectRole, SceneError};

/// Settings that override scene.toml (what `pis-trace --preset/--resolution/--spp` pass).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct LoadOptions {
    /// A `[preset.NAME]` of scene.toml, applied first.
    pub preset: Option<String>,
    /// Image size (width, height), applied after the preset.
    pub resolution: Option<(u32, u32)>,
    /// Samples per pixel, applied after the preset.
    pub spp: Option<u32>,
}

/// Loads `scene.toml` at `path` (and the glTF it names) with an optional preset.
pub fn load(path: &Path, preset: Option<&str>) -> Result<Scene, SceneError> {
    load_with(path, &LoadOptions { preset: preset.map(str::to_owned), ..LoadOptions::default() })
}

/// Loads `scene.toml` at `path` with the given overrides.
pub fn load_with(path: &Path, options: &LoadOptions) -> Result<Scene, SceneError> {
    let mut m = Manifest::read(path)?;
    if let Some(preset) = &options.preset {
        m.apply_preset(preset, path)?;
    }
    let (width, height) = options.resolution.unwrap_or((m.resolution[0], m.resolution[1]));
    if width == 0 || height == 0 {
        return Err(SceneError::invalid(
            path,
            "resolution",
            format!("{width}x{height} has a zero side"),
        ));
    }
    let spp = options.spp.unwrap_or(m.spp);
    if spp == 0 {
        return Err(SceneError::invalid(path, "spp", "must be at least 1"));
    }
    check_limits(&m, (width, height), path)?;

    let dir = path.parent().unwrap_or(Path::new("."));
    let gltf_path = dir.join(&m.gltf);
    let mut g = read_gltf(&gltf_path, m.allow_outside_files)?;

    for (name, spec) in &m.objects {
        let Some(obj) = g.objects.iter_mut().find(|o| &o.name == name) else {
            let known = g.objects.iter().map(|o| o.name.as_str());
            return Err(SceneError::unknown(path, format!("object.{name}"), "object", name, known));
        };
        if let Some(role) = spec.role {
            obj.role = match role {
                RoleSpec::Diffuse => ObjectRole::Diffuse,
                RoleSpec::Reflective => ObjectRole::Reflective,
                RoleSpec::Refractive => ObjectRole::Refractive,
            };
        }
        if let Some(reflector) = &spec.reflector {
            if reflector.trim().is_empty() {
                return Err(SceneError::invalid(
                    path,
                    format!("object.{name}.reflector"),
                    "a reflector name must not be empty",
                ));
            }
            obj.reflector = Some(reflector.clone());
        }
    }

    crate::toml_lights::add_lights(&mut g.rig, &m.lights, path)?;
    let environment = m
        .environment
        .as_ref()
        .map(|e| crate::environment::load(e, path, m.allow_outside_files))
        .transpose()?;
    let space = build_space(&m.dimensions, &g, path)?;
    g.rig.camera = resolve_camera(
        &m,
        &g,
        path,
        space.dims.iter().any(|d| matches!(d.driver, crate::Driver::Orbit { .. })),
    )?;

    let name = m.name.clone().unwrap_or_else(|| {
        dir.file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_else(|| "scene".to_owned())
    });
    Ok(Scene {
        name,
        resolution: (width, height),
        spp,
        objects: g.objects,
        materials: g.materials,
        textures: g.textures,
        space,
        rig: g.rig,
        environment,
        source: Some(path.to_path_buf()),
        warnings: g.warnings,
    })
}

/// What a `.pis` file can hold (SPEC.md section 12), checked before the glTF is read or a
/// sample value made: an image side, the dimension count and the parameter points.
fn check_limits(m: &Manifest, (width, height): (u32, u32), path: &Path) -> Result<(), SceneError> {
    use pis_format::checks::{MAX_DIMS, MAX_IMAGE_SIDE, MAX_POINTS};
    if width > MAX_IMAGE_SIDE || height > MAX_IMAGE_SIDE {
        let msg = format!(
            "{width}x{height}: a .pis file holds images of at most {MAX_IMAGE_SIDE} pixels a side"
        );
        return Err(SceneError::invalid(path, "resolution", msg));
    }
    if m.dimensions.len() > MAX_DIMS as usize {
        let msg =
            format!("{} dimensions: a .pis file holds at most {MAX_DIMS}", m.dimensions.len());
        return Err(SceneError::invalid(path, "dimension", msg));
    }
    let points = m
        .dimensions
        .iter()
        .try_fold(1u64, |n, d| n.checked_mul(d.samples as u64).filter(|&n| n <= MAX_POINTS));
    if points.is_none() {
        let counts: Vec<String> =
            m.dimensions.iter().map(|d| format!("{} {}", d.samples, d.name)).collect();
        let msg = format!(
            "{}: more than {MAX_POINTS} parameter points, the most a .pis file holds",
            counts.join(" × ")
        );
        return Err(SceneError::invalid(path, "dimension", msg));
    }
    Ok(())
}

/// The camera from `[camera]`, else the first glTF camera, else (with an orbit) a placeholder.
fn resolve_camera(
    m: &Manifest,
    g: &crate::gltf_load::GltfScene,
    path: &Path,
    has_orbit: bool,
) -> Result<CameraRig, SceneError> {
    let spec = m.camera.clone().unwrap_or_default();
    let mut rig = CameraRig::default();
    let mut gltf_camera = None;
    if let Some(name) = &spec.node {
        let found = g.cameras.iter().find(|c| &g.rig.nodes[c.node].name == name);
        let Some(c) = found else {
            let known = g.cameras.iter().map(|c| g.rig.nodes[c.node].name.as_str());
            return Err(SceneError::unknown(path, "camera.node", "camera", name, known));
        };
        if spec.eye.is_some() || spec.target.is_some() {
            return Err(SceneError::invalid(
                path,
                "camera.eye",
                "give either `node` or `eye`/`target`, not both",
            ));
        }
        gltf_camera = Some(c);
    } else if let Some(eye) = spec.eye {
        let target = spec
            .target
            .ok_or_else(|| SceneError::invalid(path, "camera.target", "required with `eye`"))?;
        let up = spec.up.map(Vec3::from).unwrap_or(Vec3::Y);
        if Vec3::from(eye) == Vec3::from(target) {
            return Err(SceneError::invalid(path, "camera.target", "equals camera.eye"));
        }
        rig.placement = CameraPlacement::Fixed(look_at(eye.into(), target.into(), up));
    } else if spec.target.is_some() {
        return Err(SceneError::invalid(path, "camera.eye", "required with `target`"));
    } else if let Some(c) = g.cameras.first() {
        gltf_camera = Some(c);
    } else if !has_orbit {
        return Err(SceneError::invalid(
            path,
            "camera",
            "no camera: give [camera] node or eye/target, add a camera to the glTF, or add an orbit dimension",
        ));
    }
    if let Some(c) = gltf_camera {
        rig.placement = CameraPlacement::Node(c.node);
        rig.yfov = c.yfov;
        rig.znear = c.znear;
        rig.zfar = c.zfar.unwrap_or(f32::INFINITY);
    }
    if let Some(deg) = spec.yfov_deg {
        if !(deg > 0.0 && deg < 180.0) {
            return Err(SceneError::invalid(
                path,
                "camera.yfov_deg",
                format!("must be in (0, 180), found {deg}"),
            ));
        }
        rig.yfov = deg.to_radians();
    }
    if let Some(z) = spec.znear {
        rig.znear = z;
    }
    if let Some(z) = spec.zfar {
        rig.zfar = z;
    }
    if !(rig.znear > 0.0 && rig.zfar > rig.znear) {
        return Err(SceneError::invalid(
            path,
            "camera.znear",
            format!("need 0 < znear < zfar, found {} and {}", rig.znear, rig.zfar),
        ));
    }
    Ok(rig)
}
