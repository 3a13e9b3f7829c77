//! The evaluated scene: what the tracer consumes.
//!
//! Conventions: right-handed world, +Y up, metres; cameras look down their local -Z with +Y up
//! (glTF). Colours are linear RGB. Matrices are column-major `glam::Mat4`.

use glam::{Mat4, Vec2, Vec3, Vec4};
use pis_format::{DimensionKind, ObjectRole};

pub use crate::light::{Light, LightKind};
use crate::rig::Rig;
pub use crate::texture_ref::{TextureRef, UvTransform};

/// A loaded scene: static content plus the parameter space that animates it.
///
/// Build one with [`crate::load`]; a hand-built scene can start from `Scene::default()`
/// (its [`Rig`] then places every object at the origin).
#[derive(Clone, Debug, Default)]
pub struct Scene {
    /// Short name (the scene directory name, or `name` in scene.toml).
    pub name: String,
    /// Image size in pixels (width, height).
    pub resolution: (u32, u32),
    /// Camera samples per pixel.
    pub spp: u32,
    /// Renderable objects (one per glTF node that has a mesh), in glTF node order.
    pub objects: Vec<SceneObject>,
    pub materials: Vec<Material>,
    /// Decoded textures referenced by materials.
    pub textures: Vec<TextureImage>,
    pub space: ParameterSpace,
    /// Node hierarchy, camera, lights and animations: what [`Scene::frame`] poses.
    pub rig: Rig,
    /// Light from infinitely far away (scene.toml `[environment]`), the same at every
    /// parameter point.
    pub environment: Option<crate::environment::Environment>,
    /// The scene.toml it was loaded from (`None` for a scene built in code).
    pub source: Option<std::path::PathBuf>,
    /// What loading found and rendering will ignore or approximate (glTF extensions PIS does
    /// not implement, texture coordinate sets a mesh lacks), one line each, each said once.
    pub warnings: Vec<String>,
}

impl Scene {
    /// Whether anything in the scene emits light: a light (the glTF's or scene.toml's), an
    /// environment that is not black, or a material with emission. Without, every traced
    /// image is black.
    pub fn emits(&self) -> bool {
        !self.rig.lights.is_empty()
            || self.environment.as_ref().is_some_and(|e| e.emits())
            || self.materials.iter().any(|m| m.emissive.iter().any(|&e| e > 0.0))
    }

    /// The reflector object `o` is a part of, as the index of its first part. An object is
    /// a reflector of its own, named after itself, unless it names another (`reflector`);
    /// objects of the same reflector name share the index of the first of them.
    pub fn reflector_of(&self, o: usize) -> u32 {
        let Some(name) = self.objects.get(o).map(SceneObject::reflector_name) else {
            return o as u32;
        };
        self.objects.iter().position(|x| x.reflector_name() == name).unwrap_or(o) as u32
    }

    /// [`Scene::reflector_of`] every object, in one pass.
    pub fn reflectors(&self) -> Vec<u32> {
        let mut first = std::collections::HashMap::new();
        self.objects
            .iter()
            .enumerate()
            .map(|(o, x)| *first.entry(x.reflector_name()).or_insert(o as u32))
            .collect()
    }
}

impl SceneObject {
    /// The name of the reflector the object is a part of: `reflector`, else its own name.
    pub fn reflector_name(&self) -> &str {
        self.reflector.as_deref().unwrap_or(&self.name)
    }
}

/// One renderable object. Its mesh is in object space; [`Frame::instances`] places it.
#[derive(Clone, Debug)]
pub struct SceneObject {
    pub name: String,
    /// Inferred from the material (transmission → refractive, metallic or low roughness →
    /// reflective, else diffuse) unless scene.toml overrides it.
    pub role: ObjectRole,
    /// The reflector this object is a part of (scene.toml `reflector`; `None`: a reflector
    /// of its own, named after the object). A reflective part's local layer records its reflected rays that hit any part
    /// of its reflector, and its distant layer sees through all of them (thesis 5.10: the
    /// teapot's lid and body, one local shell each, reflecting each other locally).
    pub reflector: Option<String>,
    pub primitives: Vec<Primitive>,
}

