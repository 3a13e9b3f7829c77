//! Reading a glTF 2.0 file (.gltf or .glb) into objects, materials, textures and the rig.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use glam::{Quat, Vec2, Vec3, Vec4};
use gltf::animation::util::ReadOutputs;
use gltf::mesh::Mode;

use crate::accessor_check::check_accessor;
use crate::animation::{Animation, Channel, Interpolation, Sampler, TargetPath, Trs};
use crate::material::{convert_material, infer_role, mean_material};
use crate::material_textures::TextureSet;
use crate::model::{LightKind, Material, Primitive, SceneObject, TextureImage};
use crate::rig::{LightRig, Node, Rig};
use crate::SceneError;

/// Everything read from the glTF, before scene.toml is applied.
#[derive(Debug)]
pub(crate) struct GltfScene {
    pub objects: Vec<SceneObject>,
    pub materials: Vec<Material>,
    pub textures: Vec<TextureImage>,
    pub rig: Rig,
    /// glTF cameras attached to nodes: (index into `rig.nodes`, perspective parameters).
    pub cameras: Vec<GltfCamera>,
    /// Animations that cannot be sampled, with the field and reason (used only if referenced).
    pub unsupported_animations: BTreeMap<String, Unsupported>,
    /// What the glTF uses that PIS ignores or reads otherwise, one line each.
    pub warnings: Vec<String>,
}

/// What PIS cannot sample in an animation: the field, and why.
pub(crate) type Unsupported = (String, String);

/// A perspective glTF camera on a node.
#[derive(Clone, Debug)]
pub(crate) struct GltfCamera {
    pub node: usize,
    pub yfov: f32,
    pub znear: f32,
    pub zfar: Option<f32>,
}

/// Reads the glTF file at `path`, its buffers and its images.
///
/// Indices and accessors are checked before the gltf crate's readers see them; should the
/// crate still panic on malformed data (its validation indexes unchecked in places), the
/// panic becomes a [`SceneError::Gltf`].
pub(crate) fn read_gltf(path: &Path, allow_outside: bool) -> Result<GltfScene, SceneError> {
    if let Err(source) = std::fs::metadata(path) {
        return Err(SceneError::Io { path: path.to_owned(), source });
    }
    let read = || {
        // Parsed once: the files it names are checked before any is read.
        let gltf = open_gltf(path)?;
        crate::gltf_files::check_files(path, &gltf, allow_outside)?;
        let base = path.parent().unwrap_or(Path::new("./"));
        let gltf::Gltf { document: doc, blob } = gltf;
        let buffers =
            gltf::import_buffers(&doc, Some(base), blob).map_err(|e| import_error(path, e))?;
        let images = crate::gltf_images::import_images(path, &doc, base, &buffers)?;
        check_animation_indices(path, &doc)?;
        convert(path, &doc, &buffers, &images)
    };
    std::panic::catch_unwind(read).unwrap_or_else(|panic| {
        let what = panic
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| panic.downcast_ref::<String>().cloned())
            .unwrap_or_default();
        Err(SceneError::Gltf {
            path: path.to_owned(),
            message: format!("malformed data made the glTF reader fail: {what}"),
        })
    })
}

/// Parses the glTF, refuses an extension it requires that PIS can neither implement nor
/// ignore (naming it), then validates the rest (the glTF reader's own list of extensions it
/// accepts as required is narrower than what PIS reads).
fn open_gltf(path: &Path) -> Result<gltf::Gltf, SceneError> {
    let file = std::fs::File::open(path)
        .map_err(|source| SceneError::Io { path: path.to_owned(), source })?;
    let parsed = gltf::Gltf::from_reader_without_validation(std::io::BufReader::new(file));
    let gltf::Gltf { document, blob } = parsed.map_err(|e| import_error(path, e))?;
    let mut root = document.into_json();
    crate::extensions::check_required(path, &root.extensions_required)?;
    root.extensions_required.clear();
    let document = gltf::Document::from_json(root).map_err(|e| import_error(path, e))?;
    Ok(gltf::Gltf { document, blob })
}

