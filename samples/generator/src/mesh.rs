//! Procedural triangle meshes with normals and UVs: lathes (surfaces of revolution),
//! boxes and subdivided quads.

use glam::{Vec2, Vec3};

/// An indexed triangle mesh; triangles wind counter-clockwise seen from the normal side.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    pub positions: Vec<Vec3>,
    pub normals: Vec<Vec3>,
    pub uvs: Vec<Vec2>,
    pub indices: Vec<u32>,
}

impl Mesh {
    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }

    /// Appends `other` (indices shifted).
    pub fn append(&mut self, other: &Mesh) {
        let base = self.positions.len() as u32;
        self.positions.extend_from_slice(&other.positions);
        self.normals.extend_from_slice(&other.normals);
        self.uvs.extend_from_slice(&other.uvs);
        self.indices.extend(other.indices.iter().map(|i| i + base));
    }

    /// Adds a grid of `(cols + 1) × (rows + 1)` vertices from `vertex(i, j)` and two triangles
    /// per cell. Triangles that are degenerate (zero area) are dropped; the others are wound
    /// so that their face normal agrees with the vertex normals.
    pub fn add_grid(
        &mut self,
        cols: usize,
        rows: usize,
        mut vertex: impl FnMut(usize, usize) -> (Vec3, Vec3, Vec2),
    ) {
        let base = self.positions.len() as u32;
        for j in 0..=rows {
            for i in 0..=cols {
                let (p, n, uv) = vertex(i, j);
                self.positions.push(p);
                self.normals.push(n.normalize_or(Vec3::Y));
                self.uvs.push(uv);
            }
        }
        let at = |i: usize, j: usize| base + (j * (cols + 1) + i) as u32;
        for j in 0..rows {
            for i in 0..cols {
                let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
                self.add_triangle(a, b, c);
                self.add_triangle(a, c, d);
            }
        }
    }

    /// Adds one triangle, wound to agree with its vertex normals; drops it if degenerate.
    pub fn add_triangle(&mut self, a: u32, b: u32, c: u32) {
        let p = |k: u32| self.positions[k as usize];
        let face = (p(b) - p(a)).cross(p(c) - p(a));
        if face.length_squared() < 1e-14 {
            return;
        }
        let n = self.normals[a as usize] + self.normals[b as usize] + self.normals[c as usize];
        if face.dot(n) >= 0.0 {
            self.indices.extend([a, b, c]);
        } else {
            self.indices.extend([a, c, b]);
        }
    }

    /// Applies a scale and then a translation to positions (normals unchanged for uniform
    /// positive scale).
    pub fn scaled_translated(mut self, scale: f32, offset: Vec3) -> Mesh {
        for p in &mut self.positions {
            *p = *p * scale + offset;
        }
        self
    }
}

/// A surface of revolution about +Y. `strips` are profile polylines in the (radius, height)
/// plane, each smooth; separate strips meet at sharp edges. The side of the profile to the
/// right of its direction of travel is the outside (so an outer wall goes up, an inner wall
/// down). UVs: u = turn fraction around the axis, v = arc length along all strips, 0..1.
pub fn lathe(strips: &[Vec<Vec2>], segments: usize) -> Mesh {
    let total: f32 = strips.iter().map(|s| polyline_length(s)).sum::<f32>().max(1e-9);
    let mut mesh = Mesh::default();
    let mut walked = 0.0;
    for strip in strips {
        let mut lengths = vec![0.0f32];
        for w in strip.windows(2) {
            lengths.push(lengths[lengths.len() - 1] + w[0].distance(w[1]));
        }
        let tangents: Vec<Vec2> = (0..strip.len())
            .map(|k| {
                let a = strip[k.saturating_sub(1)];
                let b = strip[(k + 1).min(strip.len() - 1)];
                (b - a).normalize_or(Vec2::Y)
            })
            .collect();
        mesh.add_grid(segments, strip.len() - 1, |i, j| {
            let theta = std::f32::consts::TAU * i as f32 / segments as f32;
            let (s, c) = theta.sin_cos();
            let q = strip[j];
            let t = tangents[j];
            let n2 = Vec2::new(t.y, -t.x); // right of travel
            let p = Vec3::new(q.x * c, q.y, -q.x * s);
            let n = Vec3::new(n2.x * c, n2.y, -n2.x * s);
            (p, n, Vec2::new(i as f32 / segments as f32, (walked + lengths[j]) / total))
        });
        walked += lengths[lengths.len() - 1];
    }
    mesh
}

