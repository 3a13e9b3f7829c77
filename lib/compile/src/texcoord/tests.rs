//! Texture-coordinate optimization on small meshes seen by a perspective camera.

use glam::{Mat4, Vec2, Vec3, Vec4};

use super::*;

/// clip ← world for a right-handed camera, depth in [0, 1] (wgpu), 0.8 rad vertical field.
fn camera(eye: Vec3, target: Vec3) -> Mat4 {
    let (fov, aspect, near, far) = (0.8f32, 4.0 / 3.0, 0.1f32, 100.0f32);
    let g = 1.0 / (0.5 * fov).tan();
    let proj = Mat4::from_cols(
        Vec4::new(g / aspect, 0.0, 0.0, 0.0),
        Vec4::new(0.0, g, 0.0, 0.0),
        Vec4::new(0.0, 0.0, far / (near - far), -1.0),
        Vec4::new(0.0, 0.0, near * far / (near - far), 0.0),
    );
    let f = (target - eye).normalize();
    let s = f.cross(Vec3::Y).normalize();
    let u = s.cross(f);
    let view = Mat4::from_cols(
        Vec4::new(s.x, u.x, -f.x, 0.0),
        Vec4::new(s.y, u.y, -f.y, 0.0),
        Vec4::new(s.z, u.z, -f.z, 0.0),
        Vec4::new(-s.dot(eye), -u.dot(eye), f.dot(eye), 1.0),
    );
    proj * view
}

fn view(clip_from_world: Mat4, positions: &[Vec3]) -> ViewGeometry {
    ViewGeometry {
        clip: positions.iter().map(|p| clip_from_world * Vec4::new(p.x, p.y, p.z, 1.0)).collect(),
        width: 160,
        height: 120,
    }
}

/// A unit square in the z = 0 plane as an n × n grid, uv = (x, y).
fn grid(n: u32) -> (Vec<Vec3>, Vec<Vec2>, Vec<u32>) {
    let (mut p, mut uv, mut idx) = (vec![], vec![], vec![]);
    for j in 0..=n {
        for i in 0..=n {
            let (u, v) = (i as f32 / n as f32, j as f32 / n as f32);
            p.push(Vec3::new(u - 0.5, v - 0.5, 0.0));
            uv.push(Vec2::new(u, v));
        }
    }
    for j in 0..n {
        for i in 0..n {
            let a = j * (n + 1) + i;
            idx.extend([a, a + 1, a + n + 2, a, a + n + 2, a + n + 1]);
        }
    }
    (p, uv, idx)
}

/// A cylinder of radius ½ around y, u = angle / 2π (periodic), v = height.
fn cylinder(n: u32) -> (Vec<Vec3>, Vec<Vec2>, Vec<u32>) {
    let (mut p, mut uv, mut idx) = (vec![], vec![], vec![]);
    for i in 0..=n {
        let u = i as f32 / n as f32;
        let a = u * std::f32::consts::TAU;
        for v in [0.0f32, 1.0] {
            p.push(Vec3::new(0.5 * a.cos(), v - 0.5, 0.5 * a.sin()));
            uv.push(Vec2::new(u, v));
        }
    }
    for i in 0..n {
        let a = 2 * i;
        idx.extend([a, a + 1, a + 3, a, a + 3, a + 2]);
    }
    (p, uv, idx)
}

fn check_visible_inside(
    placement: &TexturePlacement,
    uvs: &[Vec2],
    views: &[ViewGeometry],
    idx: &[u32],
) {
    for v in views {
        for e in edges::visible_edges(v, uvs, idx).0 {
            for uv in e.uv {
                let (s, t) = placement.apply(uv.x as f32, uv.y as f32);
                assert!((-1e-3..=1.001).contains(&s) && (-1e-3..=1.001).contains(&t), "({s}, {t})");
            }
        }
    }
}