/// Animation channel targets and samplers are not validated by the gltf crate, whose
/// accessors then panic; check them here.
fn check_animation_indices(path: &Path, doc: &gltf::Document) -> Result<(), SceneError> {
    let root = doc.as_json();
    for (ai, a) in root.animations.iter().enumerate() {
        for (ci, c) in a.channels.iter().enumerate() {
            let field = format!("animations[{ai}].channels[{ci}]");
            let node = c.target.node.value();
            if node >= root.nodes.len() {
                let msg = format!("node {node} does not exist");
                return Err(SceneError::invalid(path, format!("{field}.target.node"), msg));
            }
            let sampler = c.sampler.value();
            if sampler >= a.samplers.len() {
                let msg = format!("sampler {sampler} does not exist");
                return Err(SceneError::invalid(path, format!("{field}.sampler"), msg));
            }
        }
    }
    Ok(())
}

/// Converts an imported document (see [`read_gltf`]).
fn convert(
    path: &Path,
    doc: &gltf::Document,
    buffers: &[gltf::buffer::Data],
    images: &[crate::gltf_images::ImageData],
) -> Result<GltfScene, SceneError> {
    let ctx = Ctx { path: path.to_owned(), buffers };

    let scene = doc
        .default_scene()
        .or_else(|| doc.scenes().next())
        .ok_or_else(|| SceneError::invalid(path, "scenes", "the glTF has no scene"))?;
    let (mut rig, rig_index) = read_nodes(path, &scene)?;
    let Materials { mut materials, textures, mut warnings } = read_materials(path, doc, images)?;

    // The scene's nodes with their index in the rig, in glTF node order.
    let gltf_nodes: Vec<gltf::Node> = doc.nodes().collect();
    let mut by_gltf: Vec<(usize, usize)> = rig_index.iter().map(|(&g, &r)| (g, r)).collect();
    by_gltf.sort();
    let placed: Vec<(&gltf::Node, usize)> =
        by_gltf.iter().filter_map(|&(g, r)| Some((gltf_nodes.get(g)?, r))).collect();

    let objects = ctx.read_objects(&placed, &mut rig, &mut materials, &textures, &mut warnings)?;
    let cameras = ctx.read_lights_and_cameras(&placed, &mut rig)?;
    let unsupported_animations = ctx.read_animations(doc, &rig_index, &mut rig)?;

    Ok(GltfScene { objects, materials, textures, rig, cameras, unsupported_animations, warnings })
}

/// The rig's nodes, depth-first from the scene roots, so that parents precede children;
/// also the rig index of each glTF node index.
fn read_nodes(
    path: &Path,
    scene: &gltf::Scene,
) -> Result<(Rig, BTreeMap<usize, usize>), SceneError> {
    let mut rig = Rig::default();
    let mut rig_index: BTreeMap<usize, usize> = BTreeMap::new();
    let mut stack: Vec<(gltf::Node, Option<usize>)> = scene.nodes().map(|n| (n, None)).collect();
    stack.reverse();
    while let Some((node, parent)) = stack.pop() {
        if rig_index.contains_key(&node.index()) {
            return Err(SceneError::invalid(
                path,
                format!("nodes[{}]", node.index()),
                "node is reached twice (it has two parents or is part of a cycle)",
            ));
        }
        let here = rig.nodes.len();
        rig_index.insert(node.index(), here);
        let (translation, rotation, scale) = node.transform().decomposed();
        let local = Trs {
            translation: Vec3::from(translation),
            rotation: Quat::from_array(rotation).normalize(),
            scale: Vec3::from(scale),
        };
        if !(local.translation.is_finite() && local.rotation.is_finite() && local.scale.is_finite())
        {
            return Err(SceneError::NonFinite {
                path: path.to_owned(),
                field: format!("nodes[{}]", node.index()),
                element: 0,
            });
        }
        rig.nodes.push(Node { name: node_name(&node), gltf_index: node.index(), parent, local });
        for child in node.children().collect::<Vec<_>>().into_iter().rev() {
            stack.push((child, Some(here)));
        }
    }
    Ok((rig, rig_index))
}

/// The glTF's materials in its order with the textures they read, and the warnings so far:
/// the extensions PIS does not implement, then what reading the textures found.
struct Materials {
    materials: Vec<Material>,
    textures: Vec<TextureImage>,
    warnings: Vec<String>,
}

