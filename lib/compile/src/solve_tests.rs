//! Tests of the least-squares solver on synthetic render matrices.

use crate::normal_equations::Form;
use crate::synthetic::warp_matrix;
use crate::{
    render, solve, solve_view_independent, CompileError, Filter, FormChoice, RenderMatrix,
    SolveSettings, TextureLayout, View,
};

/// A smooth colourful texture over every level (level m a blurred version of level 0).
fn texture(layout: &TextureLayout) -> Vec<f32> {
    let mut x = Vec::with_capacity(layout.texel_count() * 3);
    for m in 0..layout.levels {
        let (w, h) = layout.level_size(m);
        for j in 0..h {
            for i in 0..w {
                let (s, t) = ((i as f32 + 0.5) / w as f32, (j as f32 + 0.5) / h as f32);
                let a = 1.0 / (1 + m) as f32;
                x.push(0.5 + 0.4 * a * (9.0 * s).sin() * (7.0 * t).cos());
                x.push(0.3 + 0.2 * s);
                x.push(2.0 * t * t);
            }
        }
    }
    x
}

fn psnr(a: &[f32], b: &[f32]) -> f64 {
    let peak = b.iter().fold(0.0f32, |m, &v| m.max(v)) as f64;
    let mse = a.iter().zip(b).map(|(x, y)| ((x - y) as f64).powi(2)).sum::<f64>() / a.len() as f64;
    10.0 * (peak * peak / mse.max(1e-300)).log10()
}

/// A view of a 16×12 texture on a 40×30 screen, rotated and slightly perspective.
fn view(filter: Filter, shift: f64) -> (RenderMatrix, Vec<f32>) {
    let layout = TextureLayout::full(16, 12);
    let a = warp_matrix(40, 30, layout, filter, |x, y| {
        let (x, y) = (x - 20.0 - shift, y - 15.0);
        let w = 1.0 + 0.01 * x;
        let s = 0.5 + (0.9 * x + 0.3 * y) / (36.0 * w);
        let t = 0.5 + (-0.3 * x + 0.9 * y) / (26.0 * w);
        ((0.0..1.0).contains(&s) && (0.0..1.0).contains(&t)).then_some((s, t))
    });
    let b = render(&a, &texture(&layout));
    (a, b)
}

fn assert_monotone(sol: &crate::Solution) {
    for ch in &sol.channels {
        for w in ch.objective.windows(2) {
            assert!(w[1] <= w[0], "objective rose from {} to {}", w[0], w[1]);
        }
        assert!(ch.objective.iter().all(|f| f.is_finite()));
    }
}

#[test]
fn recovers_an_exactly_representable_image_in_both_forms() {
    let (a, b) = view(Filter::Bilinear, 0.0);
    let mut previous: Option<Vec<f32>> = None;
    for form in [Form::A, Form::Normal] {
        let settings = SolveSettings { form: FormChoice::Fixed(form), ..Default::default() };
        let sol = solve(&a, &b, None, &settings).unwrap();
        assert_eq!(sol.form, form);
        assert_monotone(&sol);
        let p = psnr(&render(&a, &sol.texels), &b);
        assert!(p > 60.0, "{form:?}: {p} dB, residual {}", sol.residual_rms);
        assert!(sol.residual_rms < 1e-3);
        if let Some(prev) = &previous {
            assert!(psnr(&render(&a, prev), &render(&a, &sol.texels)) > 60.0);
        }
        previous = Some(sol.texels);
    }
}

