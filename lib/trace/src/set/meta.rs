//! The contents of `set.json`.

use crate::film::GaussianFilter;
use crate::settings::TraceSettings;
use serde::{Deserialize, Serialize};

/// `set.json`: everything about a ray-traced set except the pixels.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SetMeta {
    /// Always `"pis-rayset"`.
    pub format: String,
    /// Layout version, 1.
    pub version: u32,
    /// Scene name.
    pub scene: String,
    /// Image size `[width, height]` in pixels.
    pub resolution: [u32; 2],
    /// Camera samples per pixel.
    pub spp: u32,
    /// The Gaussian reconstruction filter every layer was filtered with.
    pub filter: GaussianFilter,
    /// Who rendered the set and how (informative; absent in sets from other renderers).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub renderer: Option<RendererMeta>,
    /// The parameter space, dimension order = order of `samples` in each point.
    pub space: Vec<DimensionMeta>,
    /// Objects in scene order; record and point `objects` indices refer to this list.
    pub objects: Vec<ObjectMeta>,
    /// Parameter points in linear-index order (last dimension fastest).
    pub points: Vec<PointMeta>,
    /// The scene.toml the set was traced from: relative to the set directory where both
    /// lie under one root, else absolute (RAYSET.md section 3). Absent when unknown.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scene_file: Option<String>,
    /// The denoiser whose `denoised.` layers the points hold (`Open Image Denoise 2.5.1`);
    /// absent when the set was not denoised by its renderer.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub denoiser: Option<String>,
}

/// The renderer that produced a set.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RendererMeta {
    /// `pis-trace`, `cycles` ...
    pub name: String,
    pub version: String,
    /// pis-trace's settings.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub settings: Option<TraceSettings>,
}

/// One dimension of the parameter space.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DimensionMeta {
    pub name: String,
    /// `view`, `light`, `object_motion`, `time` or `other`.
    pub kind: String,
    /// `orbit`, `animation`, `light_path`, `light_direction` or `still`.
    pub driver: String,
    /// True when the dimension wraps around.
    pub periodic: bool,
    /// Unit of `values`.
    pub unit: String,
    /// The value of every sample.
    pub values: Vec<f32>,
    /// A `light_direction` dimension's direction of every sample: unit, world space, from
    /// the scene towards the light.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub directions: Option<Vec<[f32; 3]>>,
}

/// One object and the layers it has.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ObjectMeta {
    /// The scene's name for the object.
    pub name: String,
    /// The name used in EXR channel names (`object.<channel_name>.<layer>.<C>`).
    pub channel_name: String,
    /// `diffuse`, `reflective` or `refractive`.
    pub role: String,
    /// Names of the layers present in every point's EXR.
    pub layers: Vec<String>,
    /// True when the points' ray-record side files hold records of this object.
    pub records: bool,
    /// The reflector the object is a part of, when it is not a reflector of its own
    /// (scene.toml `reflector`): its `local` layer counts hits on every part of it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reflector: Option<String>,
}

/// One parameter point.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PointMeta {
    /// Linear index.
    pub index: usize,
    /// Sample index per dimension.
    pub samples: Vec<u32>,
    /// Sample value per dimension.
    pub values: Vec<f32>,
    /// EXR file name, relative to the set directory.
    pub image: String,
    /// Ray-record side file name, relative to the set directory; null when no object has records.
    pub rays: Option<String>,
    pub camera: CameraMeta,
    pub lights: Vec<LightMeta>,
    /// Placement of every object, same order as the set's `objects`.
    pub objects: Vec<ObjectStateMeta>,
    /// Which layers of the point have a denoised twin, and which objects were kept raw.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub denoise: Option<crate::denoise::PointDenoise>,
}

/// The camera at one point. Matrices are column-major, 16 numbers.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CameraMeta {
    /// Rigid camera-to-world transform; the camera looks down its local −Z, +Y up.
    pub world_from_camera: [f32; 16],
    /// Inverse of `world_from_camera`.
    pub camera_from_world: [f32; 16],
    /// Right-handed perspective projection, clip depth in [0, 1].
    pub projection: [f32; 16],
    /// Vertical field of view, radians.
    pub yfov: f32,
    pub znear: f32,
    /// Null for an infinite far plane.
    pub zfar: Option<f32>,
}

/// A light at one point.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LightMeta {
    pub name: String,
    /// `point`, `spot` or `directional`.
    pub kind: String,
    pub position: [f32; 3],
    pub direction: [f32; 3],
    /// Colour × intensity, linear RGB.
    pub radiance: [f32; 3],
    /// Sphere radius, 0 for a point light.
    pub radius: f32,
    /// Whether camera rays see the sphere; written only when false.
    #[serde(default = "seen", skip_serializing_if = "is_seen")]
    pub visible_camera: bool,
}

/// [`LightMeta::visible_camera`]'s default.
fn seen() -> bool {
    true
}

