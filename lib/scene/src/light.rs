//! Lights as a frame places them in the world; shared by the evaluated scene ([`crate::model`])
//! and the rig that poses them ([`crate::rig`]).

use glam::Vec3;

/// A light from KHR_lights_punctual, placed in the world.
#[derive(Clone, Debug, PartialEq)]
pub struct Light {
    pub name: String,
    pub kind: LightKind,
    /// Linear RGB colour times intensity (W/sr-like units for point/spot, lux for directional).
    pub radiance: [f32; 3],
    /// Sphere radius for area lights and soft shadows (glTF extras `radius`), 0 = point.
    pub radius: f32,
    /// Whether camera rays see a sphere light's surface (`visible_camera`); reflected,
    /// refracted and scattered rays always do.
    pub visible_camera: bool,
    pub position: Vec3,
    /// Direction the light points to (unit), for spot and directional lights.
    pub direction: Vec3,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LightKind {
    Point,
    Spot { inner_cone: f32, outer_cone: f32 },
    Directional,
}
