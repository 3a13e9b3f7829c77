//! Material textures in the tracer: emissive and normal maps, alpha MASK and BLEND holes in
//! closest-hit, shadow and all-hit queries (tiny programmatic scenes).

mod common;

use common::*;
use glam::{Vec3, Vec4};
use pis_scene::{AlphaMode, Material, ObjectRole, Scene, TextureImage, TextureRef};
use pis_trace::bvh::SceneGeometry;
use pis_trace::{render_point, TraceSettings};

/// A texture one texel high: `left` on its left half, `right` on its right half (8 texels).
fn halves(left: [f32; 4], right: [f32; 4]) -> TextureImage {
    TextureImage { width: 8, height: 1, texels: [[left; 4], [right; 4]].concat() }
}

/// A 2×2 quad at depth `z` facing +Z (u along +X, v down along −Y) with material `m`.
fn wall(z: f32, m: usize) -> pis_scene::Primitive {
    quad(Vec3::new(0.0, 0.0, z), Vec3::X, Vec3::Y, m)
}

fn scene_of(
    prims: Vec<pis_scene::Primitive>,
    materials: Vec<Material>,
    textures: Vec<TextureImage>,
) -> Scene {
    let mut s = scene(vec![object("o", ObjectRole::Diffuse, prims)], materials, (16, 8), 4);
    s.textures = textures;
    s
}

#[test]
fn emissive_map_modulates_emissive_factor() {
    // emissiveFactor 1 with a map black on its left half: only the right half glows.
    let m = Material {
        emissive: [1.0; 3],
        emissive_texture: Some(TextureRef::new(0)),
        ..matte([0.0; 3])
    };
    let s = scene_of(vec![wall(0.0, 0)], vec![m], vec![halves([0.0, 0.0, 0.0, 1.0], [1.0; 4])]);
    // From 2 m away the camera sees x ∈ [−1, 1] across the 16 columns, y ∈ [−½, ½] down the 8 rows.
    let fov = 2.0 * 0.25f32.atan().to_degrees();
    let f = frame(&s, camera(Vec3::new(0.0, 0.0, 2.0), Vec3::ZERO, fov), vec![]);
    let r = render_point(&s, &f, &TraceSettings::new(s.resolution, s.spp), &|| {}).expect("render");
    let combined = r.images.layer("combined").unwrap();
    for y in 2..6 {
        for x in 2..6 {
            assert!(
                combined.rgb(x, y).max_element() < 0.05,
                "({x},{y}) glows: {}",
                combined.rgb(x, y)
            );
        }
        for x in 10..14 {
            assert!(
                (combined.rgb(x, y) - Vec3::ONE).abs().max_element() < 0.05,
                "({x},{y}): {}",
                combined.rgb(x, y)
            );
        }
    }
}

#[test]
fn alpha_mask_lets_rays_through_cut_texels() {
    // A masked wall whose left half has alpha 0, before an opaque wall.
    let mask = Material {
        base_color_texture: Some(TextureRef::new(0)),
        alpha_mode: AlphaMode::Mask { cutoff: 0.5 },
        ..matte([1.0; 3])
    };
    let s = scene_of(
        vec![wall(0.0, 0), wall(-1.0, 1)],
        vec![mask.clone(), matte([1.0; 3])],
        vec![halves([1.0, 1.0, 1.0, 0.0], [1.0; 4])],
    );
    let f = frame(&s, camera(Vec3::Z, Vec3::ZERO, 40.0), vec![]);
    let g = SceneGeometry::build(&s, &f);
    let (hole, solid) = (Vec3::new(-0.5, 0.0, 1.0), Vec3::new(0.5, 0.0, 1.0));
    let t = |o: Vec3| g.closest(o, Vec3::NEG_Z, f32::INFINITY, None).map(|h| h.t);
    assert!((t(hole).unwrap() - 2.0).abs() < 1e-4, "through the hole to the back wall");
    assert!((t(solid).unwrap() - 1.0).abs() < 1e-4, "stopped by the solid half");
    // Shadow rays and all-hit queries see the same holes.
    assert!(!g.occluded(hole, Vec3::NEG_Z, 1.5) && g.occluded(solid, Vec3::NEG_Z, 1.5));
    assert_eq!(g.all_hits(hole, Vec3::NEG_Z, f32::INFINITY).len(), 1);
    assert_eq!(g.all_hits(solid, Vec3::NEG_Z, f32::INFINITY).len(), 2);
    // OPAQUE ignores alpha.
    let opaque = Material { alpha_mode: AlphaMode::Opaque, ..mask };
    let s =
        scene_of(vec![wall(0.0, 0)], vec![opaque], vec![halves([1.0, 1.0, 1.0, 0.0], [1.0; 4])]);
    let g = SceneGeometry::build(&s, &f);
    assert!(g.occluded(hole, Vec3::NEG_Z, 1.5));
}

