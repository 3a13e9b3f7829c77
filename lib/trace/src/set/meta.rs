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
    /// `orbit`, `animation` or `light_path`.
    pub driver: String,
    /// True when the dimension wraps around.
    pub periodic: bool,
    /// Unit of `values`.
    pub unit: String,
    /// The value of every sample.
    pub values: Vec<f32>,
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
}

/// An object's placement at one point.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ObjectStateMeta {
    pub name: String,
    /// Column-major object-to-world matrix.
    pub world_from_object: [f32; 16],
}