/// A triangle list with one material.
#[derive(Clone, Debug, Default)]
pub struct Primitive {
    pub positions: Vec<Vec3>,
    /// Unit normals, one per vertex (generated flat if the glTF has none).
    pub normals: Vec<Vec3>,
    /// Texture coordinates (TEXCOORD_0), one per vertex; zeros if the glTF has none.
    pub uvs: Vec<Vec2>,
    /// Second texture coordinates (TEXCOORD_1), one per vertex; empty if the glTF has none
    /// (textures reading set 1 then read TEXCOORD_0).
    pub uvs1: Vec<Vec2>,
    /// glTF TANGENT: unit tangent (xyz) and bitangent sign (w), one per vertex; empty if the
    /// glTF has none (normal maps then use a tangent frame made per triangle from the UVs).
    pub tangents: Vec<Vec4>,
    /// Triangle list, three indices per triangle.
    pub indices: Vec<u32>,
    /// Index into [`Scene::materials`].
    pub material: usize,
}

/// glTF PBR metallic-roughness with KHR_materials_transmission, _ior, _volume, _specular,
/// and emission (KHR_materials_emissive_strength folded into `emissive`). Each texture is
/// multiplied by its factor where it is sampled (docs/SCENE.md).
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    pub name: String,
    /// Linear RGBA base colour factor.
    pub base_color: [f32; 4],
    /// Base colour (sRGB, decoded to linear) and alpha, multiplied by `base_color`.
    pub base_color_texture: Option<TextureRef>,
    pub metallic: f32,
    pub roughness: f32,
    /// Roughness in G and metallic in B (linear), multiplying `roughness` and `metallic`.
    pub metallic_roughness_texture: Option<TextureRef>,
    /// Emitted radiance (linear RGB, strength applied).
    pub emissive: [f32; 3],
    /// Emission colour (sRGB, decoded to linear), multiplying `emissive`.
    pub emissive_texture: Option<TextureRef>,
    /// Tangent-space normal map (linear; X right, Y up, Z out of the surface).
    pub normal_texture: Option<TextureRef>,
    /// The normal map's `scale`, applied to its X and Y (default 1).
    pub normal_scale: f32,
    /// How base-colour alpha covers the surface.
    pub alpha_mode: AlphaMode,
    /// KHR_materials_transmission factor (0 opaque .. 1 fully transmissive).
    pub transmission: f32,
    /// KHR_materials_ior (default 1.5).
    pub ior: f32,
    /// KHR_materials_volume: attenuation distance (f32::INFINITY = no absorption) and colour.
    pub attenuation_distance: f32,
    pub attenuation_color: [f32; 3],
    /// KHR_materials_specular factor and colour (defaults 1 and white).
    pub specular: f32,
    pub specular_color: [f32; 3],
}

impl Default for Material {
    fn default() -> Self {
        Material {
            name: String::new(),
            base_color: [1.0; 4],
            base_color_texture: None,
            metallic: 1.0,
            roughness: 1.0,
            metallic_roughness_texture: None,
            emissive: [0.0; 3],
            emissive_texture: None,
            normal_texture: None,
            normal_scale: 1.0,
            alpha_mode: AlphaMode::Opaque,
            transmission: 0.0,
            ior: 1.5,
            attenuation_distance: f32::INFINITY,
            attenuation_color: [1.0; 3],
            specular: 1.0,
            specular_color: [1.0; 3],
        }
    }
}

impl Material {
    /// Every texture the material reads.
    pub fn textures(&self) -> impl Iterator<Item = &TextureRef> {
        [
            &self.base_color_texture,
            &self.metallic_roughness_texture,
            &self.emissive_texture,
            &self.normal_texture,
        ]
        .into_iter()
        .flatten()
    }
}

/// glTF `alphaMode`: how the base colour's alpha (factor × texture) covers the surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AlphaMode {
    /// Alpha is ignored: the surface is solid.
    Opaque,
    /// Texels of alpha below the cutoff are holes every ray passes through (glTF
    /// `alphaCutoff`, default 0.5); the rest is solid.
    Mask { cutoff: f32 },
    /// Stochastic transparency: a ray passes with probability 1 − alpha.
    Blend,
}