#[test]
fn a_square_seen_head_on_gets_about_its_screen_resolution() {
    let (p, uv, idx) = grid(4);
    let views = [view(camera(Vec3::new(0.0, 0.0, 2.0), Vec3::ZERO), &p)];
    let mesh = ObjectMesh { name: "square", uvs: &uv, indices: &idx, wrap: [false; 2] };
    let pl = optimize_placement(&mesh, &views, &TexcoordSettings::default()).unwrap();
    // the square covers ≈ 1 / (2·2·tan 0.4) · 120 ≈ 71 pixels
    assert!((60..=100).contains(&pl.width) && (60..=100).contains(&pl.height), "{pl:?}");
    assert!(pl.stretch <= 1.25);
    assert_eq!(pl.repeat, [false, false]);
    check_visible_inside(&pl, &uv, &views, &idx);
    // the reduction factor halves the size
    let half = TexcoordSettings { reduction: 0.5, ..Default::default() };
    let h = optimize_placement(&mesh, &views, &half).unwrap();
    assert!(
        h.width.abs_diff(pl.width.div_ceil(2)) <= 1
            && h.height.abs_diff(pl.height.div_ceil(2)) <= 1
    );
    assert_eq!(h.affine, pl.affine);
}

#[test]
fn a_grazing_half_off_screen_square_uses_a_smaller_stretched_texture() {
    let (p, uv, idx) = grid(8);
    // seen at a grazing angle and shifted so half of it is off screen
    let views = [view(camera(Vec3::new(0.6, -1.6, 0.35), Vec3::new(0.6, 0.0, 0.0)), &p)];
    let mesh = ObjectMesh { name: "square", uvs: &uv, indices: &idx, wrap: [false; 2] };
    let pl = optimize_placement(&mesh, &views, &TexcoordSettings::default()).unwrap();
    assert!(pl.stretch <= 1.25 + 1e-9, "{pl:?}");
    assert!(pl.width >= 1 && pl.height >= 1);
    check_visible_inside(&pl, &uv, &views, &idx);
}

#[test]
fn the_texel_budget_reduces_a_grazing_floor_to_its_covered_pixels() {
    // A large floor seen at a grazing angle: the nearest pixels set the density, the far
    // end is minified, so the optimal texture holds far more texels than the pixels.
    let (p, uv, idx) = grid(16);
    let p: Vec<Vec3> = p.iter().map(|q| *q * 6.0).collect();
    let views = [view(camera(Vec3::new(0.0, -3.5, 0.6), Vec3::new(0.0, 2.0, 0.0)), &p)];
    let mesh = ObjectMesh { name: "floor", uvs: &uv, indices: &idx, wrap: [false; 2] };
    let free = optimize_placement(&mesh, &views, &TexcoordSettings::default()).unwrap();
    let texels = |pl: &TexturePlacement| pl.width as f64 * pl.height as f64;
    assert!(
        free.covered_pixels > 0 && texels(&free) > 4.0 * free.covered_pixels as f64,
        "{free:?}"
    );
    assert_eq!(free.reduction, 1.0);
    for k in [1.0, 2.0] {
        let budget = TexcoordSettings { texels_per_pixel: Some(k), ..Default::default() };
        let pl = optimize_placement(&mesh, &views, &budget).unwrap();
        // within the budget up to the rounding of each side up to whole texels
        let limit = k * pl.covered_pixels as f64;
        assert!(texels(&pl) <= limit + pl.width as f64 + pl.height as f64 + 1.0, "k {k}: {pl:?}");
        assert!(texels(&pl) >= 0.8 * limit, "k {k}: {pl:?}");
        assert!(pl.reduction < 1.0 && pl.reduction > 0.0);
        // the same placement, fewer texels: the affine map is unchanged
        assert_eq!(pl.affine, free.affine);
        check_visible_inside(&pl, &uv, &views, &idx);
    }
    // a budget the optimal texture already meets changes nothing
    let loose = TexcoordSettings {
        texels_per_pixel: Some(texels(&free) / free.covered_pixels as f64 + 1.0),
        ..Default::default()
    };
    let same = optimize_placement(&mesh, &views, &loose).unwrap();
    assert_eq!((same.width, same.height, same.reduction), (free.width, free.height, 1.0));
    // a non-positive budget is a settings error
    let bad = TexcoordSettings { texels_per_pixel: Some(0.0), ..Default::default() };
    assert!(optimize_placement(&mesh, &views, &bad).is_err());
}

