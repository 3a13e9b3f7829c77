//! A glTF material's textures: each image decoded once per colour space, each reference with
//! its texture-coordinate set and KHR_texture_transform.

use std::collections::BTreeMap;
use std::path::Path;

use serde_json::Value;

use crate::gltf_images::ImageData;
use crate::model::{Material, TextureImage};
use crate::texture_ref::{TextureRef, UvTransform};
use crate::SceneError;

/// The textures decoded so far and what reading them found to warn of.
pub(crate) struct TextureSet<'a> {
    path: &'a Path,
    images: &'a [ImageData],
    pub textures: Vec<TextureImage>,
    /// (image, sRGB) → index into `textures`.
    decoded: BTreeMap<(usize, bool), usize>,
    pub warnings: Vec<String>,
}

impl<'a> TextureSet<'a> {
    pub fn new(path: &'a Path, images: &'a [ImageData]) -> Self {
        TextureSet {
            path,
            images,
            textures: Vec::new(),
            decoded: BTreeMap::new(),
            warnings: Vec::new(),
        }
    }

    fn warn(&mut self, w: String) {
        if !self.warnings.contains(&w) {
            self.warnings.push(w);
        }
    }

    /// Reads the base-colour, metallic-roughness, emissive and normal textures of `m` into
    /// `mat`. The occlusion texture is not read: the tracer computes occlusion itself.
    pub fn read_material(
        &mut self,
        m: &gltf::Material,
        mat: &mut Material,
    ) -> Result<(), SceneError> {
        let field = format!("materials[{}]", m.index().unwrap_or(0));
        let pbr = m.pbr_metallic_roughness();
        let transform = |e: Option<&serde_json::Map<String, Value>>| {
            e.and_then(|e| e.get("KHR_texture_transform")).cloned()
        };
        if let Some(t) = pbr.base_color_texture() {
            let f = format!("{field}.pbrMetallicRoughness.baseColorTexture");
            mat.base_color_texture =
                self.read(&f, t.texture(), t.tex_coord(), transform(t.extensions()), true)?;
        }
        if let Some(t) = pbr.metallic_roughness_texture() {
            let f = format!("{field}.pbrMetallicRoughness.metallicRoughnessTexture");
            mat.metallic_roughness_texture =
                self.read(&f, t.texture(), t.tex_coord(), transform(t.extensions()), false)?;
        }
        if let Some(t) = m.emissive_texture() {
            let f = format!("{field}.emissiveTexture");
            mat.emissive_texture =
                self.read(&f, t.texture(), t.tex_coord(), transform(t.extensions()), true)?;
        }
        if let Some(t) = m.normal_texture() {
            let f = format!("{field}.normalTexture");
            if !t.scale().is_finite() {
                return Err(SceneError::NonFinite {
                    path: self.path.to_owned(),
                    field: format!("{f}.scale"),
                    element: 0,
                });
            }
            mat.normal_texture =
                self.read(&f, t.texture(), t.tex_coord(), transform(t.extensions()), false)?;
            mat.normal_scale = t.scale();
        }
        self.warn_unread(m);
        Ok(())
    }

    /// Textures of implemented extensions that PIS does not read, warned of once each.
    fn warn_unread(&mut self, m: &gltf::Material) {
        let unread = [
            (
                "KHR_materials_transmission",
                "transmissionTexture",
                m.transmission().and_then(|t| t.transmission_texture()).is_some(),
            ),
            (
                "KHR_materials_volume",
                "thicknessTexture",
                m.volume().and_then(|v| v.thickness_texture()).is_some(),
            ),
            (
                "KHR_materials_specular",
                "specularTexture",
                m.specular().and_then(|s| s.specular_texture()).is_some(),
            ),
            (
                "KHR_materials_specular",
                "specularColorTexture",
                m.specular().and_then(|s| s.specular_color_texture()).is_some(),
            ),
        ];
        for (ext, texture, present) in unread {
            if present {
                self.warn(format!(
                    "{ext}: {texture} is not read (its factor applies to the whole surface)"
                ));
            }
        }
    }