/// Reads the [`Materials`].
fn read_materials(
    path: &Path,
    doc: &gltf::Document,
    images: &[crate::gltf_images::ImageData],
) -> Result<Materials, SceneError> {
    let mut texture_set = TextureSet::new(path, images);
    let mut materials = Vec::new();
    for m in doc.materials() {
        let mut mat = convert_material(&m);
        texture_set.read_material(&m, &mut mat)?;
        materials.push(mat);
    }
    let TextureSet { textures, warnings: texture_warnings, .. } = texture_set;
    let mut warnings =
        crate::extensions::unimplemented_warnings(doc.extensions_used().chain(
            (doc.as_json().materials.iter()).flat_map(|m| {
                m.extensions.iter().flat_map(|e| e.others.keys().map(String::as_str))
            }),
        ));
    warnings.extend(texture_warnings);
    Ok(Materials { materials, textures, warnings })
}

impl Ctx<'_> {
    /// Objects: one per placed node with a mesh, in glTF node order, each with its role.
    /// A default material is appended to `materials` if a primitive has none.
    fn read_objects(
        &self,
        placed: &[(&gltf::Node, usize)],
        rig: &mut Rig,
        materials: &mut Vec<Material>,
        textures: &[TextureImage],
        warnings: &mut Vec<String>,
    ) -> Result<Vec<SceneObject>, SceneError> {
        let mut default_material = None;
        let mut objects = Vec::new();
        let mut used_names: BTreeMap<String, usize> = BTreeMap::new();
        for &(node, r) in placed {
            let g = node.index();
            let Some(mesh) = node.mesh() else { continue };
            let mut primitives = Vec::new();
            for p in mesh.primitives() {
                let material = match p.material().index() {
                    Some(i) => i,
                    None => *default_material.get_or_insert_with(|| {
                        materials.push(Material { name: "default".into(), ..Material::default() });
                        materials.len() - 1
                    }),
                };
                let field = format!("meshes[{}].primitives[{}]", mesh.index(), p.index());
                let prim = self.read_primitive(&p, material, &field)?;
                if prim.uvs1.is_empty()
                    && materials
                        .get(material)
                        .is_some_and(|m| m.textures().any(|t| t.tex_coord == 1))
                {
                    let w = format!("{field} has no TEXCOORD_1, which the textures of materials[{material}] read: TEXCOORD_0 is read instead");
                    if !warnings.contains(&w) {
                        warnings.push(w);
                    }
                }
                primitives.push(prim);
            }
            // Roles are judged on the materials with their textures' means.
            let flat: Vec<Material> = primitives
                .iter()
                .filter_map(|p: &Primitive| materials.get(p.material))
                .map(|m| mean_material(m, textures))
                .collect();
            let mats: Vec<&Material> = flat.iter().collect();
            let mut name = rig.nodes[r].name.clone();
            if node.name().is_none() {
                if let Some(mesh_name) = mesh.name() {
                    name = mesh_name.to_owned();
                }
            }
            let count = used_names.entry(name.clone()).or_insert(0);
            *count += 1;
            if *count > 1 {
                name = format!("{name}.{g}");
            }
            objects.push(SceneObject {
                name,
                role: infer_role(&mats),
                reflector: None,
                primitives,
            });
            rig.object_nodes.push(r);
        }
        Ok(objects)
    }

    /// Lights (into the rig) and perspective cameras on the placed nodes.
    fn read_lights_and_cameras(
        &self,
        placed: &[(&gltf::Node, usize)],
        rig: &mut Rig,
    ) -> Result<Vec<GltfCamera>, SceneError> {
        let mut cameras = Vec::new();
        for &(node, r) in placed {
            if let Some(light) = node.light() {
                rig.lights.push(self.read_light(&light, &rig.nodes[r].name, r)?);
            }
            if let Some(camera) = node.camera() {
                if let gltf::camera::Projection::Perspective(p) = camera.projection() {
                    cameras.push(GltfCamera {
                        node: r,
                        yfov: p.yfov(),
                        znear: p.znear(),
                        zfar: p.zfar(),
                    });
                }
            }
        }
        Ok(cameras)
    }

    /// Animations into the rig; those that cannot be sampled by name, with the field and
    /// reason.
    fn read_animations(
        &self,
        doc: &gltf::Document,
        rig_index: &BTreeMap<usize, usize>,
        rig: &mut Rig,
    ) -> Result<BTreeMap<String, Unsupported>, SceneError> {
        let mut unsupported_animations = BTreeMap::new();
        for a in doc.animations() {
            let name =
                a.name().map(str::to_owned).unwrap_or_else(|| format!("animation{}", a.index()));
            match self.read_animation(&a, &name, rig_index)? {
                Ok(anim) => rig.animations.push(anim),
                Err(why) => {
                    unsupported_animations.insert(name, why);
                }
            }
        }
        Ok(unsupported_animations)
    }
}

