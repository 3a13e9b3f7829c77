//! Cube-map lookups (SPEC.md 8.2): face selection, face coordinates (s, t), the level of
//! detail from the lookup vector's screen derivatives, and the filter taps — bilinear per
//! level and trilinear between levels, with the texels a footprint reaches beyond a face's
//! edge read from the neighbouring face (seamless filtering).
//!
//! The player reads a cube map's texels itself (`textureLoad`), so every weight here is what
//! the GPU computes, on any adapter. WGSL twins in `lib/play/src/shell.wgsl`: `cube_face`,
//! `face_st`, `face_vector`, `cube_texel`, `beyond`, `bilinear_corner`, `cube_lod`,
//! `cube_bilinear`, and the lookup `cube_sample`.

use glam::DVec3;

use crate::filter::Taps;
use crate::lod::texture_lod;
use crate::TextureLayout;

/// The face of lookup vector `d` (0..6 = +X, −X, +Y, −Y, +Z, −Z): the axis of largest
/// magnitude, x before y before z on ties, positive when the component is ≥ 0.
pub fn cube_face(d: DVec3) -> u32 {
    let a = d.abs();
    if a.x >= a.y && a.x >= a.z {
        if d.x >= 0.0 {
            0
        } else {
            1
        }
    } else if a.y >= a.z {
        if d.y >= 0.0 {
            2
        } else {
            3
        }
    } else if d.z >= 0.0 {
        4
    } else {
        5
    }
}

/// (sc, tc, ma) of vector `v` on face `face` (SPEC.md 8.2's table), with ma signed so that
/// it is |ma| for vectors on the face: the face's coordinates are linear in `v`, which also
/// gives the derivatives of (sc, tc, |ma|).
pub fn face_components(face: u32, v: DVec3) -> [f64; 3] {
    match face {
        0 => [-v.z, -v.y, v.x],
        1 => [v.z, -v.y, -v.x],
        2 => [v.x, v.z, v.y],
        3 => [v.x, -v.z, -v.y],
        4 => [v.x, -v.y, v.z],
        _ => [-v.x, -v.y, -v.z],
    }
}

/// (s, t) ∈ [0, 1]² of `d` on face `face`: ((sc/|ma|) + 1)/2, ((tc/|ma|) + 1)/2.
pub fn face_st(face: u32, d: DVec3) -> [f64; 2] {
    let [sc, tc, ma] = face_components(face, d);
    [(sc / ma + 1.0) * 0.5, (tc / ma + 1.0) * 0.5]
}

/// The vector with |ma| = 1 and coordinates (sc, tc) on face `face`: the inverse of
/// [`face_components`].
pub fn face_vector(face: u32, sc: f64, tc: f64) -> DVec3 {
    match face {
        0 => DVec3::new(1.0, -tc, -sc),
        1 => DVec3::new(-1.0, -tc, sc),
        2 => DVec3::new(sc, 1.0, tc),
        3 => DVec3::new(sc, -1.0, -tc),
        4 => DVec3::new(sc, -tc, 1.0),
        _ => DVec3::new(-sc, -tc, -1.0),
    }
}

/// Whether texel coordinate `x` lies beyond an `n`-texel face.
pub fn beyond(x: i64, n: u32) -> bool {
    !(0..n as i64).contains(&x)
}

/// The bilinear weight (`wi[di] · wj[dj]`) of the footprint's texel beyond a corner (both
/// coordinates beyond the face) at (i0, j0), or 0 when none is.
pub fn bilinear_corner(i0: i64, j0: i64, n: u32, wi: [f64; 2], wj: [f64; 2]) -> f64 {
    let mut w = 0.0;
    for (dj, &w_j) in wj.iter().enumerate() {
        for (di, &w_i) in wi.iter().enumerate() {
            if beyond(i0 + di as i64, n) && beyond(j0 + dj as i64, n) {
                w = w_i * w_j;
            }
        }
    }
    w
}

/// The texel that texel (i, j) of an `n × n` level of face `face` names, (i, j) beyond at
/// most one edge: itself inside the face; else the texel of the neighbouring face that holds
/// the direction of its centre (the centre's (sc, tc) continue the face's plane; the
/// direction is re-projected).
pub fn cube_texel(face: u32, i: i64, j: i64, n: u32) -> (u32, u32, u32) {
    let n64 = n as i64;
    if (0..n64).contains(&i) && (0..n64).contains(&j) {
        return (face, i as u32, j as u32);
    }
    let nf = n as f64;
    let sc = 2.0 * (i as f64 + 0.5) / nf - 1.0;
    let tc = 2.0 * (j as f64 + 0.5) / nf - 1.0;
    let d = face_vector(face, sc, tc);
    let f2 = cube_face(d);
    let [s, t] = face_st(f2, d);
    let k = |x: f64| ((x * nf).floor() as i64).clamp(0, n64 - 1) as u32;
    (f2, k(s), k(t))
}

