//! A scene's lens object as hybrid rendering traces it (thesis 6.4): its triangles placed in
//! world space at a frame as pis-trace places them, and its material's constants as
//! pis-trace shades them (the greedy paths' IOR, base colour and absorption).

use glam::{Mat3, Vec3};
use pis_compile::hybrid::{LensMaterial, LensObject};
use pis_scene::{Frame, Material, Scene};

/// The constants of `m` the greedy paths use, computed as pis-trace's shading material does
/// (a base-colour texture is not applied: the runtime's paths take the factor alone).
pub fn lens_material(m: &Material) -> LensMaterial {
    let ior = if m.ior.is_finite() && m.ior >= 1.0 { m.ior } else { 1.5 };
    let sigma_a = if m.attenuation_distance.is_finite() && m.attenuation_distance > 0.0 {
        Vec3::from(m.attenuation_color).max(Vec3::splat(1e-6)).min(Vec3::ONE).map(|c| -c.ln())
            / m.attenuation_distance
    } else {
        Vec3::ZERO
    };
    LensMaterial {
        ior,
        base: Vec3::new(m.base_color[0], m.base_color[1], m.base_color[2]),
        sigma_a,
    }
}

/// Object `o` of `scene` at `frame` as a lens object: every primitive's triangles in world
/// space, normals by the normal matrix (not renormalized, as pis-trace blends them), the
/// material of its first primitive; an index past the scene's objects gives an empty lens
/// object.
pub fn lens_object(scene: &Scene, frame: &Frame, o: usize) -> LensObject {
    let m = frame.instances.get(o).map(|i| i.world_from_object).unwrap_or(glam::Mat4::IDENTITY);
    let normal_matrix = Mat3::from_mat4(m).inverse().transpose();
    let (mut positions, mut normals, mut indices) = (Vec::new(), Vec::new(), Vec::new());
    let mut material = None;
    for prim in scene.objects.get(o).map_or(&[][..], |x| &x.primitives[..]) {
        let base = positions.len() as u32;
        positions.extend(prim.positions.iter().map(|&p| m.transform_point3(p)));
        normals.extend(
            (0..prim.positions.len())
                .map(|k| prim.normals.get(k).map_or(Vec3::ZERO, |&n| normal_matrix * n)),
        );
        indices.extend(prim.indices.iter().map(|&i| base + i));
        if material.is_none() {
            material = scene.materials.get(prim.material).map(lens_material);
        }
    }
    let material =
        material.unwrap_or(LensMaterial { ior: 1.5, base: Vec3::ONE, sigma_a: Vec3::ZERO });
    LensObject::new(material, positions, normals, &indices)
}
