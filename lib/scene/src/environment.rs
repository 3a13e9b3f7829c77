//! The environment light (`[environment]` in scene.toml): radiance arriving from infinitely
//! far away, a uniform colour or an equirectangular (latitude-longitude) image, turned about
//! +Y by `rotation_deg`. What arrives from each direction is defined here
//! ([`Environment::radiance`]); the tracer importance-samples it by the image's
//! [`Distribution2D`], built once at load.
//!
//! The lat-long convention (+Y up, as in glTF): the image's top row looks straight up (+Y),
//! its bottom row straight down; the centre of the image looks along +X; a quarter of the
//! width right of the centre is +Z, a quarter left of it −Z, the left and right edges −X.
//! Seen from inside, the image is not mirrored (turning right, from +X towards +Z, moves
//! right in the image). Each texel is a patch of constant radiance.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::{Quat, Vec3};
use serde::Deserialize;
use std::f32::consts::PI;

use crate::distribution::Distribution2D;
use crate::SceneError;

/// `[environment]`: the environment light as written in scene.toml.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EnvironmentSpec {
    /// Uniform linear RGB radiance (instead of `image`).
    pub color: Option<[f32; 3]>,
    /// An equirectangular `.hdr` or `.exr` image, relative to scene.toml.
    pub image: Option<String>,
    /// Scales the radiance; default 1.
    pub strength: Option<f32>,
    /// Turns the environment about +Y (degrees, right-hand rule); default 0.
    pub rotation_deg: Option<f32>,
    /// Camera rays that leave the scene see the environment; default false (black).
    pub background: Option<bool>,
}

/// The environment light of a scene.
#[derive(Clone, Debug, PartialEq)]
pub struct Environment {
    pub radiance: EnvironmentRadiance,
    /// Turn about +Y in radians (right-hand rule): the image's direction d is the world's
    /// direction `rotation · d`.
    pub rotation: f32,
    /// Whether camera rays that hit nothing see the environment (else black).
    pub background: bool,
}

/// What the environment emits.
#[derive(Clone, Debug, PartialEq)]
pub enum EnvironmentRadiance {
    /// The same linear RGB radiance from every direction (strength applied).
    Uniform([f32; 3]),
    /// An equirectangular image (shared: scenes are cloned for probes).
    Image(Arc<LatLongImage>),
}

/// An equirectangular environment image in linear RGB, strength applied, with the
/// distribution the tracer samples it by.
#[derive(Clone, PartialEq)]
pub struct LatLongImage {
    /// The file it was read from.
    pub file: PathBuf,
    pub width: u32,
    pub height: u32,
    /// Row after row from the top (+Y); finite and ≥ 0.
    pub texels: Vec<[f32; 3]>,
    /// Over the texels, proportional to luminance × sin θ (θ from +Y at the row's centre),
    /// so that the directions drawn follow the light arriving; `None` when the image is
    /// black.
    pub distribution: Option<Distribution2D>,
}

impl std::fmt::Debug for LatLongImage {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "LatLongImage({}, {}x{})", self.file.display(), self.width, self.height)
    }
}

/// Image coordinates (u, v) ∈ [0, 1]² of the direction `d` (unit) in the image's own frame:
/// u = ½ + atan2(z, x) / 2π (0.5 at +X, 0.75 at +Z), v = acos(y) / π (0 at +Y).
pub fn lat_long_uv(d: Vec3) -> [f32; 2] {
    let u = 0.5 + d.z.atan2(d.x) / (2.0 * PI);
    let v = d.y.clamp(-1.0, 1.0).acos() / PI;
    [u.clamp(0.0, 1.0), v.clamp(0.0, 1.0)]
}

/// The unit direction (image frame) of image coordinates (u, v): the inverse of
/// [`lat_long_uv`].
pub fn lat_long_direction(uv: [f32; 2]) -> Vec3 {
    let phi = 2.0 * PI * (uv[0] - 0.5);
    let (sin_t, cos_t) = (PI * uv[1]).sin_cos();
    Vec3::new(sin_t * phi.cos(), cos_t, sin_t * phi.sin())
}

/// Luminance of linear RGB (Rec. 709 weights).
fn luminance(c: [f32; 3]) -> f32 {
    0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
}

impl LatLongImage {
    /// An image of `width × height` texels (row after row from the top), finite and ≥ 0.
    pub fn new(file: PathBuf, width: u32, height: u32, texels: Vec<[f32; 3]>) -> LatLongImage {
        let (w, h) = (width as usize, height as usize);
        let distribution = Distribution2D::new(w, h, |i, j| {
            let sin_theta = (PI * (j as f32 + 0.5) / h as f32).sin();
            texels.get(j * w + i).map_or(0.0, |&t| luminance(t) * sin_theta)
        });
        LatLongImage { file, width, height, texels, distribution }
    }

