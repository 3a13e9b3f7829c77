//! The display-filter resolve of multisampled frames (resolve.rs) through the frame
//! pipelines directly, with the ray-traced set's default filter (σ = 0.5 px, R = 1.5 px):
//! inside objects a frame keeps its single-sample values; at a straight edge of a flat
//! object over the empty background a pixel is the object's radiance times the filtered
//! coverage of the edge, to within the error of quadrature by the 36 samples of the pixel's
//! 3×3 neighbourhood.

mod common;

use common::*;
use pis_compile::{Address, Filter, Sampler, TextureLayout, Viewport};
use pis_format::DisplayFilter;
use pis_play::frame::resolve::SAMPLE_POSITIONS;
use pis_play::frame::{offscreen_format, FramePipelines, MeshGpu, NO_OBJECT};
use pis_play::multisample::choose;
use pis_play::textured::create_sampler;
use pis_play::{FloatImage, Gpu, ObjectTexture};

const SIZE: (u32, u32) = (80, 60);
const GAUSSIAN: DisplayFilter = DisplayFilter { sigma_px: 0.5, radius_px: 1.5 };

/// The GPU where it multisamples the offscreen format 4×, else `None` (fails in CI).
fn multisampling_gpu(test: &str) -> Option<Gpu> {
    let gpu = gpu_or_skip(test)?;
    let ms = choose(&gpu, 4, offscreen_format(&gpu));
    if ms.samples != 4 {
        assert!(std::env::var("CI").map_or(true, |v| v != "true"), "{test}: {ms:?}");
        eprintln!("{test}: skipped: {}", ms.note.unwrap_or_default());
        return None;
    }
    Some(gpu)
}

fn texture(gpu: &Gpu, rgba: &[f32]) -> ObjectTexture {
    let t = ObjectTexture::new(gpu, TextureLayout::new(16, 16, 1));
    t.upload(gpu, rgba).unwrap();
    t
}

