//! Tessellation of the Newell teapot's bicubic Bézier patches into a triangle mesh.

use glam::{Vec2, Vec3};

use crate::mesh::Mesh;
use crate::teapot_data::{TEAPOT_PATCHES, TEAPOT_POINTS};

/// Patch index ranges of the teapot's parts.
pub const RIM: std::ops::Range<usize> = 0..4;
pub const BODY: std::ops::Range<usize> = 4..12;
pub const HANDLE: std::ops::Range<usize> = 12..16;
pub const SPOUT: std::ops::Range<usize> = 16..20;
pub const LID: std::ops::Range<usize> = 20..28;
pub const BOTTOM: std::ops::Range<usize> = 28..32;

/// Cubic Bernstein weights and their derivatives at `t`.
fn bernstein(t: f32) -> ([f32; 4], [f32; 4]) {
    let s = 1.0 - t;
    (
        [s * s * s, 3.0 * t * s * s, 3.0 * t * t * s, t * t * t],
        [-3.0 * s * s, 3.0 * s * s - 6.0 * t * s, 6.0 * t * s - 3.0 * t * t, 3.0 * t * t],
    )
}

/// A control point, converted from the data's z-up to y-up (x, z, -y).
fn control(patch: usize, k: usize) -> Vec3 {
    let [x, y, z] = TEAPOT_POINTS[TEAPOT_PATCHES[patch][k] as usize];
    Vec3::new(x, z, -y)
}

/// Position and partial derivatives of a patch at (u, v).
fn eval(patch: usize, u: f32, v: f32) -> (Vec3, Vec3, Vec3) {
    let (bu, du) = bernstein(u);
    let (bv, dv) = bernstein(v);
    let (mut p, mut pu, mut pv) = (Vec3::ZERO, Vec3::ZERO, Vec3::ZERO);
    for i in 0..4 {
        for j in 0..4 {
            let c = control(patch, i * 4 + j);
            p += c * bu[i] * bv[j];
            pu += c * du[i] * bv[j];
            pv += c * bu[i] * dv[j];
        }
    }
    (p, pu, pv)
}

/// Surface normal of a patch at (u, v), `sign` choosing the side; where the patch is
/// degenerate (the lid's apex, the bottom's centre, where control points coincide) the normal
/// is taken a little way inside the patch.
fn normal(patch: usize, u: f32, v: f32, sign: f32) -> Vec3 {
    let mut n = Vec3::ZERO;
    for eps in [0.0f32, 1e-3, 1e-2, 5e-2] {
        let (_, pu, pv) = eval(patch, u.clamp(eps, 1.0 - eps), v.clamp(eps, 1.0 - eps));
        n = pu.cross(pv);
        if n.length_squared() > 1e-12 {
            break;
        }
    }
    (n * sign).normalize_or(Vec3::Y)
}

/// Which side of patch `patch` is outside: the sign of (∂u × ∂v) that points away from the
/// part's interior, judged by the flux through the patch relative to `inside`.
fn orientation(patch: usize, inside: Vec3) -> f32 {
    let mut flux = 0.0;
    for a in 1..8 {
        for b in 1..8 {
            let (p, pu, pv) = eval(patch, a as f32 / 8.0, b as f32 / 8.0);
            flux += pu.cross(pv).dot(p - inside);
        }
    }
    if flux >= 0.0 {
        1.0
    } else {
        -1.0
    }
}

/// A point inside the part that patch `patch` belongs to (y-up, data units).
fn inside_point(patch: usize) -> Vec3 {
    if LID.contains(&patch) {
        if patch < 24 {
            Vec3::new(0.0, 2.9, 0.0) // the knob
        } else {
            Vec3::new(0.0, 2.2, 0.0)
        }
    } else if HANDLE.contains(&patch) || SPOUT.contains(&patch) {
        Vec3::NAN // judged per sample, see `tube_orientation`
    } else {
        Vec3::new(0.0, 1.4, 0.0)
    }
}

