//! A small glTF 2.0 writer: JSON built with serde_json plus one binary buffer, written as
//! `NAME.gltf` and `NAME.bin`. Output is deterministic: arrays in insertion order, numbers
//! printed by serde_json's shortest round-trip formatting.

use std::collections::BTreeSet;
use std::io;
use std::path::Path;

use glam::{Quat, Vec3};
use serde_json::{json, Map, Value};

use crate::mesh::Mesh;

/// A material in glTF terms (PBR metallic-roughness and the KHR extensions PIS reads).
#[derive(Clone, Debug)]
pub struct MaterialDesc {
    pub name: &'static str,
    /// Linear RGBA.
    pub base_color: [f32; 4],
    /// Index returned by [`GltfWriter::add_png_texture`].
    pub base_color_texture: Option<usize>,
    pub metallic: f32,
    pub roughness: f32,
    /// KHR_materials_transmission factor.
    pub transmission: Option<f32>,
    /// KHR_materials_ior.
    pub ior: Option<f32>,
    /// KHR_materials_volume: thickness, attenuation distance, attenuation colour.
    pub volume: Option<(f32, f32, [f32; 3])>,
    /// KHR_materials_specular factor.
    pub specular: Option<f32>,
    /// Emissive colour and KHR_materials_emissive_strength.
    pub emissive: Option<([f32; 3], f32)>,
    /// `metallicRoughnessTexture` (roughness in G, metallic in B).
    pub metallic_roughness_texture: Option<usize>,
    /// `normalTexture` and its `scale`.
    pub normal_texture: Option<(usize, f32)>,
    /// `emissiveTexture` (times the emissive colour; needs `emissive`).
    pub emissive_texture: Option<usize>,
}

impl MaterialDesc {
    /// A plain dielectric (metallic 0) of the given colour and roughness.
    pub fn plain(name: &'static str, rgb: [f32; 3], roughness: f32) -> MaterialDesc {
        MaterialDesc {
            name,
            base_color: [rgb[0], rgb[1], rgb[2], 1.0],
            base_color_texture: None,
            metallic: 0.0,
            roughness,
            transmission: None,
            ior: None,
            volume: None,
            specular: None,
            emissive: None,
            metallic_roughness_texture: None,
            normal_texture: None,
            emissive_texture: None,
        }
    }

    /// A plain dielectric whose base colour is the image `texture` (white factor).
    pub fn textured(name: &'static str, texture: usize, roughness: f32) -> MaterialDesc {
        MaterialDesc {
            base_color_texture: Some(texture),
            ..MaterialDesc::plain(name, [1.0; 3], roughness)
        }
    }

    /// A metal (metallic 1) of the given colour and roughness.
    pub fn metal(name: &'static str, rgb: [f32; 3], roughness: f32) -> MaterialDesc {
        MaterialDesc { metallic: 1.0, ..MaterialDesc::plain(name, rgb, roughness) }
    }

    /// Clear glass: full transmission, the given IOR and Beer absorption towards `tint`
    /// over `attenuation_distance`; `thickness` is the volume extension's thickness factor.
    pub fn glass(
        name: &'static str,
        ior: f32,
        thickness: f32,
        attenuation_distance: f32,
        tint: [f32; 3],
    ) -> MaterialDesc {
        MaterialDesc {
            transmission: Some(1.0),
            ior: Some(ior),
            volume: Some((thickness, attenuation_distance, tint)),
            specular: Some(1.0),
            ..MaterialDesc::plain(name, [1.0, 1.0, 1.0], 0.0)
        }
    }
}

/// A node to add.
#[derive(Clone, Debug, Default)]
pub struct NodeDesc {
    pub name: String,
    pub mesh: Option<usize>,
    pub camera: Option<usize>,
    pub light: Option<usize>,
    pub translation: Option<Vec3>,
    pub rotation: Option<Quat>,
    pub scale: Option<Vec3>,
    pub children: Vec<usize>,
}

/// glTF animation interpolation.
#[derive(Clone, Copy, Debug)]
pub enum Interp {
    Step,
    Linear,
    CubicSpline,
}

/// One animation channel with its own sampler; `values` are flattened (3 per key for
/// translation and scale, 4 for rotation; three times as many for CUBICSPLINE).
#[derive(Clone, Debug)]
pub struct ChannelDesc {
    pub node: usize,
    /// "translation", "rotation" or "scale".
    pub path: &'static str,
    pub interpolation: Interp,
    pub times: Vec<f32>,
    pub values: Vec<f32>,
}

/// Accumulates a glTF document and its binary buffer.
#[derive(Default)]
pub struct GltfWriter {
    bin: Vec<u8>,
    buffer_views: Vec<Value>,
    accessors: Vec<Value>,
    meshes: Vec<Value>,
    materials: Vec<Value>,
    nodes: Vec<Value>,
    cameras: Vec<Value>,
    lights: Vec<Value>,
    animations: Vec<Value>,
    images: Vec<Value>,
    textures: Vec<Value>,
    roots: Vec<usize>,
    extensions_used: BTreeSet<&'static str>,
}