/// λ of a lookup with vector `d` and fine derivatives `ddx`, `ddy` of it: the derivatives of
/// (s, t) on `d`'s face by the quotient rule, ∂s = ½(∂sc·|ma| − sc·∂|ma|)/ma², then the
/// isotropic LOD of a `size`-texel face ([`texture_lod`]).
pub fn cube_lod(d: DVec3, ddx: DVec3, ddy: DVec3, size: f64, max_level: f64) -> f64 {
    let face = cube_face(d);
    let [sc, tc, ma] = face_components(face, d);
    let deriv = |dv: DVec3| {
        let [dsc, dtc, dma] = face_components(face, dv);
        [0.5 * (dsc * ma - sc * dma) / (ma * ma), 0.5 * (dtc * ma - tc * dma) / (ma * ma)]
    };
    texture_lod(deriv(ddx), deriv(ddy), [size, size], max_level)
}

/// Adds the bilinear taps of level `m` of lookup vector `d`, scaled by `scale`: the four
/// texels around (u, v), each [`cube_texel`]'s texel within the face or beyond one edge.
/// Beyond a corner, where three faces meet and no fourth texel exists, a texel is the mean
/// of the three meeting there (as Vulkan's seamless cube filtering does, which keeps lookups
/// continuous across corners); those are the footprint's other three, so the corner's
/// weight goes to them in thirds ([`bilinear_corner`]; at most one texel is beyond a corner).
pub fn cube_bilinear(layout: &TextureLayout, d: DVec3, m: u32, scale: f64, taps: &mut Taps) {
    let face = cube_face(d);
    let [s, t] = face_st(face, d);
    let (n, _) = layout.level_size(m);
    let u = s * n as f64 - 0.5;
    let v = t * n as f64 - 0.5;
    let (i0, j0) = (u.floor(), v.floor());
    let (a, b) = (u - i0, v - j0);
    let (i0, j0) = (i0 as i64, j0 as i64);
    let wi = [1.0 - a, a];
    let wj = [1.0 - b, b];
    let third = bilinear_corner(i0, j0, n, wi, wj) / 3.0;
    for (dj, &w_j) in wj.iter().enumerate() {
        for (di, &w_i) in wi.iter().enumerate() {
            let (i, j) = (i0 + di as i64, j0 + dj as i64);
            if beyond(i, n) && beyond(j, n) {
                continue;
            }
            let (f, ti, tj) = cube_texel(face, i, j, n);
            taps.add(layout.face_texel(f, m, ti, tj) as u32, scale * (w_i * w_j + third));
        }
    }
}

/// The taps of one trilinear lookup of vector `d` at level of detail λ (clamped to the
/// layout's levels): bilinear on levels ⌊λ⌋ and ⌊λ⌋ + 1, blended by frac(λ).
pub fn cube_taps(layout: &TextureLayout, d: DVec3, lambda: f64, taps: &mut Taps) {
    *taps = Taps::default();
    let q = layout.levels.saturating_sub(1);
    let l = lambda.clamp(0.0, q as f64);
    let hi = (l.floor() as u32).min(q);
    let lo = (hi + 1).min(q);
    let delta = l - hi as f64;
    cube_bilinear(layout, d, hi, 1.0 - delta, taps);
    if delta > 0.0 {
        cube_bilinear(layout, d, lo, delta, taps);
    }
}