#[test]
fn the_seam_of_a_cylinder_seen_from_one_side_gets_a_branch_cut() {
    let (p, uv, idx) = cylinder(32);
    // the seam (u = 0) faces +x; the camera on +x sees u ∈ [−¼, ¼] across the seam
    let views = [view(camera(Vec3::new(3.0, 0.0, 0.0), Vec3::ZERO), &p)];
    let mesh = ObjectMesh { name: "cylinder", uvs: &uv, indices: &idx, wrap: [true, false] };
    let pl = optimize_placement(&mesh, &views, &TexcoordSettings::default()).unwrap();
    let cut = pl.branch_cut[0].expect("a cut along u");
    assert!((cut - 0.5).abs() < 0.1, "cut at {cut}");
    assert_eq!(pl.repeat, [false, false]);
    let cut_uv: Vec<Vec2> =
        uv.iter().map(|w| Vec2::new(branch_cut::apply_cut(w.x as f64, cut) as f32, w.y)).collect();
    check_visible_inside(&pl, &cut_uv, &views, &idx);
    assert!(pl.stretch <= 1.25);
}

#[test]
fn a_wall_of_a_wrapping_room_seen_in_its_middle_is_not_cut_at_the_seam() {
    // One wall whose u runs over the whole period [0, 1] (a room's walls side by side, u
    // periodic around the room); the camera sees u ∈ about [0.16, 0.84]. The gap in the
    // visible extents holds the seam u = 0 ≡ 1: no cut (a cut there would move the vertices
    // at u = 1 to 0 and fold the last column of triangles over the whole texture).
    let (p, uv, idx) = grid(3);
    let views = [view(camera(Vec3::new(0.0, 0.0, 0.6), Vec3::ZERO), &p)];
    let mesh = ObjectMesh { name: "wall", uvs: &uv, indices: &idx, wrap: [true, false] };
    let pl = optimize_placement(&mesh, &views, &TexcoordSettings::default()).unwrap();
    assert_eq!(pl.branch_cut, [None, None], "{pl:?}");
    assert_eq!(pl.repeat, [false, false]);
    check_visible_inside(&pl, &uv, &views, &idx);
}

#[test]
fn a_cylinder_seen_all_around_keeps_wrapping_with_a_scale_only_map() {
    let (p, uv, idx) = cylinder(32);
    let views: Vec<_> = (0..4)
        .map(|k| {
            let a = k as f32 * std::f32::consts::FRAC_PI_2;
            view(camera(Vec3::new(3.0 * a.cos(), 0.0, 3.0 * a.sin()), Vec3::ZERO), &p)
        })
        .collect();
    let mesh = ObjectMesh { name: "cylinder", uvs: &uv, indices: &idx, wrap: [true, false] };
    let pl = optimize_placement(&mesh, &views, &TexcoordSettings::default()).unwrap();
    assert_eq!(pl.branch_cut[0], None);
    assert_eq!(pl.repeat, [true, false]);
    assert_eq!((pl.affine[0], pl.affine[1], pl.affine[2], pl.affine[4]), (1.0, 0.0, 0.0, 0.0));
    assert!(pl.width > 50 && pl.width.is_power_of_two(), "{pl:?}");
}

#[test]
fn bad_meshes_are_rejected() {
    let (p, uv, mut idx) = grid(1);
    let views = [view(camera(Vec3::new(0.0, 0.0, 2.0), Vec3::ZERO), &p)];
    idx[0] = 99;
    let mesh = ObjectMesh { name: "square", uvs: &uv, indices: &idx, wrap: [false; 2] };
    let e = optimize_placement(&mesh, &views, &TexcoordSettings::default()).unwrap_err();
    assert!(e.to_string().contains("square"), "{e}");
}