/// Maps a gltf crate error to a [`SceneError`] that names the file.
fn import_error(path: &Path, e: gltf::Error) -> SceneError {
    match e {
        gltf::Error::Validation(errors) => {
            if let Some((p, _)) =
                errors.iter().find(|(p, _)| p.as_str().starts_with("extensionsRequired"))
            {
                return SceneError::unsupported(
                    path,
                    p.as_str(),
                    "required glTF extension is not supported by PIS",
                );
            }
            let list: Vec<String> =
                errors.iter().map(|(p, err)| format!("{}: {err}", p.as_str())).collect();
            SceneError::Gltf { path: path.to_owned(), message: list.join("; ") }
        }
        gltf::Error::Io(source) => SceneError::Gltf {
            path: path.to_owned(),
            message: format!("cannot read a buffer it references: {source}"),
        },
        other => SceneError::Gltf { path: path.to_owned(), message: other.to_string() },
    }
}

/// The largest |coordinate| of a vertex position: 10¹⁸, so that a squared distance or a dot
/// product of positions stays well inside `f32` (whose largest value is 3.4 · 10³⁸).
pub const MAX_COORDINATE: f32 = 1e18;

fn node_name(node: &gltf::Node) -> String {
    node.name().map(str::to_owned).unwrap_or_else(|| format!("node{}", node.index()))
}

/// What the readers need: the file (for errors) and the buffers.
struct Ctx<'b> {
    path: PathBuf,
    buffers: &'b [gltf::buffer::Data],
}