#[test]
fn pyramidal_regularization_defines_every_texel_and_costs_little() {
    let (a, mut b) = view(Filter::Trilinear, 0.0);
    // deterministic noise, so neither solve can match b exactly (like a ray-traced layer)
    for (k, v) in b.iter_mut().enumerate() {
        *v += 0.02 * (((k * 2654435761) % 1000) as f32 / 1000.0 - 0.5);
    }
    let plain = solve(&a, &b, None, &SolveSettings::default()).unwrap();
    assert!(plain.undefined > 0, "the unregularized trilinear solve leaves unseen texels");
    let reg = solve(&a, &b, None, &SolveSettings::pyramidal()).unwrap();
    assert_eq!(reg.undefined, 0);
    assert!(reg.texels.iter().all(|v| v.is_finite()));
    // every level holds values of the image's magnitude, not the zero start
    let l = reg.layout;
    let last = l.level_offset(l.levels - 1) * 3;
    assert!(reg.texels[last..].iter().any(|&v| v > 0.1));
    assert_monotone(&reg);
    let (p0, p1) = (psnr(&render(&a, &plain.texels), &b), psnr(&render(&a, &reg.texels), &b));
    // (the drop shrinks with ε_f: 0.3 dB at ε_f = 0.03, 0.06 dB at 0.01 on this view)
    assert!(p0 - p1 < 2.0, "plain {p0} dB, pyramidal {p1} dB");
}

#[test]
fn range_regularization_keeps_texels_in_range_and_never_raises_the_objective() {
    let (a, mut b) = view(Filter::Trilinear, 0.0);
    // a few outliers the texture cannot reproduce, pulling unconstrained texels out of range
    for (k, v) in b.iter_mut().enumerate() {
        if k % 37 == 0 {
            *v += 1.5;
        }
    }
    let settings = SolveSettings { epsilon_f: 0.1, ..SolveSettings::range() };
    let sol = solve(&a, &b, None, &settings).unwrap();
    assert_monotone(&sol);
    let r = 1.1 * b.iter().fold(0.0f32, |m, &v| m.max(v));
    let d = r / 512.0;
    assert!(sol.texels.iter().all(|&v| v > -d && v < r + d));
}

#[test]
fn unobserved_texels_grazing_views_tiny_coverage_and_half_off_screen_stay_finite() {
    let layout = TextureLayout::full(32, 32);
    let x = texture(&layout);
    let cases: Vec<(&str, RenderMatrix)> = vec![
        // grazing: t spans the texture over 2 rows of pixels
        (
            "grazing",
            warp_matrix(40, 30, layout, Filter::Trilinear, |x, y| {
                let (s, t) = (x / 40.0, (y - 14.0) / 2.0);
                (0.0..1.0).contains(&t).then_some((s, t))
            }),
        ),
        (
            "tiny",
            warp_matrix(40, 30, layout, Filter::Trilinear, |x, y| {
                (x < 2.0 && y < 2.0).then_some((0.3 + x * 0.01, 0.6 + y * 0.01))
            }),
        ),
        // the object's left half is off screen: only s ≥ ½ is seen
        (
            "half-off-screen",
            warp_matrix(40, 30, layout, Filter::Trilinear, |x, y| Some((0.5 + x / 80.0, y / 30.0))),
        ),
    ];
    for (name, a) in cases {
        let b = render(&a, &x);
        for settings in [
            SolveSettings::default(),
            SolveSettings::pyramidal(),
            SolveSettings { epsilon_b: 1.0 / 32.0, ..SolveSettings::pyramidal() },
        ] {
            let sol = solve(&a, &b, None, &settings).unwrap();
            assert!(sol.texels.iter().all(|v| v.is_finite()), "{name}");
            assert!(sol.residual_rms.is_finite(), "{name}");
            assert!(sol.residual_relative < 0.05, "{name}: residual {}", sol.residual_relative);
            assert_monotone(&sol);
        }
    }
}

