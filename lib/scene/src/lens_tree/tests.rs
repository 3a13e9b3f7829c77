use super::*;

/// A glass sphere (radius 1 at the origin, n = 1.5, clear), intersected analytically.
fn sphere_next(o: Vec3, d: Vec3) -> Step<()> {
    let b = o.dot(d);
    let c = o.length_squared() - 1.0;
    let disc = b * b - c;
    if disc < 0.0 {
        return Step::Exit(());
    }
    let (t0, t1) = (-b - disc.sqrt(), -b + disc.sqrt());
    let t = if t0 > 1e-5 { t0 } else { t1 };
    if t <= 1e-5 {
        return Step::Exit(());
    }
    let p = o + d * t;
    let outward = p.normalize();
    let front_face = d.dot(outward) < 0.0;
    let n = if front_face { outward } else { -outward };
    Step::Interface(LensInterface {
        position: p,
        normal: n,
        geometric_normal: outward,
        front_face,
        ior: 1.5,
        base: Vec3::ONE,
        absorption: Vec3::ONE,
    })
}

/// Where a ray at height `h` (0 … 1) above the axis, travelling along −z, meets the sphere.
fn first(h: f32) -> (LensInterface, Vec3) {
    let dir = -Vec3::Z;
    let Step::Interface(s) = sphere_next(Vec3::new(0.0, h, 5.0), dir) else {
        panic!("misses the sphere")
    };
    (s, dir)
}

fn weight(p: &Option<LensPath<()>>) -> f32 {
    p.as_ref().map_or(0.0, |p| p.modulation.x)
}

#[test]
fn the_tree_splits_a_sphere_into_r_t_trt_and_trrt_with_fresnel_weights() {
    for h in [0.0f32, 0.3, 0.6, 0.8] {
        let (s, dir) = first(h);
        let terms = lens_paths(
            &s,
            dir,
            LensModel::Tree { min_weight: 1e-4, internal_terms: 3 },
            8,
            sphere_next,
        );
        // In a sphere every inner interface meets the ray at the refracted angle, so each
        // reflection inside weighs the same F as the first (to within what the origins'
        // offset off each interface, 10⁻⁴ of the scale, turns the angles by).
        let f = fresnel_dielectric(-dir.dot(s.normal), 1.0 / 1.5);
        let want =
            [f, (1.0 - f) * (1.0 - f), (1.0 - f) * f * (1.0 - f), (1.0 - f) * f * f * (1.0 - f)];
        for (k, w) in want.iter().enumerate() {
            let got = weight(&terms[k]);
            assert!((got - w).abs() < 5e-3 * w, "h {h}, term {k}: {got} against {w}");
            let p = terms[k].as_ref().unwrap();
            assert_eq!(p.topology.interfaces as usize, if k == 0 { 1 } else { k + 1 });
        }
        // Straight through the centre the ray leaves undeviated.
        if h == 0.0 {
            assert!(terms[1].as_ref().unwrap().exit_direction.dot(dir) > 1.0 - 1e-6);
        }
    }
}

#[test]
fn the_tree_carries_more_of_the_light_than_the_greedy_paths() {
    // Over the sphere's disc (heights weighted by area), the greedy paths carry about 93 %
    // of the light that reaches it, the tree's four terms over 99 %.
    let (mut greedy, mut tree, mut area) = (0.0, 0.0, 0.0);
    for i in 0..200 {
        let h = (i as f32 + 0.5) / 200.0;
        let (s, dir) = first(h);
        let g = lens_paths(&s, dir, LensModel::Greedy, 8, sphere_next);
        let t = lens_paths(&s, dir, LensModel::TREE, 8, sphere_next);
        greedy += h * g.iter().map(weight).sum::<f32>();
        tree += h * t.iter().map(weight).sum::<f32>();
        area += h;
    }
    let (greedy, tree) = (greedy / area, tree / area);
    assert!((0.90..0.95).contains(&greedy), "greedy {greedy}");
    assert!(tree > 0.99, "tree {tree}");
}

#[test]
fn the_greedy_model_is_the_trees_first_two_terms_where_fresnel_is_small() {
    let (s, dir) = first(0.5);
    let g = lens_paths(&s, dir, LensModel::Greedy, 8, sphere_next);
    let t = lens_paths(&s, dir, LensModel::TREE, 8, sphere_next);
    assert_eq!(g[0], t[0]);
    assert_eq!(g[1], t[1]);
    assert!(g[2].is_none() && g[3].is_none());
}

#[test]
fn weights_below_the_threshold_and_paths_past_the_depth_cap_are_dropped() {
    let (s, dir) = first(0.5);
    let t =
        lens_paths(&s, dir, LensModel::Tree { min_weight: 0.5, internal_terms: 3 }, 8, sphere_next);
    assert!(t[0].is_none() && t[2].is_none() && t[3].is_none());
    assert!(t[1].is_some());
    // One segment after the first interface: the reflection leaves, the refraction is still
    // inside.
    let t = lens_paths(&s, dir, LensModel::TREE, 1, sphere_next);
    assert!(t[0].is_some() && t[1].is_none());
    let t = lens_paths(&s, dir, LensModel::TREE, 2, sphere_next);
    assert!(t[1].is_some() && t[2].is_none());
    // Fewer terms: the paths with more internal reflections are not followed.
    let t = lens_paths(
        &s,
        dir,
        LensModel::Tree { min_weight: 1e-4, internal_terms: 1 },
        8,
        sphere_next,
    );
    assert!(t[1].is_some() && t[2].is_none());
}

#[test]
fn topology_records_the_reflections() {
    let t = Topology::default().then(false).then(true).then(false);
    assert_eq!(t, Topology { interfaces: 3, reflected: 0b010 });
}