impl Ctx<'_> {
    fn non_finite(&self, field: String, element: usize) -> SceneError {
        SceneError::NonFinite { path: self.path.clone(), field, element }
    }

    fn check_finite<const N: usize>(
        &self,
        values: &[[f32; N]],
        field: impl Fn() -> String,
    ) -> Result<(), SceneError> {
        match values.iter().position(|v| v.iter().any(|x| !x.is_finite())) {
            Some(i) => Err(self.non_finite(field(), i)),
            None => Ok(()),
        }
    }

    /// Positions within ±[`MAX_COORDINATE`].
    fn check_in_range(
        &self,
        positions: &[[f32; 3]],
        field: impl Fn() -> String,
    ) -> Result<(), SceneError> {
        let out = |p: &[f32; 3]| p.iter().any(|x| x.abs() > MAX_COORDINATE);
        match positions.iter().position(out) {
            Some(i) => Err(SceneError::invalid(
                &self.path,
                field(),
                format!(
                    "element {i}: {:?} lies beyond ±{MAX_COORDINATE:e}, where squared distances \
                     no longer fit a 32-bit float",
                    positions[i]
                ),
            )),
            None => Ok(()),
        }
    }

    /// A vertex attribute beside POSITION's `n` values: finite, and one per vertex.
    fn check_vertex_attribute<const N: usize>(
        &self,
        values: &[[f32; N]],
        n: usize,
        field: impl Fn() -> String,
    ) -> Result<(), SceneError> {
        self.check_finite(values, &field)?;
        if values.len() != n {
            return Err(SceneError::invalid(&self.path, field(), "count differs from POSITION"));
        }
        Ok(())
    }

    fn read_primitive(
        &self,
        p: &gltf::Primitive,
        material: usize,
        field: &str,
    ) -> Result<Primitive, SceneError> {
        use gltf::accessor::{DataType as T, Dimensions as D};
        use gltf::Semantic;
        for (semantic, name, dims, types) in [
            (Semantic::Positions, "POSITION", D::Vec3, &[T::F32][..]),
            (Semantic::Normals, "NORMAL", D::Vec3, &[T::F32][..]),
            (Semantic::TexCoords(0), "TEXCOORD_0", D::Vec2, &[T::F32, T::U8, T::U16][..]),
            (Semantic::TexCoords(1), "TEXCOORD_1", D::Vec2, &[T::F32, T::U8, T::U16][..]),
            (Semantic::Tangents, "TANGENT", D::Vec4, &[T::F32][..]),
        ] {
            if let Some(a) = p.get(&semantic) {
                let f = format!("{field}.attributes.{name}");
                check_accessor(&self.path, &f, &a, self.buffers, &[dims], types)?;
            }
        }
        if let Some(a) = p.indices() {
            let f = format!("{field}.indices");
            check_accessor(
                &self.path,
                &f,
                &a,
                self.buffers,
                &[D::Scalar],
                &[T::U8, T::U16, T::U32],
            )?;
        }
        let reader = p.reader(|b| self.buffers.get(b.index()).map(|d| &d.0[..]));
        let positions: Vec<[f32; 3]> = reader
            .read_positions()
            .ok_or_else(|| {
                SceneError::invalid(&self.path, format!("{field}.attributes.POSITION"), "missing")
            })?
            .collect();
        self.check_finite(&positions, || format!("{field}.attributes.POSITION"))?;
        self.check_in_range(&positions, || format!("{field}.attributes.POSITION"))?;
        let n = positions.len();
        let normals: Option<Vec<[f32; 3]>> = reader.read_normals().map(|r| r.collect());
        if let Some(ns) = &normals {
            self.check_vertex_attribute(ns, n, || format!("{field}.attributes.NORMAL"))?;
        }
        let uvs: Option<Vec<[f32; 2]>> = reader.read_tex_coords(0).map(|r| r.into_f32().collect());
        let uvs1: Option<Vec<[f32; 2]>> = reader.read_tex_coords(1).map(|r| r.into_f32().collect());
        for (set, values) in [(0, &uvs), (1, &uvs1)] {
            let Some(us) = values else { continue };
            self.check_vertex_attribute(us, n, || format!("{field}.attributes.TEXCOORD_{set}"))?;
        }
        let tangents: Option<Vec<[f32; 4]>> = reader.read_tangents().map(|r| r.collect());
        if let Some(ts) = &tangents {
            self.check_vertex_attribute(ts, n, || format!("{field}.attributes.TANGENT"))?;
        }
        let raw: Vec<u32> = match reader.read_indices() {
            Some(r) => r.into_u32().collect(),
            None => (0..n as u32).collect(),
        };
        if let Some(i) = raw.iter().position(|&i| i as usize >= n) {
            return Err(SceneError::invalid(
                &self.path,
                format!("{field}.indices"),
                format!("index {} at element {i} is out of range for {n} vertices", raw[i]),
            ));
        }
        let indices = triangle_list(p.mode(), &raw).ok_or_else(|| {
            SceneError::unsupported(
                &self.path,
                format!("{field}.mode"),
                format!("{:?} primitives (only triangles)", p.mode()),
            )
        })?;

        let positions: Vec<Vec3> = positions.into_iter().map(Vec3::from).collect();
        let uvs: Vec<Vec2> = match uvs {
            Some(u) => u.into_iter().map(Vec2::from).collect(),
            None => vec![Vec2::ZERO; n],
        };
        let uvs1: Vec<Vec2> =
            uvs1.map_or_else(Vec::new, |u| u.into_iter().map(Vec2::from).collect());
        match normals {
            Some(ns) => {
                let smooth = smooth_normals(&positions, &indices);
                let normals = ns
                    .into_iter()
                    .zip(smooth)
                    .map(|(v, s)| Vec3::from(v).try_normalize().unwrap_or(s))
                    .collect();
                Ok(Primitive {
                    positions,
                    normals,
                    uvs,
                    uvs1,
                    // The glTF rule: tangents are read only beside normals.
                    tangents: tangents
                        .map_or_else(Vec::new, |t| t.into_iter().map(Vec4::from).collect()),
                    indices,
                    material,
                })
            }
            None => Ok(flat_shaded(&positions, &uvs, &uvs1, &indices, material)),
        }
    }

    fn read_light(
        &self,
        light: &gltf::khr_lights_punctual::Light,
        node_name: &str,
        node: usize,
    ) -> Result<LightRig, SceneError> {
        use gltf::khr_lights_punctual::Kind;
        let field = format!("extensions.KHR_lights_punctual.lights[{}]", light.index());
        let kind = match light.kind() {
            Kind::Point => LightKind::Point,
            Kind::Directional => LightKind::Directional,
            Kind::Spot { inner_cone_angle, outer_cone_angle } => {
                LightKind::Spot { inner_cone: inner_cone_angle, outer_cone: outer_cone_angle }
            }
        };
        let c = light.color();
        let radiance =
            [c[0] * light.intensity(), c[1] * light.intensity(), c[2] * light.intensity()];
        let mut radius = 0.0;
        if let Some(raw) = light.extras() {
            let value: serde_json::Value = serde_json::from_str(raw.get()).map_err(|e| {
                SceneError::invalid(&self.path, format!("{field}.extras"), e.to_string())
            })?;
            if let Some(r) = value.get("radius") {
                radius = r.as_f64().filter(|r| r.is_finite() && *r >= 0.0).ok_or_else(|| {
                    SceneError::invalid(
                        &self.path,
                        format!("{field}.extras.radius"),
                        format!("expected a number ≥ 0, found {r}"),
                    )
                })? as f32;
            }
        }
        let name = light.name().unwrap_or(node_name).to_owned();
        Ok(LightRig { name, node, kind, radiance, radius, visible_camera: true })
    }

    /// Reads an animation; the inner `Err` holds (field, reason) when it uses something PIS
    /// cannot sample (morph-target weights), which matters only if a dimension uses it.
    fn read_animation(
        &self,
        a: &gltf::Animation,
        name: &str,
        rig_index: &BTreeMap<usize, usize>,
    ) -> Result<Result<Animation, Unsupported>, SceneError> {
        let mut channels = Vec::new();
        for (ci, c) in a.channels().enumerate() {
            let field = format!("animations[{}].channels[{ci}]", a.index());
            let Some(&node) = rig_index.get(&c.target().node().index()) else {
                continue;
            };
            let sfield = format!("animations[{}].samplers[{}]", a.index(), c.sampler().index());
            {
                use gltf::accessor::{DataType as T, Dimensions as D};
                use gltf::animation::Property;
                let input = c.sampler().input();
                check_accessor(
                    &self.path,
                    &format!("{sfield}.input"),
                    &input,
                    self.buffers,
                    &[D::Scalar],
                    &[T::F32],
                )?;
                let output = c.sampler().output();
                let of = format!("{sfield}.output");
                match c.target().property() {
                    Property::Translation | Property::Scale => check_accessor(
                        &self.path,
                        &of,
                        &output,
                        self.buffers,
                        &[D::Vec3],
                        &[T::F32],
                    )?,
                    Property::Rotation => check_accessor(
                        &self.path,
                        &of,
                        &output,
                        self.buffers,
                        &[D::Vec4],
                        &[T::F32, T::I8, T::U8, T::I16, T::U16],
                    )?,
                    Property::MorphTargetWeights => {}
                }
            }
            let reader = c.reader(|b| self.buffers.get(b.index()).map(|d| &d.0[..]));
            let times: Vec<f32> = reader
                .read_inputs()
                .ok_or_else(|| {
                    SceneError::invalid(
                        &self.path,
                        format!("{sfield}.input"),
                        "cannot read keyframe times",
                    )
                })?
                .collect();
            if let Some(i) = times.iter().position(|t| !t.is_finite()) {
                return Err(self.non_finite(format!("{sfield}.input"), i));
            }
            if let Some(i) = times.windows(2).position(|w| w[1] <= w[0]) {
                return Err(SceneError::invalid(
                    &self.path,
                    format!("{sfield}.input"),
                    format!("times not strictly increasing at element {}", i + 1),
                ));
            }
            let outputs = reader.read_outputs().ok_or_else(|| {
                SceneError::invalid(
                    &self.path,
                    format!("{sfield}.output"),
                    "cannot read keyframe values",
                )
            })?;
            let (path, values): (TargetPath, Vec<Vec4>) = match outputs {
                ReadOutputs::Translations(t) => {
                    (TargetPath::Translation, t.map(|v| Vec3::from(v).extend(0.0)).collect())
                }
                ReadOutputs::Scales(s) => {
                    (TargetPath::Scale, s.map(|v| Vec3::from(v).extend(0.0)).collect())
                }
                ReadOutputs::Rotations(r) => {
                    (TargetPath::Rotation, r.into_f32().map(Vec4::from).collect())
                }
                ReadOutputs::MorphTargetWeights(_) => {
                    return Ok(Err((
                        format!("{field}.target.path"),
                        "morph target weights cannot be animated".into(),
                    )))
                }
            };
            if let Some(i) = values.iter().position(|v| !v.is_finite()) {
                return Err(self.non_finite(format!("{sfield}.output"), i));
            }
            let interpolation = match c.sampler().interpolation() {
                gltf::animation::Interpolation::Step => Interpolation::Step,
                gltf::animation::Interpolation::Linear => Interpolation::Linear,
                gltf::animation::Interpolation::CubicSpline => Interpolation::CubicSpline,
            };
            let per_key = if interpolation == Interpolation::CubicSpline { 3 } else { 1 };
            if values.len() != per_key * times.len() {
                return Err(SceneError::invalid(
                    &self.path,
                    format!("{sfield}.output"),
                    format!(
                        "{} values for {} keyframes ({:?} needs {per_key} per keyframe)",
                        values.len(),
                        times.len(),
                        interpolation
                    ),
                ));
            }
            channels.push(Channel {
                node,
                path,
                sampler: Sampler { interpolation, times, values },
            });
        }
        Ok(Ok(Animation { name: name.to_owned(), channels }))
    }
}