#[test]
fn non_finite_inputs_are_rejected() {
    let (mut a, mut b) = view(Filter::Bilinear, 0.0);
    b[7] = f32::NAN;
    let e = solve(&a, &b, None, &SolveSettings::default()).unwrap_err();
    assert!(matches!(e, CompileError::NonFinite { index: 7, .. }), "{e}");
    assert!(e.to_string().contains("b holds a non-finite value"));
    b[7] = 0.0;
    a.vals[3] = f32::INFINITY;
    let e = solve(&a, &b, None, &SolveSettings::default()).unwrap_err();
    assert!(matches!(e, CompileError::NonFinite { index: 3, .. }), "{e}");
    a.vals[3] = 0.5;
    let x0 = vec![f32::NEG_INFINITY; a.cols() * 3];
    assert!(matches!(
        solve(&a, &b, Some(&x0), &SolveSettings::default()),
        Err(CompileError::NonFinite { .. })
    ));
    assert!(matches!(
        solve(&a, &b[1..], None, &SolveSettings::default()),
        Err(CompileError::Size { .. })
    ));
    a.cols[0] = a.cols() as u32;
    assert!(matches!(solve(&a, &b, None, &SolveSettings::default()), Err(CompileError::Matrix(_))));
}

#[test]
fn a_warm_start_from_a_neighbouring_sample_needs_fewer_iterations() {
    let (a0, b0) = view(Filter::Trilinear, 0.0);
    let (a1, b1) = view(Filter::Trilinear, 0.7);
    let s = SolveSettings::pyramidal();
    let first = solve(&a0, &b0, None, &s).unwrap();
    let cold = solve(&a1, &b1, None, &s).unwrap();
    let warm = solve(&a1, &b1, Some(&first.texels), &s).unwrap();
    assert!(warm.iterations < cold.iterations, "warm {} cold {}", warm.iterations, cold.iterations);
}

#[test]
fn a_view_independent_texture_is_solved_over_stacked_views() {
    let layout = TextureLayout::full(16, 16);
    let x = texture(&layout);
    // each view sees one half of the texture
    let left = warp_matrix(32, 32, layout, Filter::Bilinear, |x, y| Some((x / 64.0, y / 32.0)));
    let right =
        warp_matrix(32, 32, layout, Filter::Bilinear, |x, y| Some((0.5 + x / 64.0, y / 32.0)));
    let (bl, br) = (render(&left, &x), render(&right, &x));
    let views = [View { a: &left, b: &bl }, View { a: &right, b: &br }];
    let sol = solve_view_independent(&views, None, &SolveSettings::default()).unwrap();
    assert_eq!(sol.form, Form::Normal);
    assert_eq!(sol.n_s, 2 * 32 * 32);
    assert!(psnr(&render(&left, &sol.texels), &bl) > 60.0);
    assert!(psnr(&render(&right, &sol.texels), &br) > 60.0);
    // level 0 is fully determined by the two views together
    let n0 = 16 * 16 * 3;
    assert!(psnr(&sol.texels[..n0], &x[..n0]) > 50.0);
}

/// Serves views one at a time, as a scratch file would, counting what it serves.
struct OneAtATime<'a> {
    views: &'a [View<'a>],
    served: std::cell::Cell<usize>,
}

impl crate::ViewSource for OneAtATime<'_> {
    fn count(&self) -> usize {
        self.views.len()
    }

    fn visit(
        &self,
        k: usize,
        f: &mut dyn FnMut(View<'_>) -> Result<(), CompileError>,
    ) -> Result<(), CompileError> {
        self.served.set(self.served.get() + 1);
        // A copy that lives only for the call.
        let (a, b) = (self.views[k].a.clone(), self.views[k].b.to_vec());
        f(View { a: &a, b: &b })
    }
}

