//! `scene.toml`: the scene manifest (documented key by key in docs/SCENE.md).
//!
//! These types mirror the file one to one; [`crate::load`] resolves them against the glTF.
//! Unknown keys are errors (`deny_unknown_fields`), so a typo never silently does nothing.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::Deserialize;

use crate::SceneError;

/// The whole of scene.toml.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Manifest {
    /// Scene name; defaults to the name of the directory holding scene.toml.
    pub name: Option<String>,
    /// The glTF file (.gltf or .glb), relative to scene.toml.
    pub gltf: PathBuf,
    /// Image size in pixels, `[width, height]`.
    pub resolution: [u32; 2],
    /// Camera samples per pixel.
    pub spp: u32,
    /// Where the camera is when no orbit dimension moves it.
    pub camera: Option<CameraSpec>,
    /// Per-object settings, keyed by object (glTF node) name: `[object.Vase]`.
    #[serde(default, rename = "object")]
    pub objects: BTreeMap<String, ObjectSpec>,
    /// The parameter space, one `[[dimension]]` table per dimension, slowest first.
    #[serde(default, rename = "dimension")]
    pub dimensions: Vec<DimensionSpec>,
    /// Lights of the scene.toml's own, beside the glTF's: `[[light]]`.
    #[serde(default, rename = "light")]
    pub lights: Vec<crate::toml_lights::LightSpec>,
    /// The environment light: `[environment]`.
    pub environment: Option<crate::environment::EnvironmentSpec>,
    /// Named presets: `[preset.paper]`.
    #[serde(default, rename = "preset")]
    pub presets: BTreeMap<String, PresetSpec>,
    /// Let the glTF read buffers and images, and `[environment]` its image, outside their
    /// own folder (absolute paths, `file:` URIs, relative paths that climb out with `..`);
    /// refused by default.
    #[serde(default)]
    pub allow_outside_files: bool,
}

/// `[camera]`: a glTF camera node, or an explicit eye and target.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraSpec {
    /// Name of a glTF node that carries a camera.
    pub node: Option<String>,
    /// Eye position (world), used with `target` instead of `node`.
    pub eye: Option<[f32; 3]>,
    /// The point looked at.
    pub target: Option<[f32; 3]>,
    /// Up hint, default `[0, 1, 0]`.
    pub up: Option<[f32; 3]>,
    /// Vertical field of view in degrees (overrides the glTF camera's).
    pub yfov_deg: Option<f32>,
    pub znear: Option<f32>,
    pub zfar: Option<f32>,
}

/// `[object.NAME]`: settings for one object.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObjectSpec {
    /// Overrides the role inferred from the material.
    pub role: Option<RoleSpec>,
    /// Joins the object to the reflector of that name: its parts reflect each other in
    /// their local layers.
    pub reflector: Option<String>,
}

/// An object role as written in scene.toml.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum RoleSpec {
    Diffuse,
    Reflective,
    Refractive,
}

/// What drives a dimension.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum DriverSpec {
    Orbit,
    Animation,
    LightPath,
    LightDirection,
}

/// A dimension kind as written in scene.toml.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum KindSpec {
    View,
    Light,
    ObjectMotion,
    Time,
    Other,
}

