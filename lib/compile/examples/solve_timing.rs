//! Times the solver on a synthetic 320×240 view of a perspective-warped texture:
//! `cargo run --release -p pis-compile --example solve_timing`.

use pis_compile::synthetic::warp_matrix;
use pis_compile::{render, solve, Filter, Form, FormChoice, SolveSettings, TextureLayout};

fn main() {
    let layout = TextureLayout::full(200, 150);
    for filter in [Filter::Bilinear, Filter::Trilinear] {
        let a = warp_matrix(320, 240, layout, filter, |x, y| {
            let (x, y) = (x - 160.0, y - 120.0);
            let w = 1.0 + 0.002 * x;
            let s = 0.5 + (0.9 * x + 0.2 * y) / (300.0 * w);
            let t = 0.5 + (-0.2 * x + 0.9 * y) / (220.0 * w);
            ((0.0..1.0).contains(&s) && (0.0..1.0).contains(&t)).then_some((s, t))
        });
        let x: Vec<f32> =
            (0..layout.texel_count() * 3).map(|k| ((k * 7919) % 1000) as f32 / 1000.0).collect();
        let b = render(&a, &x);
        for (name, s) in [
            ("auto", SolveSettings::default()),
            ("A", SolveSettings { form: FormChoice::Fixed(Form::A), ..Default::default() }),
            ("AtA", SolveSettings { form: FormChoice::Fixed(Form::Normal), ..Default::default() }),
            ("pyramidal", SolveSettings::pyramidal()),
            ("range+pyr", SolveSettings { epsilon_b: 1.0 / 32.0, ..SolveSettings::pyramidal() }),
        ] {
            let sol = solve(&a, &b, None, &s).unwrap();
            println!(
                "{filter:?} {name}: n_s {} n_t {} form {:?} {} it, {:.0} ms, rel residual {:.2e}",
                sol.n_s, sol.n_t, sol.form, sol.iterations, sol.solve_ms, sol.residual_relative
            );
        }
    }
}