#[test]
fn views_served_one_at_a_time_give_the_stacked_solve_bit_for_bit() {
    let layout = TextureLayout::full(16, 16);
    let x = texture(&layout);
    let mats: Vec<RenderMatrix> = (0..4)
        .map(|k| {
            let (u0, v0) = (0.1 * k as f64, 0.05 * k as f64);
            warp_matrix(28 + 3 * k, 30, layout, Filter::Trilinear, move |x, y| {
                Some((u0 + x / 70.0, v0 + (y / 40.0).powf(1.1)))
            })
        })
        .collect();
    let bs: Vec<Vec<f32>> = mats
        .iter()
        .enumerate()
        .map(|(k, a)| render(a, &x).iter().map(|v| v * (1.0 + 0.01 * k as f32)).collect())
        .collect();
    let views: Vec<View> = mats.iter().zip(&bs).map(|(a, b)| View { a, b }).collect();
    for settings in [SolveSettings::pyramidal(), SolveSettings::range(), SolveSettings::decimated()]
    {
        // The stacked matrix held, in the AᵀA form.
        let held = crate::solve::solve_views(&views, Some(&x), &settings, true).unwrap();
        let source = OneAtATime { views: &views, served: std::cell::Cell::new(0) };
        let streamed = crate::solve_view_source(&source, Some(&x), &settings).unwrap();
        assert_eq!(streamed.form, Form::Normal);
        assert_eq!(streamed.texels, held.texels);
        assert_eq!(streamed.iterations, held.iterations);
        assert_eq!((streamed.n_s, streamed.undefined), (held.n_s, held.undefined));
        assert_eq!(streamed.residual_rms.to_bits(), held.residual_rms.to_bits());
        assert_eq!(streamed.residual_relative.to_bits(), held.residual_relative.to_bits());
        // The data term, then the residual.
        assert_eq!(source.served.get(), 2 * views.len());
    }
}

#[test]
fn solving_twice_gives_identical_bytes() {
    let (a, b) = view(Filter::Trilinear, 0.3);
    for form in [Form::A, Form::Normal] {
        let s = SolveSettings { form: FormChoice::Fixed(form), ..SolveSettings::pyramidal() };
        let one = solve(&a, &b, None, &s).unwrap();
        let two = solve(&a, &b, None, &s).unwrap();
        assert_eq!(one.texels, two.texels);
        assert_eq!(one.iterations, two.iterations);
    }
}

/// A quad from the hardware model: positions in object space, uv = corners.
fn model_matrix(
    positions: [[f32; 3]; 4],
    clip_from_object: glam::Mat4,
    layout: TextureLayout,
) -> RenderMatrix {
    use crate::{
        render_matrix, Address, DrawMesh, Sampler, TextureTransform, TexturedObject, Viewport,
    };
    const UV: [[f32; 2]; 4] = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
    const IDX: [u32; 6] = [0, 1, 2, 0, 2, 3];
    let object = TexturedObject {
        mesh: DrawMesh { positions: &positions, uvs: &UV, indices: &IDX, clip_from_object },
        transform: TextureTransform::IDENTITY,
        layout,
        sampler: Sampler { filter: Filter::Trilinear, address: [Address::ClampToEdge; 2] },
    };
    render_matrix(Viewport { width: 48, height: 36 }, &object, None).unwrap()
}

#[test]
fn hardware_model_views_where_most_texels_are_unobserved_converge() {
    use crate::transform::{look_at, perspective};
    use glam::Vec3;
    let layout = TextureLayout::full(32, 32);
    let x = texture(&layout);
    let proj = perspective(0.9, 48.0 / 36.0, 0.1, 100.0);
    // wound counter-clockwise seen from above (+y)
    let floor = [[-1.0, 0.0, -1.0], [-1.0, 0.0, 1.0], [1.0, 0.0, 1.0], [1.0, 0.0, -1.0]];
    let cases = [
        // the quad seen almost edge-on
        ("grazing", floor, proj * look_at(Vec3::new(0.0, 0.3, 3.0), Vec3::ZERO, Vec3::Y)),
        // far away: a few pixels
        ("tiny", floor, proj * look_at(Vec3::new(0.0, 12.0, 16.0), Vec3::ZERO, Vec3::Y)),
        // the camera looks past the quad's edge: its left half is off screen
        (
            "half-off-screen",
            floor,
            proj * look_at(Vec3::new(-1.0, 2.0, 0.5), Vec3::new(-1.0, 0.0, 0.0), Vec3::Y),
        ),
    ];
    for (name, p, m) in cases {
        let a = model_matrix(p, m, layout);
        assert!(a.rows() > 0, "{name}: the quad is visible");
        let b = render(&a, &x);
        for settings in [
            SolveSettings::default(),
            SolveSettings::pyramidal(),
            SolveSettings { epsilon_b: 1.0 / 32.0, ..SolveSettings::pyramidal() },
        ] {
            let sol = solve(&a, &b, None, &settings).unwrap();
            assert!(sol.texels.iter().all(|v| v.is_finite()), "{name}");
            assert!(
                sol.residual_rms.is_finite() && sol.residual_relative < 0.05,
                "{name}: residual {}",
                sol.residual_relative
            );
            assert_monotone(&sol);
            if settings.epsilon_f > 0.0 {
                assert_eq!(sol.undefined, 0);
            }
        }
    }
}