    /// The texel holding image coordinates `uv`.
    pub fn texel(&self, uv: [f32; 2]) -> [f32; 3] {
        let i = ((uv[0].max(0.0) * self.width as f32) as usize).min(self.width as usize - 1);
        let j = ((uv[1].max(0.0) * self.height as f32) as usize).min(self.height as usize - 1);
        self.texel_at(i, j)
    }

    /// Texel (column, row), clamped to the image.
    pub fn texel_at(&self, i: usize, j: usize) -> [f32; 3] {
        let (i, j) = (i.min(self.width as usize - 1), j.min(self.height as usize - 1));
        self.texels[j * self.width as usize + i]
    }
}

impl Environment {
    /// The world direction of the image-frame direction `d`.
    pub fn to_world(&self, d: Vec3) -> Vec3 {
        Quat::from_rotation_y(self.rotation) * d
    }

    /// The image-frame direction of the world direction `d`.
    pub fn to_image(&self, d: Vec3) -> Vec3 {
        Quat::from_rotation_y(-self.rotation) * d
    }

    /// Radiance arriving from the world direction `d` (unit; that is, along −d).
    pub fn radiance(&self, d: Vec3) -> [f32; 3] {
        match &self.radiance {
            EnvironmentRadiance::Uniform(c) => *c,
            EnvironmentRadiance::Image(image) => image.texel(lat_long_uv(self.to_image(d))),
        }
    }

    /// Whether any direction sends light.
    pub fn emits(&self) -> bool {
        match &self.radiance {
            EnvironmentRadiance::Uniform(c) => c.iter().any(|&x| x > 0.0),
            EnvironmentRadiance::Image(image) => image.distribution.is_some(),
        }
    }
}

/// Resolves `[environment]` of the scene.toml at `path`: validates every key (errors name
/// `environment.KEY`) and reads the image, which must lie in scene.toml's folder unless
/// `allow_outside` (`allow_outside_files`).
pub(crate) fn load(
    spec: &EnvironmentSpec,
    path: &Path,
    allow_outside: bool,
) -> Result<Environment, SceneError> {
    let bad = |key: &str, why: String| SceneError::invalid(path, format!("environment.{key}"), why);
    let strength = spec.strength.unwrap_or(1.0);
    if !(strength.is_finite() && strength >= 0.0) {
        return Err(bad("strength", format!("{strength}: expected a finite value ≥ 0")));
    }
    let rotation_deg = spec.rotation_deg.unwrap_or(0.0);
    if !rotation_deg.is_finite() {
        return Err(bad(
            "rotation_deg",
            format!("{rotation_deg}: expected a finite angle in degrees"),
        ));
    }
    let radiance = match (&spec.color, &spec.image) {
        (Some(_), Some(_)) => {
            return Err(bad("image", "give either `color` or `image`, not both".into()))
        }
        (None, None) => {
            return Err(SceneError::invalid(
                path,
                "environment",
                "needs `color = [r, g, b]` or `image = \"FILE.hdr\"`",
            ))
        }
        (Some(c), None) => {
            if c.iter().any(|x| !(x.is_finite() && *x >= 0.0)) {
                return Err(bad("color", format!("{c:?}: expected finite values ≥ 0")));
            }
            EnvironmentRadiance::Uniform(c.map(|x| x * strength))
        }
        (None, Some(name)) => {
            let file = image_path(name, path, allow_outside)?;
            let (w, h, mut texels) = crate::env_image::read(&file)
                .map_err(|why| bad("image", format!("{}: {why}", file.display())))?;
            if let Some(k) = texels.iter().position(|t| t.iter().any(|x| !x.is_finite())) {
                let (x, y) = (k % w as usize, k / w as usize);
                return Err(bad(
                    "image",
                    format!("{}: texel ({x}, {y}) is not finite (NaN or infinity)", file.display()),
                ));
            }
            // Negative values (ringing of a resampled image) emit nothing.
            for t in &mut texels {
                *t = t.map(|x| x.max(0.0) * strength);
            }
            EnvironmentRadiance::Image(Arc::new(LatLongImage::new(file, w, h, texels)))
        }
    };
    Ok(Environment {
        radiance,
        rotation: rotation_deg.to_radians(),
        background: spec.background.unwrap_or(false),
    })
}

