//! An object's mesh as the container stores it (SPEC.md 6.5): positions with the first
//! point's scale baked in where its transform is not rigid ([`baked`]), vertex normals in
//! the same space for the objects whose shading reads them, the texture coordinates of the
//! file and the triangle list.

use glam::{Mat3, Mat4, Vec3};
use pis_format::{Mesh, ObjectRole};

use super::input::LoadedSet;
use super::model::ObjectModel;
use super::transforms::baked;

/// The container mesh of `m`, an object of `role`: normals for reflective and refractive
/// objects (their shells are looked up along the reflected and refracted rays), none for
/// diffuse ones.
pub fn stored_mesh(set: &LoadedSet, m: &ObjectModel, role: ObjectRole) -> Mesh {
    let bake = baked(&set.frames, m.index);
    Mesh {
        positions: stored_positions(bake, &m.mesh.positions),
        normals: (role != ObjectRole::Diffuse).then(|| stored_normals(bake, &m.mesh.normals)),
        texcoords: Some(m.mesh_uvs.clone()),
        indices: m.mesh.indices.clone(),
        hull_triangles: m.hull_triangles,
    }
}

/// Object-space positions moved by the baked linear part `bake`, if any.
fn stored_positions(bake: Option<Mat4>, positions: &[[f32; 3]]) -> Vec<[f32; 3]> {
    match bake {
        Some(b) => {
            positions.iter().map(|&p| b.transform_point3(Vec3::from(p)).to_array()).collect()
        }
        None => positions.to_vec(),
    }
}

/// Object-space unit normals carried by the baked linear part `bake`, if any: through its
/// inverse transpose (normals stay perpendicular to the surface under a scale or shear),
/// renormalized. A normal that collapses keeps its direction before the bake.
pub fn stored_normals(bake: Option<Mat4>, normals: &[[f32; 3]]) -> Vec<[f32; 3]> {
    let inverse_transpose = bake.map(|b| Mat3::from_mat4(b).inverse().transpose());
    normals
        .iter()
        .map(|&n| {
            let n = Vec3::from(n);
            let before = n.normalize_or(Vec3::Y);
            inverse_transpose.map_or(before, |m| (m * n).normalize_or(before)).to_array()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normals_stay_perpendicular_to_a_scaled_and_mirrored_surface() {
        // A plane through the origin spanned by two tangents, and its normal.
        let (t1, t2) = (Vec3::new(1.0, 1.0, 0.0), Vec3::new(0.0, 1.0, 1.0));
        let n = t1.cross(t2).normalize();
        let bake = Mat4::from_scale(Vec3::new(0.8, 1.3, -0.8)) * Mat4::from_rotation_y(0.3);
        let [got] = stored_normals(Some(bake), &[n.to_array()])[..] else { panic!("one normal") };
        let got = Vec3::from(got);
        assert!((got.length() - 1.0).abs() < 1e-6, "{got}");
        for t in [t1, t2] {
            let moved = bake.transform_vector3(t);
            assert!(got.dot(moved).abs() < 1e-5, "{got} · {moved}");
        }
        // On the side the point one normal off the plane moves to: still outward.
        assert!(got.dot(bake.transform_vector3(n)) > 0.0);
    }

    #[test]
    fn without_a_bake_normals_and_positions_are_kept() {
        let n = [[0.0, 0.0, 1.0], [0.6, 0.8, 0.0]];
        assert_eq!(stored_normals(None, &n), n.to_vec());
        let p = [[1.0, 2.0, 3.0]];
        assert_eq!(stored_positions(None, &p), p.to_vec());
        let scaled = stored_positions(Some(Mat4::from_scale(Vec3::splat(2.0))), &p);
        assert_eq!(scaled, vec![[2.0, 4.0, 6.0]]);
    }
}