fn polyline_length(p: &[Vec2]) -> f32 {
    p.windows(2).map(|w| w[0].distance(w[1])).sum()
}

/// A subdivided planar quad from `origin` spanning `du` and `dv`, facing `du × dv`, with
/// UVs 0..1 over the quad (scaled by `uv_scale`).
pub fn quad(origin: Vec3, du: Vec3, dv: Vec3, cols: usize, rows: usize, uv_scale: Vec2) -> Mesh {
    let n = du.cross(dv).normalize();
    let mut mesh = Mesh::default();
    mesh.add_grid(cols, rows, |i, j| {
        let (s, t) = (i as f32 / cols as f32, j as f32 / rows as f32);
        (origin + du * s + dv * t, n, Vec2::new(s, 1.0 - t) * uv_scale)
    });
    mesh
}

/// An axis-aligned box from `min` to `max`, faces pointing out (or in, for a room seen from
/// inside), each face with its own planar UVs 0..1 and `div × div` cells.
pub fn cuboid(min: Vec3, max: Vec3, div: usize, inward: bool) -> Mesh {
    let s = max - min;
    let (x, y, z) = (Vec3::X * s.x, Vec3::Y * s.y, Vec3::Z * s.z);
    // (origin, du, dv) with du × dv pointing out of the box.
    let faces = [
        (min + x + z, -z, y), // +X
        (min, z, y),          // -X
        (min + y + z, x, -z), // +Y
        (min, x, z),          // -Y
        (min + z, x, y),      // +Z
        (min + x, -x, y),     // -Z
    ];
    let mut mesh = Mesh::default();
    for (o, du, dv) in faces {
        let (o, du) = if inward { (o + du, -du) } else { (o, du) };
        mesh.append(&quad(o, du, dv, div, div, Vec2::ONE));
    }
    mesh
}

#[cfg(test)]
mod tests {
    use super::*;

    fn outward_flux(m: &Mesh, centre: Vec3) -> f32 {
        m.indices
            .chunks_exact(3)
            .map(|t| {
                let [a, b, c] = [t[0], t[1], t[2]].map(|k| m.positions[k as usize]);
                (b - a).cross(c - a).dot((a + b + c) / 3.0 - centre)
            })
            .sum()
    }

    #[test]
    fn cuboid_faces_point_out_or_in() {
        let out = cuboid(Vec3::ZERO, Vec3::ONE, 2, false);
        assert_eq!(out.triangle_count(), 6 * 8);
        assert!(outward_flux(&out, Vec3::splat(0.5)) > 0.0);
        // Every face's normal agrees with its winding and points away from the centre.
        for (p, n) in out.positions.iter().zip(&out.normals) {
            assert!(n.dot(*p - Vec3::splat(0.5)) > 0.0);
        }
        let inward = cuboid(Vec3::ZERO, Vec3::ONE, 1, true);
        assert!(outward_flux(&inward, Vec3::splat(0.5)) < 0.0);
    }

    #[test]
    fn lathe_of_a_closed_profile_is_outward() {
        // A cylinder: bottom (axis → rim), side (up), top (rim → axis).
        let strips = vec![
            vec![Vec2::new(0.0, 0.0), Vec2::new(1.0, 0.0)],
            vec![Vec2::new(1.0, 0.0), Vec2::new(1.0, 1.0)],
            vec![Vec2::new(1.0, 1.0), Vec2::new(0.0, 1.0)],
        ];
        let m = lathe(&strips, 16);
        assert!(outward_flux(&m, Vec3::new(0.0, 0.5, 0.0)) > 0.0);
        // Side normals are horizontal and outward.
        for (p, n) in m.positions.iter().zip(&m.normals) {
            if p.y > 0.1 && p.y < 0.9 {
                assert!(n.dot(Vec3::new(p.x, 0.0, p.z)) > 0.0);
            }
        }
        assert!(m.uvs.iter().all(|uv| (0.0..=1.0).contains(&uv.x) && (0.0..=1.0).contains(&uv.y)));
    }
}
