//! Tangent frames for normal maps: from the glTF TANGENT attribute where a mesh has one,
//! else one frame per triangle made from its positions and texture coordinates (the
//! derivatives of position along u and v, as MikkTSpace makes them before it averages
//! over the triangles sharing a vertex; PIS does not average, so a curved surface's frame
//! changes from one triangle to the next).
//!
//! glTF's texture v points down the image while a normal map's +Y points up it, so the
//! bitangent runs along −∂P/∂v; with a TANGENT attribute it is w · (normal × tangent).

use glam::{Vec2, Vec3};

/// A triangle's tangent frame (tangent, bitangent) about unit `normal`, from the triangle's
/// positions `p` and the texture coordinates `uv` the normal map reads at its corners; `None`
/// when the coordinates span no area.
pub fn triangle_frame(p: [Vec3; 3], uv: [Vec2; 3], normal: Vec3) -> Option<(Vec3, Vec3)> {
    let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
    let (d1, d2) = (uv[1] - uv[0], uv[2] - uv[0]);
    let det = d1.x * d2.y - d2.x * d1.y;
    if det.abs() <= f32::EPSILON * (d1.length_squared() + d2.length_squared()) || !det.is_finite() {
        return None;
    }
    let dpdu = (e1 * d2.y - e2 * d1.y) / det;
    let dpdv = (e2 * d1.x - e1 * d2.x) / det;
    let (t, b) = attribute_frame(normal, dpdu, 1.0)?;
    Some(if b.dot(-dpdv) < 0.0 { (t, -b) } else { (t, b) })
}

/// The frame of a TANGENT attribute: `tangent` made orthogonal to unit `normal`, and the
/// bitangent `sign` · (normal × tangent); `None` for a tangent along the normal.
pub fn attribute_frame(normal: Vec3, tangent: Vec3, sign: f32) -> Option<(Vec3, Vec3)> {
    let t = (tangent - normal * normal.dot(tangent)).try_normalize()?;
    let b = normal.cross(t);
    Some((t, if sign < 0.0 { -b } else { b }))
}

/// Unit normal `normal` bent by the tangent-space normal `m` in the frame (`tangent`,
/// `bitangent`, `normal`).
pub fn bend(normal: Vec3, tangent: Vec3, bitangent: Vec3, m: Vec3) -> Vec3 {
    (tangent * m.x + bitangent * m.y + normal * m.z).normalize_or(normal)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A quad in the XY plane facing +Z, its texture upright: u along +X, v down along −Y.
    fn upright() -> ([Vec3; 3], [Vec2; 3]) {
        let p = [Vec3::new(-1.0, 1.0, 0.0), Vec3::new(1.0, 1.0, 0.0), Vec3::new(-1.0, -1.0, 0.0)];
        let uv = [Vec2::new(0.0, 0.0), Vec2::new(1.0, 0.0), Vec2::new(0.0, 1.0)];
        (p, uv)
    }

    #[test]
    fn triangle_frame_points_along_u_and_up_the_image() {
        let (p, uv) = upright();
        let (t, b) = triangle_frame(p, uv, Vec3::Z).unwrap();
        assert!((t - Vec3::X).length() < 1e-6 && (b - Vec3::Y).length() < 1e-6, "{t} {b}");
        // The texture mirrored in u: the tangent turns, the bitangent stays up the image.
        let mirrored = uv.map(|c| Vec2::new(1.0 - c.x, c.y));
        let (t, b) = triangle_frame(p, mirrored, Vec3::Z).unwrap();
        assert!((t + Vec3::X).length() < 1e-6 && (b - Vec3::Y).length() < 1e-6, "{t} {b}");
        assert!(triangle_frame(p, [Vec2::ZERO; 3], Vec3::Z).is_none());
    }

    #[test]
    fn normal_map_bends_shading_normal() {
        let (p, uv) = upright();
        let (t, b) = triangle_frame(p, uv, Vec3::Z).unwrap();
        // A texel leaning to +X (right in the image) and one leaning up the image.
        let right = bend(Vec3::Z, t, b, Vec3::new(0.6, 0.0, 0.8));
        assert!((right - Vec3::new(0.6, 0.0, 0.8)).length() < 1e-6, "{right}");
        let up = bend(Vec3::Z, t, b, Vec3::new(0.0, 0.6, 0.8));
        assert!((up - Vec3::new(0.0, 0.6, 0.8)).length() < 1e-6, "{up}");
        assert_eq!(bend(Vec3::Z, t, b, Vec3::Z), Vec3::Z);
        // The attribute's frame agrees, its sign flipping the bitangent.
        assert_eq!(
            attribute_frame(Vec3::Z, Vec3::new(1.0, 0.0, 0.3), 1.0),
            Some((Vec3::X, Vec3::Y))
        );
        assert_eq!(attribute_frame(Vec3::Z, Vec3::X, -1.0), Some((Vec3::X, -Vec3::Y)));
    }
}
