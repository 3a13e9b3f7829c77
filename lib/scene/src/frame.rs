//! Evaluating a scene at one point of its parameter space.

use glam::Mat4;

use crate::light_path::point_on_path;
use crate::model::{Camera, Driver, Frame, Instance, Light, LightKind, Scene};
use crate::orbit::orbit_camera;
use crate::rig::{light_pose, rigid_part, CameraPlacement};
use crate::SceneError;

/// Where a dimension moves a light: to a place, or turned to shine from direction `w`
/// (a placed light standing at `at`).
enum Moved {
    To(glam::Vec3),
    Turned { w: glam::Vec3, at: glam::Vec3 },
}

impl Scene {
    /// The camera, lights and object placements at the parameter point `point` (one sample
    /// index per dimension, in [`crate::ParameterSpace::dims`] order).
    ///
    /// Dimensions apply in order: animations pose the nodes (a later animation overrides an
    /// earlier one on the same node), an orbit dimension then places the camera, and a light
    /// path or a light direction moves its light.
    pub fn frame(&self, point: &[u32]) -> Result<Frame, SceneError> {
        let dims = &self.space.dims;
        if point.len() != dims.len() || point.iter().zip(dims).any(|(&i, d)| i >= d.samples()) {
            return Err(SceneError::PointOutOfRange {
                scene: self.name.clone(),
                point: point.to_vec(),
                counts: dims.iter().map(|d| d.samples()).collect(),
            });
        }
        let rig = &self.rig;
        let mut locals = rig.rest_pose();
        let mut orbit = None;
        let mut moved_lights = Vec::new();
        for (d, &i) in dims.iter().zip(point) {
            let value = d.values[i as usize];
            match &d.driver {
                Driver::Animation { animation } => {
                    let Some(a) = rig.animations.iter().find(|a| &a.name == animation) else {
                        return Err(SceneError::unknown(
                            format!("scene {}", self.name),
                            format!("dimension {}", d.name),
                            "animation",
                            animation,
                            rig.animations.iter().map(|a| a.name.as_str()),
                        ));
                    };
                    a.apply(value, &mut locals);
                }
                Driver::Orbit { target, radius, elevation_deg } => {
                    orbit = Some(orbit_camera(*target, *radius, *elevation_deg, value));
                }
                Driver::LightPath { light, path } => {
                    moved_lights.push((light, Moved::To(point_on_path(path, value))))
                }
                Driver::LightDirection { light, directions, center, distance, .. } => {
                    let w = directions[i as usize];
                    moved_lights.push((light, Moved::Turned { w, at: *center + *distance * w }))
                }
                Driver::Still => {}
            }
        }
        let world = rig.world_transforms(&locals);

        let world_from_camera = match (orbit, &rig.camera.placement) {
            (Some(m), _) => m,
            (None, CameraPlacement::Node(n)) => {
                rigid_part(world.get(*n).copied().unwrap_or(Mat4::IDENTITY))
            }
            (None, CameraPlacement::Fixed(m)) => *m,
        };
        let camera = Camera {
            world_from_camera,
            yfov: rig.camera.yfov,
            znear: rig.camera.znear,
            zfar: rig.camera.zfar,
        };

        let lights = rig
            .lights
            .iter()
            .map(|l| {
                let (mut position, mut direction) =
                    light_pose(world.get(l.node).copied().unwrap_or(Mat4::IDENTITY));
                let node_name = rig.nodes.get(l.node).map(|n| n.name.as_str());
                for (name, moved) in &moved_lights {
                    if **name == l.name || Some(name.as_str()) == node_name {
                        match *moved {
                            Moved::To(p) => position = p,
                            Moved::Turned { w, at } if l.kind == LightKind::Directional => {
                                (direction, position) = (-w, at);
                            }
                            Moved::Turned { at, .. } => position = at,
                        }
                    }
                }
                Light {
                    name: l.name.clone(),
                    kind: l.kind,
                    radiance: l.radiance,
                    radius: l.radius,
                    visible_camera: l.visible_camera,
                    position,
                    direction,
                }
            })
            .collect();

        let instances = (0..self.objects.len())
            .map(|k| Instance {
                world_from_object: rig
                    .object_nodes
                    .get(k)
                    .and_then(|&n| world.get(n))
                    .copied()
                    .unwrap_or(Mat4::IDENTITY),
            })
            .collect();
        Ok(Frame { camera, lights, instances })
    }

    /// [`Scene::frame`] at the point with linear index `index` ([`crate::ParameterSpace::point`]).
    pub fn frame_at(&self, index: usize) -> Result<Frame, SceneError> {
        self.frame(&self.space.point(index))
    }
}
