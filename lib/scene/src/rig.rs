//! The scene's moving parts: the node hierarchy, where objects, the camera and lights hang,
//! and the animations that move them. [`crate::Scene::frame`] poses the rig at a point.

use glam::{Mat4, Vec3};

use crate::animation::{Animation, Trs};
use crate::light::LightKind;

/// Node hierarchy, camera, lights and animations of a scene.
///
/// A hand-built [`crate::Scene`] may leave this at its default: every object then sits at
/// the origin (identity transform), the camera at the origin looking down -Z, no lights.
#[derive(Clone, Debug, Default)]
pub struct Rig {
    /// Nodes in depth-first order from the scene roots: a parent always precedes its children.
    pub nodes: Vec<Node>,
    /// For each [`crate::Scene::objects`] entry, the index of its node in `nodes`.
    pub object_nodes: Vec<usize>,
    pub camera: CameraRig,
    pub lights: Vec<LightRig>,
    pub animations: Vec<Animation>,
}

/// A glTF node: its rest (unanimated) local transform and its parent.
#[derive(Clone, Debug, PartialEq)]
pub struct Node {
    pub name: String,
    /// Index of the node in the glTF `nodes` array (`usize::MAX` for the node of a light
    /// written in scene.toml).
    pub gltf_index: usize,
    /// Index into [`Rig::nodes`]; always smaller than this node's own index.
    pub parent: Option<usize>,
    pub local: Trs,
}

/// The camera when no orbit dimension moves it.
#[derive(Clone, Debug, PartialEq)]
pub struct CameraRig {
    pub placement: CameraPlacement,
    /// Vertical field of view in radians.
    pub yfov: f32,
    pub znear: f32,
    pub zfar: f32,
}

impl Default for CameraRig {
    fn default() -> Self {
        CameraRig {
            placement: CameraPlacement::Fixed(Mat4::IDENTITY),
            yfov: 45f32.to_radians(),
            znear: 0.01,
            zfar: f32::INFINITY,
        }
    }
}

/// Where the camera is.
#[derive(Clone, Debug, PartialEq)]
pub enum CameraPlacement {
    /// Attached to a node (index into [`Rig::nodes`]), so animations move it.
    Node(usize),
    /// A fixed camera-to-world transform.
    Fixed(Mat4),
}

/// A KHR_lights_punctual light attached to a node.
#[derive(Clone, Debug, PartialEq)]
pub struct LightRig {
    /// The light's name, or its node's name when the light has none.
    pub name: String,
    /// Index into [`Rig::nodes`].
    pub node: usize,
    pub kind: LightKind,
    /// Colour times intensity.
    pub radiance: [f32; 3],
    /// Sphere radius from the light's extras, 0 for a point light.
    pub radius: f32,
    /// Whether camera rays see the sphere ([`crate::model::Light::visible_camera`]).
    pub visible_camera: bool,
}

impl Rig {
    /// World transforms of all nodes for the given local transforms (one per node).
    pub fn world_transforms(&self, locals: &[Trs]) -> Vec<Mat4> {
        let mut world: Vec<Mat4> = Vec::with_capacity(self.nodes.len());
        for (i, node) in self.nodes.iter().enumerate() {
            let local = locals.get(i).copied().unwrap_or(node.local).matrix();
            let m = match node.parent.and_then(|p| world.get(p)) {
                Some(parent) => *parent * local,
                None => local,
            };
            world.push(m);
        }
        world
    }

    /// The rest pose: every node's unanimated local transform.
    pub fn rest_pose(&self) -> Vec<Trs> {
        self.nodes.iter().map(|n| n.local).collect()
    }

    /// Index of the node named `name`, if any.
    pub fn node_named(&self, name: &str) -> Option<usize> {
        self.nodes.iter().position(|n| n.name == name)
    }
}

/// A rigid transform with the rotation and translation of `m` (scale and shear removed).
pub fn rigid_part(m: Mat4) -> Mat4 {
    let (_, rotation, translation) = m.to_scale_rotation_translation();
    Mat4::from_rotation_translation(rotation.normalize(), translation)
}

/// Position and pointing direction (local -Z) of a light node's world transform.
pub fn light_pose(m: Mat4) -> (Vec3, Vec3) {
    (m.transform_point3(Vec3::ZERO), m.transform_vector3(Vec3::NEG_Z).normalize_or(Vec3::NEG_Z))
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Quat;

    #[test]
    fn world_transforms_compose_parent_first() {
        let rig = Rig {
            nodes: vec![
                Node {
                    name: "a".into(),
                    gltf_index: 0,
                    parent: None,
                    local: Trs { translation: Vec3::X, ..Trs::default() },
                },
                Node {
                    name: "b".into(),
                    gltf_index: 1,
                    parent: Some(0),
                    local: Trs {
                        translation: Vec3::Y,
                        rotation: Quat::from_rotation_z(1.0),
                        scale: Vec3::ONE,
                    },
                },
            ],
            ..Rig::default()
        };
        let w = rig.world_transforms(&rig.rest_pose());
        assert!(w[1].transform_point3(Vec3::ZERO).distance(Vec3::new(1.0, 1.0, 0.0)) < 1e-6);
    }

    #[test]
    fn rigid_part_removes_scale() {
        let m = Mat4::from_scale_rotation_translation(
            Vec3::splat(3.0),
            Quat::from_rotation_y(0.5),
            Vec3::Z,
        );
        let r = rigid_part(m);
        assert!((r.determinant() - 1.0).abs() < 1e-5);
        assert!(r.transform_point3(Vec3::ZERO).distance(Vec3::Z) < 1e-6);
    }
}