/// A decoded texture in linear RGBA f32, rows top to bottom (glTF UV (0,0) is the top-left).
#[derive(Clone, Debug)]
pub struct TextureImage {
    pub width: u32,
    pub height: u32,
    pub texels: Vec<[f32; 4]>,
}

/// The parameter space: named dimensions, each with its samples.
#[derive(Clone, Debug, Default)]
pub struct ParameterSpace {
    pub dims: Vec<Dimension>,
}

impl ParameterSpace {
    /// Number of parameter points (product of the sample counts).
    pub fn point_count(&self) -> usize {
        self.dims.iter().map(|d| d.samples() as usize).product()
    }

    /// Sample indices of the point with linear index `index`; the last dimension varies fastest.
    pub fn point(&self, mut index: usize) -> Vec<u32> {
        let mut out = vec![0; self.dims.len()];
        for (k, d) in self.dims.iter().enumerate().rev() {
            let n = d.samples() as usize;
            out[k] = (index % n) as u32;
            index /= n;
        }
        out
    }

    /// The linear index of `point` (inverse of [`ParameterSpace::point`]), or `None` if it
    /// has the wrong length or an index out of range.
    pub fn index_of(&self, point: &[u32]) -> Option<usize> {
        if point.len() != self.dims.len() {
            return None;
        }
        let mut index = 0usize;
        for (d, &i) in self.dims.iter().zip(point) {
            if i >= d.samples() {
                return None;
            }
            index = index * d.samples() as usize + i as usize;
        }
        Some(index)
    }
}

/// One dimension of the parameter space.
#[derive(Clone, Debug)]
pub struct Dimension {
    pub name: String,
    pub kind: DimensionKind,
    /// True when the dimension wraps around (a full orbit).
    pub periodic: bool,
    /// Unit of `values` ("deg", "s", "" ...).
    pub unit: String,
    /// The value of every sample, strictly increasing.
    pub values: Vec<f32>,
    pub driver: Driver,
}

impl Dimension {
    pub fn samples(&self) -> u32 {
        self.values.len() as u32
    }
}

/// What a dimension drives.
#[derive(Clone, Debug)]
pub enum Driver {
    /// The camera orbits `target` at `radius` and `elevation` (degrees); the sample value is
    /// the azimuth in degrees.
    Orbit { target: Vec3, radius: f32, elevation_deg: f32 },
    /// A named glTF animation; the sample value is the time in seconds.
    Animation { animation: String },
    /// A named light moves along a polyline (world space); the sample value is the path
    /// parameter in [0, 1] (arc-length).
    LightPath { light: String, path: Vec<Vec3> },
    /// A named light turned over a set of directions (unit, from the scene towards the
    /// light); the sample value is the sample's index. A directional light shines along
    /// −direction; a point, spot or sphere light stands at `center + distance · direction`.
    LightDirection {
        light: String,
        directions: Vec<Vec3>,
        center: Vec3,
        distance: f32,
        /// The directions follow an arc (a light moving continuously), not a cover.
        arc: bool,
    },
    /// Nothing moves: the one sample of the dimension a scene without `[[dimension]]` gets,
    /// since a container holds 1 to 8 dimensions.
    Still,
}

/// Everything that varies over the parameter space, evaluated at one point.
#[derive(Clone, Debug)]
pub struct Frame {
    pub camera: Camera,
    pub lights: Vec<Light>,
    /// One per [`Scene::objects`] entry, same order.
    pub instances: Vec<Instance>,
}

/// A perspective camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Rigid camera-to-world transform (camera looks down local -Z, +Y up).
    pub world_from_camera: Mat4,
    /// Vertical field of view in radians.
    pub yfov: f32,
    pub znear: f32,
    /// f32::INFINITY when the glTF camera has no far plane.
    pub zfar: f32,
}

/// An object placed in the world at one parameter point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Instance {
    pub world_from_object: Mat4,
}