/// A 64×48 texture minified onto a 24×18 screen (≈ 7 texels per pixel, n_t ≫ n_s, as on
/// demo1 at 320×240), seen with a slight perspective so pixels straddle MIP levels.
fn minified_view(shift: f64) -> (RenderMatrix, Vec<f32>) {
    let layout = TextureLayout::full(64, 48);
    let a = warp_matrix(24, 18, layout, Filter::Trilinear, |x, y| {
        let (x, y) = (x - 12.0 - shift, y - 9.0);
        let w = 1.0 + 0.04 * y;
        let s = 0.5 + (0.95 * x + 0.2 * y) / (25.0 * w);
        let t = 0.5 + (-0.2 * x + 0.95 * y) / (19.0 * w);
        ((0.0..1.0).contains(&s) && (0.0..1.0).contains(&t)).then_some((s, t))
    });
    let b = render(&a, &texture(&layout));
    (a, b)
}

/// The pyramidal criterion (PSNR drop at the sampled view) was measured against plain least
/// squares on systems with many more texels than pixels. There plain LS is ill-posed: it
/// fits b (noise included) through near-null directions of A with texels far outside the
/// image's range, and that texture fails at any other view. The pyramidal solve stays in
/// range and is the better texture off the sample.
#[test]
fn unregularized_fit_with_more_texels_than_pixels_is_an_out_of_range_overfit() {
    let (a, mut b) = minified_view(0.0);
    for (k, v) in b.iter_mut().enumerate() {
        *v += 0.02 * (((k * 2654435761) % 1000) as f32 / 1000.0 - 0.5);
    }
    assert!(
        a.layout.texel_count() > 4 * a.rows(),
        "n_t {} vs n_s {}",
        a.layout.texel_count(),
        a.rows()
    );
    let settings = |s: SolveSettings| SolveSettings {
        cg: crate::cg::CgSettings { tolerance: 1e-8, max_iterations: 5000, ..s.cg },
        ..s
    };
    let plain = solve(&a, &b, None, &settings(SolveSettings::default())).unwrap();
    let reg = solve(&a, &b, None, &settings(SolveSettings::pyramidal())).unwrap();
    assert_monotone(&reg);
    let b_max = b.iter().fold(0.0f32, |m, &v| m.max(v.abs()));
    let extent = |x: &[f32]| x.iter().fold(0.0f32, |m, &v| m.max(v.abs()));
    let (p_plain, p_reg) =
        (psnr(&render(&a, &plain.texels), &b), psnr(&render(&a, &reg.texels), &b));
    // a neighbouring view, against the noise-free truth there
    let (a2, truth2) = minified_view(0.7);
    let (q_plain, q_reg) =
        (psnr(&render(&a2, &plain.texels), &truth2), psnr(&render(&a2, &reg.texels), &truth2));
    eprintln!("plain {p_plain:.1} dB (|x| ≤ {}), pyramidal {p_reg:.1} dB (|x| ≤ {}), b ≤ {b_max}; neighbour: plain {q_plain:.1}, pyramidal {q_reg:.1}",
              extent(&plain.texels), extent(&reg.texels));
    assert!(p_plain > p_reg, "plain LS fits the sample (noise included) closer");
    assert!(extent(&reg.texels) < 1.5 * b_max, "pyramidal texels stay in the image's range");
    assert!(extent(&plain.texels) > 3.0 * b_max, "plain LS leaves the range");
    assert!(q_reg > q_plain + 3.0, "off the sample the pyramidal texture is the better one");
}