    /// The reference of texture info `field`: its image decoded (once per colour space), its
    /// texture-coordinate set and transform; `None`, with a warning, where the image could not
    /// be read (the material's factor then applies alone).
    fn read(
        &mut self,
        field: &str,
        texture: gltf::Texture,
        tex_coord: u32,
        transform: Option<Value>,
        srgb: bool,
    ) -> Result<Option<TextureRef>, SceneError> {
        let (transform, set) = match &transform {
            Some(v) => texture_transform(
                self.path,
                &format!("{field}.extensions.KHR_texture_transform"),
                v,
            )?,
            None => (UvTransform::IDENTITY, None),
        };
        let mut tex_coord = set.unwrap_or(tex_coord);
        if tex_coord > 1 {
            self.warn(format!("{field} reads TEXCOORD_{tex_coord}; PIS reads TEXCOORD_0 and TEXCOORD_1 only: TEXCOORD_0 is read instead"));
            tex_coord = 0;
        }
        let image = texture.source().index();
        let data = self.images.get(image).ok_or_else(|| {
            SceneError::invalid(self.path, field, format!("image {image} does not exist"))
        })?;
        let data = match data {
            Ok(data) => data,
            Err(why) => {
                self.warn(format!("{why}: {field} is not read (its factor applies alone)"));
                return Ok(None);
            }
        };
        let next = self.textures.len();
        let t = *self.decoded.entry((image, srgb)).or_insert(next);
        if t == next {
            let decoded = crate::texture::decode(data, srgb)
                .map_err(|why| SceneError::invalid(self.path, format!("images[{image}]"), why))?;
            self.textures.push(decoded);
        }
        Ok(Some(TextureRef { texture: t, tex_coord, transform }))
    }
}

/// KHR_texture_transform of a texture info: the transform and the `texCoord` override.
fn texture_transform(
    path: &Path,
    field: &str,
    v: &Value,
) -> Result<(UvTransform, Option<u32>), SceneError> {
    let bad = |key: &str, expected: &str| {
        SceneError::invalid(
            path,
            format!("{field}.{key}"),
            format!("expected {expected}, found {}", v[key]),
        )
    };
    let pair = |key: &str, default: [f32; 2]| -> Result<[f32; 2], SceneError> {
        match v.get(key) {
            None => Ok(default),
            Some(Value::Array(a)) if a.len() == 2 => {
                let x = a[0].as_f64().zip(a[1].as_f64()).map(|(x, y)| [x as f32, y as f32]);
                x.filter(|p| p.iter().all(|c| c.is_finite()))
                    .ok_or_else(|| bad(key, "two finite numbers"))
            }
            Some(_) => Err(bad(key, "two finite numbers")),
        }
    };
    let rotation = match v.get("rotation") {
        None => 0.0,
        Some(r) => r
            .as_f64()
            .map(|r| r as f32)
            .filter(|r| r.is_finite())
            .ok_or_else(|| bad("rotation", "a finite number"))?,
    };
    let tex_coord = match v.get("texCoord") {
        None => None,
        Some(t) => Some(
            t.as_u64()
                .and_then(|t| u32::try_from(t).ok())
                .ok_or_else(|| bad("texCoord", "an integer ≥ 0"))?,
        ),
    };
    let transform = UvTransform {
        offset: pair("offset", [0.0; 2])?,
        rotation,
        scale: pair("scale", [1.0; 2])?,
    };
    Ok((transform, tex_coord))
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn texture_transform_reads_every_field_and_refuses_bad_values() {
        let p = Path::new("a.gltf");
        let (t, set) = texture_transform(
            p,
            "x",
            &json!({"offset": [0.5, 1], "rotation": 0.25, "scale": [2, 3], "texCoord": 1}),
        )
        .unwrap();
        assert_eq!(t, UvTransform { offset: [0.5, 1.0], rotation: 0.25, scale: [2.0, 3.0] });
        assert_eq!(set, Some(1));
        assert_eq!(texture_transform(p, "x", &json!({})).unwrap(), (UvTransform::IDENTITY, None));
        for bad in [
            json!({"offset": [1]}),
            json!({"scale": "big"}),
            json!({"rotation": [1]}),
            json!({"texCoord": -1}),
        ] {
            let e = texture_transform(p, "m.t", &bad).unwrap_err().to_string();
            assert!(e.contains("m.t."), "{bad}: {e}");
        }
    }
}