/// The file `name` names beside the scene.toml at `path`, refused when it is absolute or
/// leaves scene.toml's folder (unless `allow_outside`).
fn image_path(name: &str, path: &Path, allow_outside: bool) -> Result<PathBuf, SceneError> {
    let base = path.parent().unwrap_or(Path::new(""));
    let refuse = |why: &str| {
        SceneError::invalid(
            path,
            "environment.image",
            format!("{name:?} {why}; refused (scene.toml `allow_outside_files = true` allows it)"),
        )
    };
    if name.trim().is_empty() {
        return Err(SceneError::invalid(path, "environment.image", "the image path is empty"));
    }
    let target = base.join(name);
    if allow_outside {
        return Ok(target);
    }
    let rel = Path::new(name);
    if rel.is_absolute() || rel.has_root() || name.starts_with('/') || name.starts_with('\\') {
        return Err(refuse("is an absolute path, outside scene.toml's folder"));
    }
    if crate::gltf_files::stays_inside(base, &target, name) {
        Ok(target)
    } else {
        Err(refuse("leaves scene.toml's folder"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The convention docs/SCENE.md states: centre +X, a quarter right +Z, a quarter left
    /// −Z, edges −X, top +Y, bottom −Y; `rotation_deg = 90` moves the centre to −Z.
    #[test]
    fn the_lat_long_convention_is_the_documented_one() {
        let close =
            |a: [f32; 2], b: [f32; 2]| (a[0] - b[0]).abs() < 1e-6 && (a[1] - b[1]).abs() < 1e-6;
        assert!(close(lat_long_uv(Vec3::X), [0.5, 0.5]));
        assert!(close(lat_long_uv(Vec3::Z), [0.75, 0.5]));
        assert!(close(lat_long_uv(Vec3::NEG_Z), [0.25, 0.5]));
        assert!(lat_long_uv(Vec3::Y)[1] < 1e-6 && lat_long_uv(Vec3::NEG_Y)[1] > 1.0 - 1e-6);
        let edge = lat_long_uv(Vec3::NEG_X)[0];
        assert!(!(1e-6..=1.0 - 1e-6).contains(&edge), "−X at u = {edge}");
        for k in 0..100 {
            let uv = [
                (k as f32 * 0.618_034).fract(),
                (k as f32 * 0.414_213_5 + 0.01).fract() * 0.98 + 0.01,
            ];
            let back = lat_long_uv(lat_long_direction(uv));
            // u = 0 and u = 1 are the same meridian (−X).
            let du = (back[0] - uv[0]).abs();
            assert!(du.min(1.0 - du) < 1e-5 && (back[1] - uv[1]).abs() < 1e-5, "{uv:?} → {back:?}");
        }
        let turned = Environment {
            radiance: EnvironmentRadiance::Uniform([1.0; 3]),
            rotation: 90f32.to_radians(),
            background: false,
        };
        assert!(
            turned.to_world(Vec3::X).abs_diff_eq(Vec3::NEG_Z, 1e-6),
            "{}",
            turned.to_world(Vec3::X)
        );
        assert!(turned.to_image(Vec3::NEG_Z).abs_diff_eq(Vec3::X, 1e-6));
    }

    /// An image lit in one texel: radiance from the direction of that texel, black
    /// elsewhere; all of the distribution on it.
    #[test]
    fn radiance_comes_from_the_texel_a_direction_maps_to() {
        let (w, h) = (8u32, 4u32);
        let mut texels = vec![[0.0; 3]; 32];
        // Row 1 (above the horizon), column 6: u ∈ [0.75, 0.875), from +Z a little towards −X.
        texels[w as usize + 6] = [2.0, 3.0, 4.0];
        let image = LatLongImage::new("sky.hdr".into(), w, h, texels);
        let centre = lat_long_direction([6.5 / 8.0, 1.5 / 4.0]);
        let env = Environment {
            radiance: EnvironmentRadiance::Image(Arc::new(image)),
            rotation: 0.0,
            background: false,
        };
        assert_eq!(env.radiance(centre), [2.0, 3.0, 4.0]);
        assert!(centre.y > 0.0 && centre.z > 0.0 && centre.x < 0.0, "{centre}");
        assert_eq!(env.radiance(-centre), [0.0; 3]);
        assert!(env.emits());
        let EnvironmentRadiance::Image(image) = &env.radiance else { unreachable!() };
        let d = image.distribution.as_ref().unwrap();
        assert_eq!(d.sample([0.3, 0.7]).2, (6, 1));
    }
}