/// A receding plane: a 48×32 texture on a 40×30 screen, magnified at the bottom and
/// minified up to about 4× (MIP levels 0–2) at the top; b is a striped image of (s, t), a
/// traced layer rather than a rendering of some texture.
fn receding_view() -> (RenderMatrix, Vec<f32>, TextureLayout) {
    let layout = TextureLayout::full(48, 32);
    let map = |x: f64, y: f64| {
        let depth = 1.0 + 3.0 * (1.0 - y / 30.0);
        let s = 0.5 + (x - 20.0) / (40.0 * depth) * 1.6;
        let t = 1.0 - (1.0 - 1.0 / depth) * 1.3;
        ((0.0..1.0).contains(&s) && (0.0..1.0).contains(&t)).then_some((s, t))
    };
    let a = warp_matrix(40, 30, layout, Filter::Trilinear, map);
    let mut b = vec![0.0f32; a.rows() * 3];
    for r in 0..a.rows() {
        let p = a.pixels[r];
        let (s, t) = map((p % 40) as f64 + 0.5, (p / 40) as f64 + 0.5).expect("a covered pixel");
        let stripe = 0.5 + 0.4 * (40.0 * s).sin();
        b[r * 3..r * 3 + 3].copy_from_slice(&[
            stripe as f32,
            (0.2 + 0.6 * t) as f32,
            (stripe * t) as f32,
        ]);
    }
    (a, b, layout)
}

#[test]
fn the_decimated_parameterization_fits_the_chain_the_player_draws() {
    use crate::decimation::chain_f32;
    let (a, b, layout) = receding_view();
    let n0 = layout.width as usize * layout.height as usize * 3;
    // Free levels (thesis 3.5), then drawn as the player draws them: level 0 stored, the
    // coarser levels decimated from it.
    let free = solve(&a, &b, None, &SolveSettings::pyramidal()).unwrap();
    let as_solved = psnr(&render(&a, &free.texels), &b);
    let as_drawn = psnr(&render(&a, &chain_f32(&layout, &free.texels[..n0], 3)), &b);
    // Level 0 through D: what is solved is what is drawn.
    let dec = solve(&a, &b, None, &SolveSettings::decimated()).unwrap();
    let redrawn = chain_f32(&layout, &dec.texels[..n0], 3);
    assert_eq!(dec.texels, redrawn, "the solved chain is the decimated level 0");
    let decimated = psnr(&render(&a, &dec.texels), &b);
    assert_monotone(&dec);
    assert!(dec.converged && dec.undefined == 0);
    assert!(decimated >= as_drawn + 3.0,
            "decimated solve {decimated:.2} dB vs free levels drawn decimated {as_drawn:.2} dB (as solved {as_solved:.2} dB)");
    assert!(decimated >= 30.0, "decimated solve {decimated:.2} dB");
}