/// Converts indices of any triangle mode to a triangle list; `None` for points and lines.
fn triangle_list(mode: Mode, idx: &[u32]) -> Option<Vec<u32>> {
    match mode {
        Mode::Triangles => Some(idx[..idx.len() / 3 * 3].to_vec()),
        Mode::TriangleStrip => Some(
            (2..idx.len())
                .flat_map(|i| {
                    if i % 2 == 0 {
                        [idx[i - 2], idx[i - 1], idx[i]]
                    } else {
                        [idx[i - 1], idx[i - 2], idx[i]]
                    }
                })
                .collect(),
        ),
        Mode::TriangleFan => {
            Some((2..idx.len()).flat_map(|i| [idx[0], idx[i - 1], idx[i]]).collect())
        }
        _ => None,
    }
}

/// Area-weighted vertex normals (fallback for degenerate stored normals).
fn smooth_normals(positions: &[Vec3], indices: &[u32]) -> Vec<Vec3> {
    let mut acc = vec![Vec3::ZERO; positions.len()];
    for t in indices.chunks_exact(3) {
        let [a, b, c] = [t[0] as usize, t[1] as usize, t[2] as usize];
        let n = (positions[b] - positions[a]).cross(positions[c] - positions[a]);
        for v in [a, b, c] {
            acc[v] += n;
        }
    }
    acc.into_iter().map(|n| n.normalize_or(Vec3::Y)).collect()
}