/// frame_msaa.rs's scene (a quad turned 25° in front of a wider one, random textures)
/// resolved with the display filter: a pixel whose 3×3 neighbourhood's samples all lie on
/// one object keeps its single-sample value. Samples are not read back, so "all on one
/// object" is judged from pixel centres: where the 7×7 pixel centres around p are one
/// object, so is every sample of p's 3×3 neighbourhood (a sample lies within 1.5 px of p's
/// centre on each axis, and a polygon corner with an angle near 90° that reached it without
/// covering one of those 49 centres would have to be narrower than the centres' spacing).
/// On silhouettes the resolve reaches neighbouring pixels: coverage takes values the box
/// average of 4 samples cannot (other than multiples of ¼).
#[test]
fn display_filter_resolve_keeps_interiors_and_spreads_silhouettes() {
    let test = "display_filter_resolve_keeps_interiors_and_spreads_silhouettes";
    let Some(gpu) = multisampling_gpu(test) else { return };
    let mut pipes = FramePipelines::new(&gpu);
    let clip =
        camera(Viewport { width: SIZE.0, height: SIZE.1 }, [0.3, 0.4, 3.0], [0.0, 0.0, 0.0], 0.8);
    let back = quad(-1.6, 1.6, -1.2, 1.2, -0.5);
    let front = quad(-0.6, 0.6, -0.5, 0.5, 0.4);
    let turn = glam::Mat4::from_rotation_z(25f32.to_radians());
    let mesh = |m: &Mesh| MeshGpu::new(&gpu, &m.positions, None, &m.uvs, &m.indices);
    let scene = [
        (mesh(&back), clip, texture(&gpu, &random_rgba(256, 1))),
        (mesh(&front), clip * turn, texture(&gpu, &random_rgba(256, 2))),
    ];
    let sampler = create_sampler(
        &gpu,
        &Sampler { filter: Filter::Bilinear, address: [Address::ClampToEdge; 2] },
    );
    let (one, ids) = draw_scene(&gpu, &mut pipes, SIZE, 1, None, &scene, &sampler);
    let (box_, ids_box) = draw_scene(&gpu, &mut pipes, SIZE, 4, None, &scene, &sampler);
    let (filtered, ids_f) = draw_scene(&gpu, &mut pipes, SIZE, 4, Some(GAUSSIAN), &scene, &sampler);
    assert_eq!(ids, ids_f, "object indices at pixel centres");
    assert_eq!(ids, ids_box, "object indices at pixel centres");
    let (w, h) = (SIZE.0 as usize, SIZE.1 as usize);
    let quarter = |a: f32| ((a * 4.0).round() - a * 4.0).abs() < 1e-6;
    let (mut interior, mut exact, mut spread, mut box_quarters, mut same_as_box) =
        ([0usize; 2], 0usize, 0usize, true, 0usize);
    for y in 3..h - 3 {
        for x in 3..w - 3 {
            let p = y * w + x;
            let uniform = (0..49).all(|k| ids[(y + k / 7 - 3) * w + x + k % 7 - 3] == ids[p]);
            let px = |img: &FloatImage| [0, 1, 2, 3].map(|c| img.rgba[p * 4 + c]);
            box_quarters &= quarter(box_.rgba[p * 4 + 3]);
            if uniform && ids[p] != NO_OBJECT {
                interior[ids[p] as usize] += 1;
                // As frame_msaa.rs: on a quad's diagonal the other triangle interpolates
                // (s, t) at the centre with its own barycentrics, a rounding of ~2^-23 in
                // (s, t) times a texture changing by up to 1 per texel over 16 texels.
                let differ =
                    (0..4).map(|c| (px(&one)[c] - px(&filtered)[c]).abs()).fold(0.0, f32::max);
                assert!(
                    differ <= 1e-5,
                    "pixel ({x}, {y}) inside object {}: 1 sample {:?}, filtered {:?}",
                    ids[p],
                    px(&one),
                    px(&filtered)
                );
                exact += (px(&one) == px(&filtered)) as usize;
                same_as_box += (px(&box_) == px(&filtered)) as usize;
            }
            if !quarter(filtered.rgba[p * 4 + 3]) {
                spread += 1;
            }
        }
    }
    eprintln!("{test}: interior pixels {interior:?} ({exact} bit-identical, {same_as_box} as the box resolve's), {spread} pixels with filtered coverage off the box's quarters");
    assert!(box_quarters, "the box resolve's coverage is a multiple of 1/4");
    assert!(interior[0] > 200 && interior[1] > 200, "interior pixels per object: {interior:?}");
    // Multisampled rasterisation alone moves single-sample values by rounding (above); the
    // resolve itself adds nothing inside: where a pixel's 4 samples are equal it returns
    // their value as the box average does, bit for bit, and only where two triangles of a
    // quad shade its samples (on the diagonal, a few pixels) do the two averages round apart.
    let n = interior[0] + interior[1];
    assert!(same_as_box * 50 > n * 49, "{same_as_box} of {n} interior pixels as the box resolve's");
    // The front quad's outline against the empty background (the back quad fills the
    // rest): about 2·(80 + 60)·0.3 pixels of outline, and the Gaussian reaches about 3
    // pixels across it; every one of them has a coverage off the quarters.
    assert!(spread > 60, "{spread} pixels with filtered coverage");
}

/// The normalised, truncated Gaussian's mass on one side of a line at signed distance `t`
/// from the centre (positive: the centre inside): by radial symmetry the integral of the
/// filter's marginal m(x) = ∫ w(x, y) dy over |y| ≤ √(R² − x²), from −R to t, over its
/// integral from −R to R. Simpson's rule, 4000 intervals outside and 400 inside.
fn gaussian_edge_coverage(f: DisplayFilter, t: f64) -> f64 {
    let (s, r) = (f.sigma_px as f64, f.radius_px as f64);
    let simpson = |a: f64, b: f64, n: usize, g: &dyn Fn(f64) -> f64| {
        if b <= a {
            return 0.0;
        }
        let hh = (b - a) / n as f64;
        (0..=n)
            .map(|i| {
                g(a + i as f64 * hh)
                    * if i == 0 || i == n {
                        1.0
                    } else if i % 2 == 1 {
                        4.0
                    } else {
                        2.0
                    }
            })
            .sum::<f64>()
            * hh
            / 3.0
    };
    let marginal = |x: f64| {
        let half = (r * r - x * x).max(0.0).sqrt();
        simpson(-half, half, 400, &|y| (-(x * x + y * y) / (2.0 * s * s)).exp())
    };
    let whole = simpson(-r, r, 4000, &marginal);
    let n = ((t.clamp(-r, r) + r) / (2.0 * r) * 4000.0).ceil().max(2.0) as usize;
    simpson(-r, t.clamp(-r, r), n + n % 2, &marginal) / whole
}