/// `[[dimension]]`: one dimension of the parameter space. Which keys apply depends on
/// `driver`; a key that the driver does not use is an error.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DimensionSpec {
    pub name: String,
    pub driver: DriverSpec,
    pub samples: u32,
    /// Only for `animation` (default `time`); `orbit` is always `view`, `light_path` and
    /// `light_direction` `light`.
    pub kind: Option<KindSpec>,
    /// The samples cover a closed loop: the end of the range is not sampled again.
    pub periodic: Option<bool>,
    // orbit
    pub target: Option<[f32; 3]>,
    pub radius: Option<f32>,
    pub elevation_deg: Option<f32>,
    /// First and last azimuth in degrees.
    pub azimuth_deg: Option<[f32; 2]>,
    // animation
    pub animation: Option<String>,
    /// First and last sampled time in seconds; default the animation's keyframe range.
    pub time: Option<[f32; 2]>,
    // light_path
    pub light: Option<String>,
    pub path: Option<Vec<[f32; 3]>>,
    /// First and last sampled arc-length fraction, default `[0, 1]`.
    pub range: Option<[f32; 2]>,
    // light_direction (with `light`)
    /// `hemisphere` (default), `sphere` or `arc` (with `elevation_deg` and `azimuth_deg`).
    pub directions: Option<CoverSpec>,
    /// The hemisphere's pole, default `[0, 1, 0]`.
    pub up: Option<[f32; 3]>,
    /// A point, spot or sphere light's centre of turning.
    pub center: Option<[f32; 3]>,
    /// A point, spot or sphere light's distance from `center`.
    pub distance: Option<f32>,
}

/// Which directions a `light_direction` dimension covers, as written in scene.toml.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum CoverSpec {
    Hemisphere,
    Sphere,
    /// Along a circle of constant elevation: the light moving continuously.
    Arc,
}

/// `[preset.NAME]`: overrides applied when the preset is selected.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PresetSpec {
    pub resolution: Option<[u32; 2]>,
    pub spp: Option<u32>,
    /// Sample count per dimension name.
    #[serde(default)]
    pub samples: BTreeMap<String, u32>,
}

impl Manifest {
    /// Reads and parses scene.toml.
    pub fn read(path: &Path) -> Result<Manifest, SceneError> {
        let text = std::fs::read_to_string(path)
            .map_err(|source| SceneError::Io { path: path.to_owned(), source })?;
        Self::parse(&text, path)
    }

    /// Parses scene.toml text; `path` is used in error messages.
    pub fn parse(text: &str, path: &Path) -> Result<Manifest, SceneError> {
        let manifest: Manifest = toml::from_str(text)
            .map_err(|e| SceneError::Toml { path: path.to_owned(), message: e.to_string() })?;
        manifest.check_finite(path)?;
        Ok(manifest)
    }

    /// Applies the named preset (resolution, spp, per-dimension sample counts).
    pub fn apply_preset(&mut self, preset: &str, path: &Path) -> Result<(), SceneError> {
        let Some(p) = self.presets.get(preset).cloned() else {
            return Err(SceneError::unknown(
                path,
                "preset",
                "preset",
                preset,
                self.presets.keys().map(String::as_str),
            ));
        };
        if let Some(r) = p.resolution {
            self.resolution = r;
        }
        if let Some(s) = p.spp {
            self.spp = s;
        }
        for (name, n) in &p.samples {
            let Some(d) = self.dimensions.iter_mut().find(|d| &d.name == name) else {
                let known: Vec<&str> = self.dimensions.iter().map(|d| d.name.as_str()).collect();
                return Err(SceneError::unknown(
                    path,
                    format!("preset.{preset}.samples"),
                    "dimension",
                    name,
                    known,
                ));
            };
            d.samples = *n;
        }
        Ok(())
    }