/// Eq. 3.4 as written (the box 0 ≤ x ≤ 1.1·max b, enforced exactly): on the receding plane
/// (a traced-like layer, not in A's range) the bounded fit stays in the box, its objective never rises, it meets the optimality
/// conditions of the box, and a weak pyramidal term in the same box (every texel defined)
/// costs under 0.5 dB at the sampled view against it.
#[test]
fn bounded_least_squares_keeps_the_box_and_weak_pyramidal_costs_little() {
    let (a, b, _) = receding_view();
    let b_max = b.iter().fold(0.0f32, |m, &v| m.max(v));
    // The solver's default tolerance (1e-4), with room for the iterations.
    let cg = crate::cg::CgSettings { max_iterations: 5000, ..Default::default() };
    let bounded = solve(&a, &b, None, &SolveSettings { cg, ..SolveSettings::bounded() }).unwrap();
    let hi = 1.1 * b_max;
    assert!(
        bounded.texels.iter().all(|&v| (0.0..=hi * (1.0 + 1e-6)).contains(&v)),
        "texels leave [0, {hi}]"
    );
    assert_monotone(&bounded);
    assert!(
        bounded.converged,
        "{:?}",
        bounded
            .channels
            .iter()
            .map(|c| (c.iterations, c.objective.last().copied()))
            .collect::<Vec<_>>()
    );
    let pyr =
        solve(&a, &b, None, &SolveSettings { cg, epsilon_f: 0.003, ..SolveSettings::bounded() })
            .unwrap();
    assert_eq!(pyr.undefined, 0);
    assert!(pyr.texels.iter().all(|v| v.is_finite()));
    let (p_box, p_pyr) =
        (psnr(&render(&a, &bounded.texels), &b), psnr(&render(&a, &pyr.texels), &b));
    eprintln!("bounded {p_box:.2} dB, bounded pyramidal (ε_f 0.003) {p_pyr:.2} dB");
    assert!(p_box - p_pyr < 0.5, "bounded {p_box:.2} dB, pyramidal {p_pyr:.2} dB");
    // The range term and the box are alternatives.
    assert!(solve(
        &a,
        &b,
        None,
        &SolveSettings { epsilon_b: 1.0 / 32.0, ..SolveSettings::bounded() }
    )
    .is_err());
}

#[test]
fn each_channel_solves_as_it_would_alone_bit_for_bit() {
    // The channels are iterated in lockstep, sharing each product with A. Warm-started
    // from a solution with the first channel zeroed, the other two stop at once and the
    // first goes on alone; solved with every channel equal to it, three lanes go on.
    let (a, mut b) = view(Filter::Trilinear, 0.0);
    for (k, v) in b.iter_mut().enumerate() {
        *v += 0.02 * (((k * 7919) % 61) as f32 / 61.0 - 0.5);
    }
    // The brightest value in every channel of one pixel: the range term's bound is the
    // same for the channels alone.
    let peak = b.iter().fold(0.0f32, |m, &v| m.max(v));
    b[..3].fill(peak);
    let settings = [
        SolveSettings::pyramidal(),
        SolveSettings::decimated(),
        SolveSettings { epsilon_b: 1.0 / 32.0, ..SolveSettings::pyramidal() },
        SolveSettings { form: FormChoice::Fixed(Form::A), ..SolveSettings::pyramidal() },
    ];
    let each =
        |x: &[f32], ch: usize| -> Vec<f32> { x.chunks(3).flat_map(|p| [p[ch]; 3]).collect() };
    for s in settings {
        let mut warm = solve(&a, &b, None, &s).unwrap().texels;
        warm.iter_mut().step_by(3).for_each(|v| *v = 0.0);
        let all = solve(&a, &b, Some(&warm), &s).unwrap();
        let iterations: Vec<u32> = all.channels.iter().map(|c| c.iterations).collect();
        assert!(iterations[0] > 0 && iterations[1..] == [0, 0], "{s:?}: {iterations:?}");
        for ch in 0..3 {
            let one = solve(&a, &each(&b, ch), Some(&each(&warm, ch)), &s).unwrap();
            assert_eq!(one.channels[0], all.channels[ch], "{s:?}, channel {ch}");
            let bits = |x: &[f32]| x.iter().skip(ch).step_by(3).map(|v| v.to_bits()).collect();
            let (lone, joint): (Vec<u32>, Vec<u32>) = (bits(&one.texels), bits(&all.texels));
            assert_eq!(lone, joint, "{s:?}, channel {ch}");
        }
    }
}