/// Unshares vertices so each triangle gets its face normal (the glTF rule for missing
/// normals, which also has tangents ignored).
fn flat_shaded(
    positions: &[Vec3],
    uvs: &[Vec2],
    uvs1: &[Vec2],
    indices: &[u32],
    material: usize,
) -> Primitive {
    let mut out = Primitive { material, ..Primitive::default() };
    for t in indices.chunks_exact(3) {
        let [a, b, c] = [t[0] as usize, t[1] as usize, t[2] as usize];
        let n =
            (positions[b] - positions[a]).cross(positions[c] - positions[a]).normalize_or(Vec3::Y);
        for v in [a, b, c] {
            out.indices.push(out.positions.len() as u32);
            out.positions.push(positions[v]);
            out.normals.push(n);
            out.uvs.push(uvs[v]);
            if let Some(&u) = uvs1.get(v) {
                out.uvs1.push(u);
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strips_and_fans_become_lists() {
        assert_eq!(triangle_list(Mode::TriangleStrip, &[0, 1, 2, 3]), Some(vec![0, 1, 2, 2, 1, 3]));
        assert_eq!(triangle_list(Mode::TriangleFan, &[0, 1, 2, 3]), Some(vec![0, 1, 2, 0, 2, 3]));
        assert_eq!(triangle_list(Mode::Lines, &[0, 1]), None);
    }

    #[test]
    fn flat_shading_unshares_vertices() {
        let p = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z];
        let prim = flat_shaded(&p, &[Vec2::ZERO; 4], &[], &[0, 1, 2, 0, 3, 1], 0);
        assert_eq!(prim.positions.len(), 6);
        assert_eq!(prim.normals[0], Vec3::Z);
        assert_eq!(prim.normals[3], Vec3::Y);
    }
}