fn is_seen(visible_camera: &bool) -> bool {
    *visible_camera
}

/// An object's placement at one point.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ObjectStateMeta {
    pub name: String,
    /// Column-major object-to-world matrix.
    pub world_from_object: [f32; 16],
}

/// Position differences below this fraction of the camera's distance from the origin (at
/// least 1 unit) are rounding.
const POSITION_TOLERANCE: f32 = 1e-4;
/// Angle differences (view direction, up, field of view) below this are rounding, degrees.
const ANGLE_TOLERANCE_DEG: f32 = 0.01;

impl CameraMeta {
    /// What differs between this recorded camera and one placed by `world_from_camera` with
    /// vertical field of view `yfov` (radians) beyond rounding (position, view direction, up,
    /// field of view), in words; `None` when they agree.
    pub fn differs_from(&self, world_from_camera: glam::Mat4, yfov: f32) -> Option<String> {
        let (a, b) = (glam::Mat4::from_cols_array(&self.world_from_camera), world_from_camera);
        let (pa, pb) = (a.w_axis.truncate(), b.w_axis.truncate());
        let scale = pa.length().max(pb.length()).max(1.0);
        // atan2 of the sine and cosine: accurate at small angles, where the arc cosine of a
        // dot product of unit vectors rounded to f32 reads 0.02° between equal directions.
        let angle = |u: glam::Vec3, v: glam::Vec3| u.cross(v).length().atan2(u.dot(v)).to_degrees();
        let mut what = Vec::new();
        if pa.distance(pb) > POSITION_TOLERANCE * scale {
            what.push(format!("position {pa} against {pb} ({:.4} apart)", pa.distance(pb)));
        }
        let view = angle(-a.z_axis.truncate(), -b.z_axis.truncate());
        if view > ANGLE_TOLERANCE_DEG {
            what.push(format!("view direction {view:.3}° apart"));
        }
        let up = angle(a.y_axis.truncate(), b.y_axis.truncate());
        if up > ANGLE_TOLERANCE_DEG {
            what.push(format!("up {up:.3}° apart"));
        }
        let fov = (self.yfov - yfov).abs().to_degrees();
        if fov > ANGLE_TOLERANCE_DEG {
            what.push(format!(
                "vertical field of view {:.3}° against {:.3}°",
                self.yfov.to_degrees(),
                yfov.to_degrees()
            ));
        }
        (!what.is_empty()).then(|| what.join(", "))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Mat4, Vec3};

    fn camera(eye: Vec3, yfov: f32) -> pis_scene::Camera {
        let back = eye.normalize();
        let right = Vec3::Y.cross(back).normalize();
        let up = back.cross(right);
        let world_from_camera =
            Mat4::from_cols(right.extend(0.0), up.extend(0.0), back.extend(0.0), eye.extend(1.0));
        pis_scene::Camera { world_from_camera, yfov, znear: 0.1, zfar: f32::INFINITY }
    }

    fn meta(c: &pis_scene::Camera) -> CameraMeta {
        CameraMeta {
            world_from_camera: c.world_from_camera.to_cols_array(),
            camera_from_world: c.world_from_camera.inverse().to_cols_array(),
            projection: Mat4::IDENTITY.to_cols_array(),
            yfov: c.yfov,
            znear: c.znear,
            zfar: None,
        }
    }

    #[test]
    fn a_camera_differs_beyond_rounding_only() {
        let traced = camera(Vec3::new(0.0, 1.0, 4.0), 0.8);
        let recorded = meta(&traced);
        let differs = |c: pis_scene::Camera| recorded.differs_from(c.world_from_camera, c.yfov);
        assert_eq!(differs(traced), None);
        assert_eq!(differs(camera(Vec3::new(0.0, 1.0, 4.0001), 0.8)), None);
        // Another orbit radius: the position moves along the view direction.
        let farther = differs(camera(Vec3::new(0.0, 1.2, 4.8), 0.8));
        assert!(farther.as_deref().is_some_and(|d| d.starts_with("position")), "{farther:?}");
        let wider = differs(camera(Vec3::new(0.0, 1.0, 4.0), 0.9));
        assert!(wider.as_deref().is_some_and(|d| d.contains("field of view")), "{wider:?}");
        // A roll of 0.005° is rounding, one of 0.05° is not (the arc cosine of an f32 dot
        // product read 0.02° between equal directions).
        let rolled = |deg: f32| {
            let mut c = traced;
            c.world_from_camera *= Mat4::from_rotation_z(deg.to_radians());
            recorded.differs_from(c.world_from_camera, c.yfov)
        };
        assert_eq!(rolled(0.005), None);
        assert!(rolled(0.05).is_some_and(|d| d.starts_with("up")), "{:?}", rolled(0.05));
        let turned = differs(camera(Vec3::new(4.0, 1.0, 0.0), 0.8));
        assert!(turned.as_deref().is_some_and(|d| d.contains("view direction")), "{turned:?}");
    }
}