/// The row of one pixel's k × k lookups (SPEC.md 8.2), merged by column and sorted: the
/// lookup at sub-pixel offset o = ((i + ½)/k − ½, (j + ½)/k − ½) along `direction(o_x, o_y)`
/// at the LOD of the derivatives `sx`, `sy` (the pixel's divided by k), each of weight 1/k².
pub fn footprint_row(
    layout: &TextureLayout,
    k: u32,
    (sx, sy): (DVec3, DVec3),
    direction: impl Fn(f64, f64) -> DVec3,
    taps: &mut Taps,
    row: &mut Vec<(u32, f32)>,
) {
    let kf = k as f64;
    let w = (1.0 / (kf * kf)) as f32;
    let max_level = layout.levels.saturating_sub(1) as f64;
    row.clear();
    for j in 0..k {
        let oy = (j as f64 + 0.5) / kf - 0.5;
        for i in 0..k {
            let ox = (i as f64 + 0.5) / kf - 0.5;
            let ds = direction(ox, oy);
            cube_taps(layout, ds, cube_lod(ds, sx, sy, layout.width as f64, max_level), taps);
            for (c, v) in taps.sorted() {
                match row.iter_mut().find(|e| e.0 == c) {
                    Some(e) => e.1 += v * w,
                    None => row.push((c, v * w)),
                }
            }
        }
    }
    row.sort_unstable_by_key(|e| e.0);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn faces_follow_the_spec_table() {
        assert_eq!(cube_face(DVec3::new(2.0, 1.0, -1.0)), 0);
        assert_eq!(cube_face(DVec3::new(-2.0, 1.0, -1.0)), 1);
        assert_eq!(cube_face(DVec3::new(0.1, 3.0, -1.0)), 2);
        assert_eq!(cube_face(DVec3::new(0.1, -3.0, -1.0)), 3);
        assert_eq!(cube_face(DVec3::new(0.1, 0.2, 1.0)), 4);
        assert_eq!(cube_face(DVec3::new(0.1, 0.2, -1.0)), 5);
        // +X: sc = −z, tc = −y.
        let st = face_st(0, DVec3::new(1.0, 0.5, -0.5));
        assert!((st[0] - 0.75).abs() < 1e-12 && (st[1] - 0.25).abs() < 1e-12);
    }

    #[test]
    fn face_vector_inverts_face_components() {
        for face in 0..6 {
            let v = face_vector(face, 0.3, -0.6);
            assert_eq!(cube_face(v), face);
            let [sc, tc, ma] = face_components(face, v);
            assert!(
                (sc - 0.3).abs() < 1e-12 && (tc + 0.6).abs() < 1e-12 && (ma - 1.0).abs() < 1e-12
            );
        }
    }

    #[test]
    fn texels_beyond_an_edge_come_from_the_adjacent_face() {
        let n = 8;
        for face in 0..6 {
            for j in 0..n as i64 {
                // The texel right of the last column is on a neighbouring face, on its edge,
                // and the edge texels of the two faces touch: their centres' directions are
                // within one texel of each other.
                let (f2, i2, j2) = cube_texel(face, n as i64, j, n);
                assert_ne!(f2, face);
                assert!(i2 == 0 || i2 == n - 1 || j2 == 0 || j2 == n - 1);
                let centre = |f: u32, i: u32, j: u32| {
                    face_vector(
                        f,
                        2.0 * (i as f64 + 0.5) / n as f64 - 1.0,
                        2.0 * (j as f64 + 0.5) / n as f64 - 1.0,
                    )
                    .normalize()
                };
                let a = centre(face, n - 1, j as u32);
                let b = centre(f2, i2, j2);
                assert!(
                    a.angle_between(b) < 2.5 * std::f64::consts::FRAC_PI_2 / n as f64,
                    "face {face} j {j}"
                );
            }
        }
    }

    #[test]
    fn bilinear_weights_sum_to_one_everywhere() {
        let layout = TextureLayout::cube(8);
        let mut taps = Taps::default();
        for k in 0..500 {
            let a = k as f64 * 0.731;
            let d = DVec3::new(a.cos(), (a * 1.7).sin(), (a * 0.3).cos() - 0.5);
            cube_taps(&layout, d, (k % 7) as f64 * 0.6, &mut taps);
            let sum: f32 = taps.weights[..taps.len].iter().sum();
            assert!((sum - 1.0).abs() < 1e-5);
            assert!(taps.cols[..taps.len].iter().all(|&c| (c as usize) < layout.texel_count()));
        }
    }

    /// Lookups are continuous across edges and corners: directions a hair apart on either
    /// side of a face boundary read the same value from a random cube map.
    #[test]
    fn lookups_are_continuous_across_edges_and_corners() {
        let layout = TextureLayout::cube(6);
        let x: Vec<f64> =
            (0..layout.texel_count()).map(|k| ((k * 7919) % 1013) as f64 / 1013.0).collect();
        let value = |d: DVec3, lambda: f64| {
            let mut taps = Taps::default();
            cube_taps(&layout, d, lambda, &mut taps);
            (0..taps.len).map(|k| taps.weights[k] as f64 * x[taps.cols[k] as usize]).sum::<f64>()
        };
        let e = 1e-9;
        for lambda in [0.0, 0.5, 1.7] {
            for (a, b) in [
                // Edge +X | +Z, a corner +X | +Y | +Z, and an edge −Y | −Z.
                (DVec3::new(1.0, 0.3, 1.0 - e), DVec3::new(1.0 - e, 0.3, 1.0)),
                (DVec3::new(1.0, 1.0 - e, 1.0 - e), DVec3::new(1.0 - e, 1.0, 1.0 - e)),
                (DVec3::new(1.0 - e, 1.0 - e, 1.0), DVec3::new(1.0 - e, 1.0, 1.0 - e)),
                (DVec3::new(-0.2, -1.0, -1.0 + e), DVec3::new(-0.2, -1.0 + e, -1.0)),
            ] {
                assert_ne!(cube_face(a), cube_face(b));
                assert!((value(a, lambda) - value(b, lambda)).abs() < 1e-6, "{a} {b} λ {lambda}");
            }
        }
    }

    /// Beyond a corner the footprint's fourth texel is the mean of the three meeting there
    /// (clamped, and beyond either edge): spreading its weight over the footprint's other
    /// three in thirds gives the same taps, at every corner of every face and level.
    #[test]
    fn a_corner_texel_is_the_mean_of_the_three_meeting_there() {
        let layout = TextureLayout::cube(5);
        for face in 0..6 {
            for m in 0..layout.levels {
                let (n, _) = layout.level_size(m);
                let nf = n as f64;
                // Directions at the four corners of the face, a quarter texel inside.
                for (sc, tc) in [(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0)] {
                    let q = 1.0 - 0.5 / nf;
                    let d = face_vector(face, sc * q, tc * q);
                    let mut taps = Taps::default();
                    cube_bilinear(&layout, d, m, 1.0, &mut taps);
                    // The same footprint with the corner texel as three thirds.
                    let [s, t] = face_st(cube_face(d), d);
                    let (u, v) = (s * nf - 0.5, t * nf - 0.5);
                    let (i0, j0) = (u.floor() as i64, v.floor() as i64);
                    let (a, b) = (u - u.floor(), v - v.floor());
                    let mut want = Taps::default();
                    let mut corners = 0;
                    for dj in 0..2 {
                        for di in 0..2 {
                            let (i, j) = (i0 + di, j0 + dj);
                            let w = [1.0 - a, a][di as usize] * [1.0 - b, b][dj as usize];
                            let texels = if beyond(i, n) && beyond(j, n) {
                                corners += 1;
                                let (ci, cj) = (i.clamp(0, n as i64 - 1), j.clamp(0, n as i64 - 1));
                                vec![
                                    (cube_texel(cube_face(d), ci, cj, n), w / 3.0),
                                    (cube_texel(cube_face(d), i, cj, n), w / 3.0),
                                    (cube_texel(cube_face(d), ci, j, n), w / 3.0),
                                ]
                            } else {
                                vec![(cube_texel(cube_face(d), i, j, n), w)]
                            };
                            for ((f, ti, tj), w) in texels {
                                want.add(layout.face_texel(f, m, ti, tj) as u32, w);
                            }
                        }
                    }
                    assert_eq!(corners, 1, "face {face} level {m} corner ({sc}, {tc})");
                    let got: Vec<(u32, f32)> = taps.sorted().collect();
                    let exp: Vec<(u32, f32)> = want.sorted().collect();
                    assert_eq!(got.len(), 3);
                    assert_eq!(
                        got.iter().map(|t| t.0).collect::<Vec<_>>(),
                        exp.iter().map(|t| t.0).collect::<Vec<_>>()
                    );
                    for (g, e) in got.iter().zip(&exp) {
                        assert!(
                            (g.1 - e.1).abs() < 1e-6,
                            "face {face} level {m}: {got:?} against {exp:?}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn one_texel_per_pixel_is_level_zero_and_two_is_level_one() {
        // At the centre of +Z, s = (x + 1)/2: ∂s/∂x = ½ ∂(d.x).
        let d = DVec3::Z;
        let l0 = cube_lod(
            d,
            DVec3::new(2.0 / 64.0, 0.0, 0.0),
            DVec3::new(0.0, 2.0 / 64.0, 0.0),
            64.0,
            6.0,
        );
        let l1 = cube_lod(
            d,
            DVec3::new(4.0 / 64.0, 0.0, 0.0),
            DVec3::new(0.0, 2.0 / 64.0, 0.0),
            64.0,
            6.0,
        );
        assert!(l0.abs() < 1e-9 && (l1 - 1.0).abs() < 1e-9);
    }
}