impl GltfWriter {
    pub fn new() -> GltfWriter {
        GltfWriter::default()
    }

    fn view(&mut self, bytes: &[u8], target: Option<u32>) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let mut v = json!({"buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len()});
        if let Some(t) = target {
            v["target"] = json!(t);
        }
        self.bin.extend_from_slice(bytes);
        self.buffer_views.push(v);
        self.buffer_views.len() - 1
    }

    /// Adds a float accessor of `components` per element ("SCALAR", "VEC2", ...).
    fn float_accessor(
        &mut self,
        data: &[f32],
        kind: &str,
        components: usize,
        with_bounds: bool,
        target: Option<u32>,
    ) -> usize {
        let bytes: Vec<u8> = data.iter().flat_map(|x| x.to_le_bytes()).collect();
        let view = self.view(&bytes, target);
        let count = data.len() / components;
        let mut a =
            json!({"bufferView": view, "componentType": 5126, "count": count, "type": kind});
        if with_bounds && count > 0 {
            let mut min = vec![f32::INFINITY; components];
            let mut max = vec![f32::NEG_INFINITY; components];
            for e in data.chunks_exact(components) {
                for k in 0..components {
                    min[k] = min[k].min(e[k]);
                    max[k] = max[k].max(e[k]);
                }
            }
            a["min"] = json!(min);
            a["max"] = json!(max);
        }
        self.accessors.push(a);
        self.accessors.len() - 1
    }

    fn index_accessor(&mut self, indices: &[u32], vertex_count: usize) -> usize {
        let (bytes, component): (Vec<u8>, u32) = if vertex_count <= u16::MAX as usize {
            (indices.iter().flat_map(|&i| (i as u16).to_le_bytes()).collect(), 5123)
        } else {
            (indices.iter().flat_map(|i| i.to_le_bytes()).collect(), 5125)
        };
        let view = self.view(&bytes, Some(34963));
        self.accessors.push(json!({"bufferView": view, "componentType": component, "count": indices.len(), "type": "SCALAR"}));
        self.accessors.len() - 1
    }

    /// Adds a material; returns its index.
    pub fn add_material(&mut self, m: &MaterialDesc) -> usize {
        let mut pbr = json!({"baseColorFactor": m.base_color, "metallicFactor": m.metallic, "roughnessFactor": m.roughness});
        if let Some(t) = m.base_color_texture {
            pbr["baseColorTexture"] = json!({"index": t});
        }
        if let Some(t) = m.metallic_roughness_texture {
            pbr["metallicRoughnessTexture"] = json!({"index": t});
        }
        let mut v = json!({"name": m.name, "pbrMetallicRoughness": pbr});
        if let Some((t, scale)) = m.normal_texture {
            v["normalTexture"] = json!({"index": t, "scale": scale});
        }
        if let Some(t) = m.emissive_texture {
            v["emissiveTexture"] = json!({"index": t});
        }
        let mut ext: Vec<(&'static str, Value)> = Vec::new();
        if let Some(t) = m.transmission {
            ext.push(("KHR_materials_transmission", json!({"transmissionFactor": t})));
        }
        if let Some(ior) = m.ior {
            ext.push(("KHR_materials_ior", json!({"ior": ior})));
        }
        if let Some((thickness, distance, color)) = m.volume {
            ext.push((
                "KHR_materials_volume",
                json!({"thicknessFactor": thickness, "attenuationDistance": distance, "attenuationColor": color}),
            ));
        }
        if let Some(s) = m.specular {
            ext.push(("KHR_materials_specular", json!({"specularFactor": s})));
        }
        if let Some((color, strength)) = m.emissive {
            v["emissiveFactor"] = json!(color);
            ext.push(("KHR_materials_emissive_strength", json!({"emissiveStrength": strength})));
        }
        if !ext.is_empty() {
            let mut map = Map::new();
            for (name, value) in ext {
                self.extensions_used.insert(name);
                map.insert(name.to_owned(), value);
            }
            v["extensions"] = Value::Object(map);
        }
        self.materials.push(v);
        self.materials.len() - 1
    }

    /// Adds a mesh of one primitive; returns the mesh index.
    pub fn add_mesh(&mut self, name: &str, mesh: &Mesh, material: usize) -> usize {
        let flat = |v: &[Vec3]| v.iter().flat_map(|p| p.to_array()).collect::<Vec<f32>>();
        let pos = self.float_accessor(&flat(&mesh.positions), "VEC3", 3, true, Some(34962));
        let nrm = self.float_accessor(&flat(&mesh.normals), "VEC3", 3, false, Some(34962));
        let uvs: Vec<f32> = mesh.uvs.iter().flat_map(|t| t.to_array()).collect();
        let uv = self.float_accessor(&uvs, "VEC2", 2, false, Some(34962));
        let idx = self.index_accessor(&mesh.indices, mesh.positions.len());
        self.meshes.push(json!({
            "name": name,
            "primitives": [{
                "attributes": {"POSITION": pos, "NORMAL": nrm, "TEXCOORD_0": uv},
                "indices": idx,
                "material": material,
            }]
        }));
        self.meshes.len() - 1
    }

    /// Adds a perspective camera; returns its index.
    pub fn add_camera(&mut self, yfov_deg: f32, aspect: f32, znear: f32) -> usize {
        self.cameras.push(json!({"type": "perspective", "perspective": {"yfov": yfov_deg.to_radians(), "aspectRatio": aspect, "znear": znear}}));
        self.cameras.len() - 1
    }

    /// Adds a KHR_lights_punctual point light with a sphere radius in its extras.
    pub fn add_point_light(
        &mut self,
        name: &str,
        color: [f32; 3],
        intensity: f32,
        radius: f32,
    ) -> usize {
        self.extensions_used.insert("KHR_lights_punctual");
        self.lights.push(json!({"name": name, "type": "point", "color": color, "intensity": intensity, "extras": {"radius": radius}}));
        self.lights.len() - 1
    }

    /// Adds a PNG image (a file beside the .gltf) and a texture sampling it with repeat wrap
    /// and trilinear filtering; returns the texture index.
    pub fn add_png_texture(&mut self, uri: &str) -> usize {
        self.images.push(json!({"uri": uri, "mimeType": "image/png"}));
        self.textures.push(json!({"source": self.images.len() - 1, "sampler": 0}));
        self.textures.len() - 1
    }

    /// Lists `name` in `extensionsUsed` (as exporters do for extensions they write).
    pub fn use_extension(&mut self, name: &'static str) {
        self.extensions_used.insert(name);
    }

    /// Adds a node; `root` puts it in the scene's root list. Returns its index.
    pub fn add_node(&mut self, n: NodeDesc, root: bool) -> usize {
        let mut v = json!({"name": n.name});
        if let Some(m) = n.mesh {
            v["mesh"] = json!(m);
        }
        if let Some(c) = n.camera {
            v["camera"] = json!(c);
        }
        if let Some(l) = n.light {
            v["extensions"] = json!({"KHR_lights_punctual": {"light": l}});
        }
        if let Some(t) = n.translation {
            v["translation"] = json!(t.to_array());
        }
        if let Some(r) = n.rotation {
            v["rotation"] = json!(r.to_array());
        }
        if let Some(s) = n.scale {
            v["scale"] = json!(s.to_array());
        }
        if !n.children.is_empty() {
            v["children"] = json!(n.children);
        }
        self.nodes.push(v);
        let index = self.nodes.len() - 1;
        if root {
            self.roots.push(index);
        }
        index
    }

    /// Adds a named animation.
    pub fn add_animation(&mut self, name: &str, channels: &[ChannelDesc]) {
        let mut samplers = Vec::new();
        let mut chans = Vec::new();
        for c in channels {
            let input = self.float_accessor(&c.times, "SCALAR", 1, true, None);
            let (kind, comps) = if c.path == "rotation" { ("VEC4", 4) } else { ("VEC3", 3) };
            let output = self.float_accessor(&c.values, kind, comps, false, None);
            let interpolation = match c.interpolation {
                Interp::Step => "STEP",
                Interp::Linear => "LINEAR",
                Interp::CubicSpline => "CUBICSPLINE",
            };
            samplers
                .push(json!({"input": input, "output": output, "interpolation": interpolation}));
            chans.push(
                json!({"sampler": samplers.len() - 1, "target": {"node": c.node, "path": c.path}}),
            );
        }
        self.animations.push(json!({"name": name, "samplers": samplers, "channels": chans}));
    }

    /// Writes `dir/NAME.gltf` and `dir/NAME.bin`.
    pub fn write(mut self, dir: &Path, name: &str) -> io::Result<()> {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let mut doc = json!({
            "asset": {"version": "2.0", "generator": "pis-samples"},
            "scene": 0,
            "scenes": [{"name": name, "nodes": self.roots}],
            "nodes": self.nodes,
            "meshes": self.meshes,
            "materials": self.materials,
            "accessors": self.accessors,
            "bufferViews": self.buffer_views,
            "buffers": [{"uri": format!("{name}.bin"), "byteLength": self.bin.len()}],
        });
        if !self.cameras.is_empty() {
            doc["cameras"] = json!(self.cameras);
        }
        if !self.animations.is_empty() {
            doc["animations"] = json!(self.animations);
        }
        if !self.textures.is_empty() {
            doc["images"] = json!(self.images);
            doc["textures"] = json!(self.textures);
            doc["samplers"] =
                json!([{"magFilter": 9729, "minFilter": 9987, "wrapS": 10497, "wrapT": 10497}]);
        }
        if !self.lights.is_empty() {
            doc["extensions"] = json!({"KHR_lights_punctual": {"lights": self.lights}});
        }
        if !self.extensions_used.is_empty() {
            doc["extensionsUsed"] = json!(self.extensions_used.iter().collect::<Vec<_>>());
        }
        let mut text = serde_json::to_string_pretty(&doc).map_err(io::Error::other)?;
        text.push('\n');
        std::fs::write(dir.join(format!("{name}.gltf")), text)?;
        std::fs::write(dir.join(format!("{name}.bin")), &self.bin)
    }
}