/// The filter's mass over cell [x0, x0 + ½] × [y0, y0 + ½] (relative to the pixel's
/// centre), unnormalised: midpoint rule on 64 × 64 points.
fn cell_mass(f: DisplayFilter, x0: f64, y0: f64) -> f64 {
    let (s, r) = (f.sigma_px as f64, f.radius_px as f64);
    let n = 64;
    let hh = 0.5 / n as f64;
    let mut all = 0.0;
    for i in 0..n {
        for j in 0..n {
            let (x, y) = (x0 + (i as f64 + 0.5) * hh, y0 + (j as f64 + 0.5) * hh);
            if x * x + y * y <= r * r {
                all += (-(x * x + y * y) / (2.0 * s * s)).exp() * hh * hh;
            }
        }
    }
    all
}

/// A flat, uniformly coloured object over the empty background, its right edge the line
/// x = a + b·y in pixel coordinates (y down), slanted so that the edge crosses pixel centres
/// at every phase. Each pixel near the edge must be c · C(t), C the Gaussian edge coverage
/// at the centre's signed distance t (gaussian_edge_coverage), up to the quadrature error
/// of the 36 samples, bounded per pixel as follows. Partition the 3×3 pixels into 36 cells
/// of ½ × ½ px, each holding one sample s of the 4× pattern (one per quadrant of a pixel);
/// μ the normalised filter, w_s/W the sample's normalised weight. Then C = Σ_s μ(A_s ∩ H)
/// and the quadrature's coverage Q = Σ_{s ∈ H} w_s / W. Cells wholly outside H add 0 to
/// both; a cell wholly inside adds w_s/W − μ(A_s) to Q − C (I, their sum); a cell the edge
/// cuts adds a value in [0, w_s/W] to Q and one in [0, μ(A_s)] to C. So
///   I − Σ_cut μ(A_s) ≤ Q − C ≤ I + Σ_cut w_s/W,
/// and |Q − C| is at most the larger magnitude of the two ends. The masses μ are integrated numerically (midpoint rule, 64²
/// points per cell): at most the filter's value on the disc's boundary cells, 1e-3 in all,
/// is added for that. The frame's value is also exactly the quadrature's Q · c up to float
/// rounding (1e-5), which the box resolve (a multiple of ¼) is not.
#[test]
fn display_filter_resolve_matches_the_gaussian_coverage_of_an_edge() {
    let test = "display_filter_resolve_matches_the_gaussian_coverage_of_an_edge";
    let Some(gpu) = multisampling_gpu(test) else { return };
    let mut pipes = FramePipelines::new(&gpu);
    let (wf, hf) = (SIZE.0 as f64, SIZE.1 as f64);
    let (a, b) = (40.0137f64, 0.137f64);
    let edge_x = |y: f64| a + b * y;
    // Pixel coordinates → clip space (identity clip-from-object, z = ½).
    let ndc = |x: f64, y: f64| [(x / wf * 2.0 - 1.0) as f32, (1.0 - y / hf * 2.0) as f32, 0.5];
    let (top, bottom) = (-10.0, hf + 10.0);
    let shape = Mesh {
        positions: vec![
            ndc(-10.0, top),
            ndc(edge_x(top), top),
            ndc(edge_x(bottom), bottom),
            ndc(-10.0, bottom),
        ],
        uvs: vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]],
        indices: vec![0, 1, 2, 0, 2, 3],
    };
    let c = [0.8f32, 0.5, 0.25];
    let rgba: Vec<f32> = (0..256).flat_map(|_| [c[0], c[1], c[2], 1.0]).collect();
    let scene = [(
        MeshGpu::new(&gpu, &shape.positions, None, &shape.uvs, &shape.indices),
        glam::Mat4::IDENTITY,
        texture(&gpu, &rgba),
    )];
    let sampler = create_sampler(
        &gpu,
        &Sampler { filter: Filter::Bilinear, address: [Address::ClampToEdge; 2] },
    );
    let (img, _) = draw_scene(&gpu, &mut pipes, SIZE, 4, Some(GAUSSIAN), &scene, &sampler);
    let (sigma, r) = (GAUSSIAN.sigma_px as f64, GAUSSIAN.radius_px as f64);
    let weight = |dx: f64, dy: f64| {
        if dx * dx + dy * dy <= r * r {
            (-(dx * dx + dy * dy) / (2.0 * sigma * sigma)).exp()
        } else {
            0.0
        }
    };
    let norm = (1.0 + b * b).sqrt();
    let (w, h) = (SIZE.0 as usize, SIZE.1 as usize);
    let (mut tested, mut partial, mut skipped, mut worst, mut widest) =
        (0usize, 0usize, 0usize, 0.0f64, 0.0f64);
    let total_mass = cell_mass_total(GAUSSIAN);
    for y in 2..h - 2 {
        for x in 2..w - 2 {
            let (cx, cy) = (x as f64 + 0.5, y as f64 + 0.5);
            let t = (edge_x(cy) - cx) / norm;
            if t.abs() > r + 1.0 {
                continue;
            }
            // Relative to the centre: inside H when left of the edge.
            let inside = |dx: f64, dy: f64| cx + dx < edge_x(cy + dy);
            // The quadrature and the bound's terms, cell by cell.
            let (mut wall, mut win) = (0.0, 0.0);
            let mut ambiguous = false;
            let mut cells = Vec::with_capacity(36);
            for qy in -1..=1 {
                for qx in -1..=1 {
                    for [sx, sy] in SAMPLE_POSITIONS {
                        let (dx, dy) = (qx as f64 + sx as f64 - 0.5, qy as f64 + sy as f64 - 0.5);
                        let ws = weight(dx, dy);
                        wall += ws;
                        if inside(dx, dy) {
                            win += ws;
                        }
                        // The cell: the quadrant of pixel q holding the sample.
                        let (x0, y0) = (
                            qx as f64 - 0.5 + if sx > 0.5 { 0.5 } else { 0.0 },
                            qy as f64 - 0.5 + if sy > 0.5 { 0.5 } else { 0.0 },
                        );
                        cells.push((ws, x0, y0));
                        // Vertices snap to the rasteriser's sub-pixel grid (1/256 px in
                        // Vulkan): a sample that close to the edge may fall either side.
                        ambiguous |= (cx + dx - edge_x(cy + dy)).abs() < 0.01;
                    }
                }
            }
            if ambiguous {
                skipped += 1;
                continue;
            }
            let q = win / wall;
            let (mut inner, mut cut_w, mut cut_mu) = (0.0f64, 0.0f64, 0.0f64);
            for &(ws, x0, y0) in &cells {
                let corners = [(x0, y0), (x0 + 0.5, y0), (x0, y0 + 0.5), (x0 + 0.5, y0 + 0.5)]
                    .map(|(u, v)| inside(u, v));
                let mu = cell_mass(GAUSSIAN, x0, y0) / total_mass;
                if corners.iter().all(|&k| k) {
                    inner += ws / wall - mu;
                } else if corners.iter().any(|&k| k) {
                    cut_w += ws / wall;
                    cut_mu += mu;
                }
            }
            let bound = (inner - cut_mu).abs().max((inner + cut_w).abs()) + 1e-3;
            let exact = gaussian_edge_coverage(GAUSSIAN, t);
            let p = y * w + x;
            tested += 1;
            partial += (q > 0.0 && q < 1.0) as usize;
            for (ch, &cc) in c.iter().enumerate() {
                let got = img.rgba[p * 4 + ch] as f64;
                assert!(
                    (got - q * cc as f64).abs() <= 1e-5,
                    "pixel ({x}, {y}) channel {ch}: {got}, the 36-sample quadrature gives {}",
                    q * cc as f64
                );
                let err = (got - exact * cc as f64).abs();
                assert!(err <= bound * cc as f64 + 1e-5, "pixel ({x}, {y}) at t = {t:.3}: {got}, Gaussian coverage {exact:.4} × {cc} = {}, quadrature bound {bound:.4}", exact * cc as f64);
                worst = worst.max(err / cc as f64);
            }
            let alpha = img.rgba[p * 4 + 3] as f64;
            assert!((alpha - q).abs() <= 1e-5, "pixel ({x}, {y}): alpha {alpha}, coverage {q}");
            widest = widest.max(bound);
        }
    }
    eprintln!("{test}: {tested} pixels near the edge ({partial} partly covered, {skipped} with a sample on the edge skipped): coverage error at most {worst:.4}, bounds up to {widest:.4}");
    // About 2R + 2 pixels per row lie near the edge, 2R + 1 of them partly covered; a
    // sample within 0.01 px of the edge takes a row's pixels out about one time in six.
    assert!(
        tested >= (h - 4) * 3 && partial >= (h - 4) * 2,
        "{tested} tested, {partial} partly covered, {skipped} skipped"
    );
}

/// The filter's mass over the whole disc (the 36 cells cover [−1.5, 1.5]² ⊇ the disc).
fn cell_mass_total(f: DisplayFilter) -> f64 {
    let mut total = 0.0;
    for i in 0..6 {
        for j in 0..6 {
            total += cell_mass(f, -1.5 + 0.5 * i as f64, -1.5 + 0.5 * j as f64);
        }
    }
    total
}