/// Orientation for the handle and spout, which are tubes: compare the normal with the
/// direction from the tube's centre line (the mean of the patch row across the tube, which
/// for these patches is the v = const curve through the patch and its mirror image).
fn tube_orientation(patch: usize) -> f32 {
    let mut votes = 0.0;
    for a in 1..8 {
        for b in 1..8 {
            let (u, v) = (a as f32 / 8.0, b as f32 / 8.0);
            let (p, pu, pv) = eval(patch, u, v);
            // The tube is symmetric about the z = 0 plane (y-up: the data's y = 0 plane):
            // the centre line lies in that plane; project p onto it and use the two edge
            // curves (v = 0 and v = 1) which both lie in the plane, at the same u.
            let (e0, _, _) = eval(patch, u, 0.0);
            let (e1, _, _) = eval(patch, u, 1.0);
            let centre = (e0 + e1) * 0.5;
            votes += pu.cross(pv).dot(p - centre).signum();
        }
    }
    if votes >= 0.0 {
        1.0
    } else {
        -1.0
    }
}

/// Tessellates the given patches on a `grid × grid` parameter grid each, scaled by `scale`
/// and moved by `offset` (the data's base is at y = 0). UVs tile the patches into an atlas of
/// 8 × 4 cells, one per patch, so every surface point has its own texel.
pub fn teapot(
    patches: impl IntoIterator<Item = usize>,
    grid: usize,
    scale: f32,
    offset: Vec3,
) -> Mesh {
    let mut mesh = Mesh::default();
    for patch in patches {
        let sign = if HANDLE.contains(&patch) || SPOUT.contains(&patch) {
            tube_orientation(patch)
        } else {
            orientation(patch, inside_point(patch))
        };
        let cell = Vec2::new((patch % 8) as f32, (patch / 8) as f32);
        mesh.add_grid(grid, grid, |i, j| {
            let (u, v) = (i as f32 / grid as f32, j as f32 / grid as f32);
            let (p, _, _) = eval(patch, u, v);
            let n = normal(patch, u, v, sign);
            let uv = (cell + Vec2::new(0.02 + 0.96 * u, 0.02 + 0.96 * v)) / Vec2::new(8.0, 4.0);
            (p * scale + offset, n, uv)
        });
    }
    mesh
}

/// The flat ring that closes the gap between the lid's edge (radius 1.3) and the rim's
/// inner edge (radius 1.4) at height 2.4, facing up; the patch data leaves it open.
pub fn lid_seal(segments: usize, scale: f32, offset: Vec3) -> Mesh {
    crate::mesh::lathe(&[vec![Vec2::new(1.4, 2.4), Vec2::new(1.3, 2.4)]], segments)
        .scaled_translated(scale, offset)
}

/// All 32 patches plus the [`lid_seal`]: a closed-looking solid for glass.
pub fn whole_teapot(grid: usize, scale: f32, offset: Vec3) -> Mesh {
    let mut m = teapot(0..32, grid, scale, offset);
    m.append(&lid_seal(4 * grid, scale, offset));
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn patches_join_and_span_the_known_extent() {
        let m = whole_teapot(4, 1.0, Vec3::ZERO);
        assert!(m.triangle_count() > 32 * 4 * 4);
        let max = m.positions.iter().fold(Vec3::splat(-9.0), |a, p| a.max(*p));
        let min = m.positions.iter().fold(Vec3::splat(9.0), |a, p| a.min(*p));
        // Spout tip at x ≈ 3.4–3.5, handle at x = -3, lid knob at y = 3.15, base at y = 0.
        assert!(max.y > 3.1 && max.y < 3.2 && min.y.abs() < 1e-6, "{min} {max}");
        assert!(min.x < -2.9 && max.x > 3.3, "{min} {max}");
    }

    #[test]
    fn body_normals_point_away_from_the_axis() {
        let m = teapot(BODY, 4, 1.0, Vec3::ZERO);
        for (p, n) in m.positions.iter().zip(&m.normals) {
            assert!(n.dot(Vec3::new(p.x, 0.0, p.z)) > 0.0, "{p} {n}");
        }
        let b = teapot(BOTTOM, 4, 1.0, Vec3::ZERO);
        for (p, n) in b.positions.iter().zip(&b.normals) {
            if Vec2::new(p.x, p.z).length() < 1.3 {
                assert!(n.y < -0.9, "{p} {n}");
            }
        }
    }

    #[test]
    fn spout_and_handle_normals_point_out_of_the_tube() {
        for part in [HANDLE, SPOUT] {
            let m = teapot(part.clone(), 6, 1.0, Vec3::ZERO);
            // Points with the largest |z| (the tube's sides) have normals pointing further out.
            for (p, n) in m.positions.iter().zip(&m.normals) {
                if p.z.abs() > 0.2 {
                    assert!(n.z * p.z > 0.0, "{part:?} {p} {n}");
                }
            }
        }
    }
}