    /// TOML admits `nan` and `inf`; no number in a manifest may be either.
    fn check_finite(&self, path: &Path) -> Result<(), SceneError> {
        let check = |field: String, values: &[f32]| -> Result<(), SceneError> {
            match values.iter().position(|v| !v.is_finite()) {
                Some(element) => {
                    Err(SceneError::NonFinite { path: path.to_owned(), field, element })
                }
                None => Ok(()),
            }
        };
        if let Some(c) = &self.camera {
            for (key, v) in [("eye", c.eye), ("target", c.target), ("up", c.up)] {
                if let Some(v) = v {
                    check(format!("camera.{key}"), &v)?;
                }
            }
            for (key, v) in [("yfov_deg", c.yfov_deg), ("znear", c.znear)] {
                if let Some(v) = v {
                    check(format!("camera.{key}"), &[v])?;
                }
            }
        }
        for (i, d) in self.dimensions.iter().enumerate() {
            let f = |key: &str| format!("dimension[{i}].{key}");
            if let Some(v) = d.target {
                check(f("target"), &v)?;
            }
            for (key, v) in [("radius", d.radius), ("elevation_deg", d.elevation_deg)] {
                if let Some(v) = v {
                    check(f(key), &[v])?;
                }
            }
            for (key, v) in [("azimuth_deg", d.azimuth_deg), ("time", d.time), ("range", d.range)] {
                if let Some(v) = v {
                    check(f(key), &v)?;
                }
            }
            if let Some(p) = &d.path {
                let flat: Vec<f32> = p.iter().flatten().copied().collect();
                check(f("path"), &flat)?;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const TOML: &str = r#"
        name = "t"
        gltf = "scene.gltf"
        resolution = [160, 120]
        spp = 4

        [camera]
        node = "Camera"

        [object.Vase]
        role = "reflective"

        [[dimension]]
        name = "light"
        driver = "animation"
        animation = "swing"
        kind = "light"
        samples = 4

        [[dimension]]
        name = "view"
        driver = "orbit"
        samples = 4
        target = [0, 0.8, 0]
        radius = 3
        elevation_deg = 20
        azimuth_deg = [0, 45]

        [preset.paper]
        resolution = [640, 480]
        spp = 64
        samples = { view = 8, light = 8 }
    "#;

    #[test]
    fn parses_every_section() {
        let m = Manifest::parse(TOML, Path::new("scene.toml")).unwrap();
        assert_eq!(m.resolution, [160, 120]);
        assert_eq!(m.objects["Vase"].role, Some(RoleSpec::Reflective));
        assert_eq!(m.dimensions.len(), 2);
        assert_eq!(m.dimensions[0].driver, DriverSpec::Animation);
        assert_eq!(m.dimensions[0].kind, Some(KindSpec::Light));
        assert_eq!(m.dimensions[1].azimuth_deg, Some([0.0, 45.0]));
        assert_eq!(m.camera.as_ref().and_then(|c| c.node.as_deref()), Some("Camera"));
    }

    #[test]
    fn preset_overrides() {
        let mut m = Manifest::parse(TOML, Path::new("scene.toml")).unwrap();
        m.apply_preset("paper", Path::new("scene.toml")).unwrap();
        assert_eq!(m.resolution, [640, 480]);
        assert_eq!(m.spp, 64);
        assert_eq!(m.dimensions[0].samples, 8);
        assert_eq!(m.dimensions[1].samples, 8);
        let err = m.apply_preset("huge", Path::new("scene.toml")).unwrap_err();
        assert!(matches!(err, SceneError::UnknownName { what: "preset", .. }), "{err}");
    }

    #[test]
    fn unknown_key_is_an_error_naming_the_key() {
        let text = TOML.replace("radius = 3", "radius = 3\nradios = 4");
        let err = Manifest::parse(&text, Path::new("dir/scene.toml")).unwrap_err();
        let msg = err.to_string();
        assert!(matches!(err, SceneError::Toml { .. }));
        assert!(msg.contains("dir/scene.toml") && msg.contains("radios"), "{msg}");
    }

    #[test]
    fn nan_is_an_error_naming_the_field() {
        let text = TOML.replace("radius = 3", "radius = nan");
        let err = Manifest::parse(&text, Path::new("scene.toml")).unwrap_err();
        assert!(err.to_string().contains("dimension[1].radius"), "{err}");
    }

    #[test]
    fn preset_naming_an_unknown_dimension_fails() {
        let text = TOML.replace("view = 8,", "veiw = 8,");
        let mut m = Manifest::parse(&text, Path::new("scene.toml")).unwrap();
        let err = m.apply_preset("paper", Path::new("scene.toml")).unwrap_err();
        assert!(err.to_string().contains("veiw"), "{err}");
    }
}
