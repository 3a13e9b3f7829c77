//! Lights written in scene.toml (`[[light]]`): point, spot, directional and sphere lights
//! placed in world space, added to the rig as nodes of their own beside the glTF's
//! KHR_lights_punctual lights, so that a scene without lights of its own can be lit, and a
//! `light_path` dimension can move them by name.

use std::path::Path;

use glam::{Quat, Vec3};
use serde::Deserialize;

use crate::animation::Trs;
use crate::model::LightKind;
use crate::rig::{LightRig, Node, Rig};
use crate::SceneError;

/// `[[light]]`: one light.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LightSpec {
    /// Unique among the scene's lights (a `light_path` dimension names it).
    pub name: String,
    pub kind: LightKindSpec,
    /// World position (point, spot and sphere lights).
    pub position: Option<[f32; 3]>,
    /// The direction the light points to (spot and directional lights).
    pub direction: Option<[f32; 3]>,
    /// Linear RGB, default white.
    pub color: Option<[f32; 3]>,
    /// As in KHR_lights_punctual: candela for point, spot and sphere lights, lux for
    /// directional ones; default 1.
    pub intensity: Option<f32>,
    /// Sphere lights: the radius (> 0).
    pub radius: Option<f32>,
    /// Sphere lights: whether camera rays see the sphere (default true).
    pub visible_camera: Option<bool>,
    /// Spot lights: the cone angles in degrees (defaults 0 and 45, as in glTF).
    pub inner_cone_deg: Option<f32>,
    pub outer_cone_deg: Option<f32>,
}

/// A light kind as written in scene.toml.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum LightKindSpec {
    Point,
    Spot,
    Directional,
    Sphere,
}

/// Adds `specs` to `rig`, each on a node of its own at its position, turned so that its −Z
/// axis is its direction; `path` and the index name the field of an error.
pub fn add_lights(rig: &mut Rig, specs: &[LightSpec], path: &Path) -> Result<(), SceneError> {
    for (i, s) in specs.iter().enumerate() {
        let field = |f: &str| format!("light[{}].{f}", i + 1);
        let bad = |f: &str, why: String| SceneError::invalid(path, field(f), why);
        if s.name.trim().is_empty() {
            return Err(bad("name", "a light needs a name".into()));
        }
        if rig.lights.iter().any(|l| l.name == s.name) {
            return Err(bad("name", format!("another light is named {:?}", s.name)));
        }
        let finite3 = |f: &str, v: Option<[f32; 3]>| -> Result<Option<Vec3>, SceneError> {
            match v {
                Some(v) if v.iter().all(|x| x.is_finite()) => Ok(Some(Vec3::from(v))),
                Some(v) => Err(bad(f, format!("{v:?} is not finite"))),
                None => Ok(None),
            }
        };
        let needs = |f: &str, v: Option<Vec3>| {
            v.ok_or_else(|| bad(f, format!("a {:?} light needs `{f}`", s.kind).to_lowercase()))
        };
        let position = finite3("position", s.position)?;
        let direction = finite3("direction", s.direction)?;
        let (position, direction) = match s.kind {
            LightKindSpec::Point | LightKindSpec::Sphere => {
                (needs("position", position)?, Vec3::NEG_Z)
            }
            LightKindSpec::Spot => (needs("position", position)?, needs("direction", direction)?),
            LightKindSpec::Directional => (Vec3::ZERO, needs("direction", direction)?),
        };
        if direction.length_squared() == 0.0 {
            return Err(bad("direction", "the direction is zero".into()));
        }
        let color = s.color.unwrap_or([1.0; 3]);
        if color.iter().any(|c| !(c.is_finite() && *c >= 0.0)) {
            return Err(bad("color", format!("{color:?}: expected finite values ≥ 0")));
        }
        let intensity = s.intensity.unwrap_or(1.0);
        if !(intensity.is_finite() && intensity >= 0.0) {
            return Err(bad("intensity", format!("{intensity}: expected a finite value ≥ 0")));
        }
        let radius = match (s.kind, s.radius) {
            (LightKindSpec::Sphere, Some(r)) if r.is_finite() && r > 0.0 => r,
            (LightKindSpec::Sphere, r) => {
                return Err(bad(
                    "radius",
                    format!("a sphere light needs a radius > 0, found {r:?}"),
                ))
            }
            (_, Some(_)) => return Err(bad("radius", "only a sphere light has a radius".into())),
            (_, None) => 0.0,
        };
        if s.visible_camera.is_some() && s.kind != LightKindSpec::Sphere {
            return Err(bad("visible_camera", "only a sphere light is seen by the camera".into()));
        }
        let kind = match s.kind {
            LightKindSpec::Spot => {
                let inner = s.inner_cone_deg.unwrap_or(0.0);
                let outer = s.outer_cone_deg.unwrap_or(45.0);
                if !(0.0 <= inner && inner < outer && outer <= 90.0) {
                    return Err(bad(
                        "outer_cone_deg",
                        format!(
                            "cone angles {inner}° and {outer}°: expected 0 ≤ inner < outer ≤ 90"
                        ),
                    ));
                }
                LightKind::Spot { inner_cone: inner.to_radians(), outer_cone: outer.to_radians() }
            }
            _ if s.inner_cone_deg.is_some() || s.outer_cone_deg.is_some() => {
                return Err(bad("outer_cone_deg", "only a spot light has cone angles".into()))
            }
            LightKindSpec::Directional => LightKind::Directional,
            LightKindSpec::Point | LightKindSpec::Sphere => LightKind::Point,
        };
        let node = rig.nodes.len();
        rig.nodes.push(Node {
            name: s.name.clone(),
            gltf_index: usize::MAX,
            parent: None,
            local: Trs {
                translation: position,
                rotation: Quat::from_rotation_arc(Vec3::NEG_Z, direction.normalize()),
                scale: Vec3::ONE,
            },
        });
        rig.lights.push(LightRig {
            name: s.name.clone(),
            node,
            kind,
            radiance: color.map(|c| c * intensity),
            radius,
            visible_camera: s.visible_camera.unwrap_or(true),
        });
    }
    Ok(())
}