#[test]
fn alpha_blend_passes_rays_with_probability_one_minus_alpha() {
    let blend = Material {
        base_color: [1.0, 1.0, 1.0, 0.25],
        alpha_mode: AlphaMode::Blend,
        ..matte([1.0; 3])
    };
    let s = scene_of(vec![wall(0.0, 0)], vec![blend], vec![]);
    let f = frame(&s, camera(Vec3::Z, Vec3::ZERO, 40.0), vec![]);
    let g = SceneGeometry::build(&s, &f);
    let n = 4000;
    let origin =
        |k: usize| Vec3::new((k % 63) as f32 / 63.0 - 0.5, (k / 63) as f32 / 64.0 - 0.5, 1.0);
    let passed = (0..n).filter(|&k| !g.occluded(origin(k), Vec3::NEG_Z, 2.0)).count();
    let fraction = passed as f32 / n as f32;
    assert!((fraction - 0.75).abs() < 0.03, "{fraction} of the rays passed, expected 0.75");
    // The choice is a function of the ray: the same ray, the same answer.
    assert!((0..64).all(
        |k| g.occluded(origin(k), Vec3::NEG_Z, 2.0) == g.occluded(origin(k), Vec3::NEG_Z, 2.0)
    ));
}

/// The shading normal at the centre of a wall with a normal map of one texel `texel`.
fn mapped_normal_at_hit(texel: [f32; 4], tangents: Option<Vec4>) -> Vec3 {
    let mut prim = wall(0.0, 0);
    if let Some(t) = tangents {
        prim.tangents = vec![t; 4];
    }
    let m = Material { normal_texture: Some(TextureRef::new(0)), ..matte([1.0; 3]) };
    let s = scene_of(
        vec![prim],
        vec![m],
        vec![TextureImage { width: 1, height: 1, texels: vec![texel] }],
    );
    let f = frame(&s, camera(Vec3::Z, Vec3::ZERO, 40.0), vec![]);
    let g = SceneGeometry::build(&s, &f);
    let o = Vec3::new(0.1, 0.2, 1.0);
    let hit = g.closest(o, Vec3::NEG_Z, f32::INFINITY, None).expect("a hit");
    let mut sp = g.surface(&hit, o, Vec3::NEG_Z);
    assert_eq!(sp.normal, Vec3::Z);
    sp.apply_normal_map(&s, &s.materials[0]);
    sp.normal
}

#[test]
fn normal_map_bends_shading_normal_at_a_hit() {
    // A texel leaning right (+X in tangent space): the normal leans along +u, world +X.
    let right = [0.8, 0.5, 0.9, 1.0];
    let n = mapped_normal_at_hit(right, None);
    let want = Vec3::new(0.6, 0.0, 0.8).normalize();
    assert!((n - want).length() < 1e-3, "{n} vs {want}");
    // A texel leaning up the image (+Y): the normal leans to world +Y (v runs down).
    let n = mapped_normal_at_hit([0.5, 0.8, 0.9, 1.0], None);
    assert!((n - Vec3::new(0.0, 0.6, 0.8).normalize()).length() < 1e-3, "{n}");
    // A flat texel leaves the normal alone.
    assert!((mapped_normal_at_hit([0.5, 0.5, 1.0, 1.0], None) - Vec3::Z).length() < 1e-6);
}

#[test]
fn tangent_attribute_orients_the_normal_map() {
    // TANGENT along world +Y (w = 1): a texel leaning along tangent-space +X leans to +Y.
    let n = mapped_normal_at_hit([0.8, 0.5, 0.9, 1.0], Some(Vec4::new(0.0, 1.0, 0.0, 1.0)));
    assert!((n - Vec3::new(0.0, 0.6, 0.8).normalize()).length() < 1e-3, "{n}");
    // Its bitangent is w · (normal × tangent) = Z × Y = −X for w = 1.
    let n = mapped_normal_at_hit([0.5, 0.8, 0.9, 1.0], Some(Vec4::new(0.0, 1.0, 0.0, 1.0)));
    assert!((n - Vec3::new(-0.6, 0.0, 0.8).normalize()).length() < 1e-3, "{n}");
}
