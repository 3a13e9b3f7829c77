//! Cube maps as the shells' lookups read them (shell.wgsl `cube_bilinear`): each face one
//! image holding every MIP level with a one-texel border, so that a bilinear lookup is four
//! plain loads with no seam to handle.
//!
//! Level m of a face (n_m = `mip_size(N, m)` texels a side) lies at [`CubeAtlas::origin`]
//! as (n_m + 2)² texels: level 0 at the top left, the coarser levels below one another to
//! its right. Inside, the level's texels; beyond one edge, the neighbouring face's texel
//! that pis-compile's `cube_texel` names; beyond a corner, the mean of the three texels that
//! meet there ([`sources`]). Those are the texels and weights of the hardware model's
//! seamless lookup (`cube_bilinear` in pis-compile's shell/cube.rs), whose corner weight goes
//! to the other three in thirds. The borders are written on the CPU
//! ([`CubeAtlas::fill_borders`]: cube maps rebuilt on the decoding threads or uploaded as
//! texels) or by a compute pass (cube_border.rs: cube maps rebuilt on the GPU) from the same
//! sources ([`CubeAtlas::border_map`]). A depth shell's depth cube (one level, one channel)
//! takes the same border (shell.rs `bordered_depth_faces`).

use pis_compile::shell::cube::cube_texel;
use pis_compile::TextureLayout;

/// The side of level `m` of an `n`-texel face: ⌈n / 2^m⌉.
pub(crate) fn level_side(n: u32, m: u32) -> u32 {
    pis_format::mip::mip_size(n, n, m).0
}

/// Where the levels of a cube map's faces lie in their atlas images.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CubeAtlas {
    /// The finest level's face size N and the level count.
    pub size: u32,
    pub levels: u32,
    /// Each face's atlas image.
    pub width: u32,
    pub height: u32,
}

/// A bordered texel's sources on its level: one texel (`count` 1) or three (a corner).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Sources {
    pub texels: [(u32, u32, u32); 3],
    pub count: u32,
}

impl CubeAtlas {
    /// The atlas of a cube map of `layout` (six square faces).
    pub fn of(layout: &TextureLayout) -> CubeAtlas {
        let (size, levels) = (layout.width, layout.levels.max(1));
        let right = if levels > 1 { level_side(size, 1) + 2 } else { 0 };
        let below: u32 = (1..levels).map(|m| level_side(size, m) + 2).sum();
        CubeAtlas { size, levels, width: size + 2 + right, height: (size + 2).max(below) }
    }

    /// The top-left texel of level `m`'s bordered face (the twin of shell.wgsl's
    /// `atlas_origin`).
    pub fn origin(&self, m: u32) -> (u32, u32) {
        if m == 0 {
            return (0, 0);
        }
        (self.size + 2, (1..m).map(|k| level_side(self.size, k) + 2).sum())
    }

    /// The largest texture side a cube map of this atlas takes: its atlas images, or the
    /// power-of-two levels the GPU's rebuild writes before the borders.
    pub fn largest_side(&self) -> u32 {
        self.width.max(self.height).max(self.size.next_power_of_two())
    }

    /// Texels of one face's atlas image.
    pub fn face_texels(&self) -> usize {
        self.width as usize * self.height as usize
    }

    /// The index in a face's atlas image of texel (i, j) of level `m`, (i, j) in [−1, n_m]²
    /// (the border included).
    pub fn texel(&self, m: u32, i: i64, j: i64) -> usize {
        let (ox, oy) = self.origin(m);
        (oy as i64 + j + 1) as usize * self.width as usize + (ox as i64 + i + 1) as usize
    }

    /// The atlas images of the cube map `rgba` (RGBA texels in `layout`'s order, face after
    /// face, each face's levels in order): RGBA, face after face, rows from the top, texels
    /// no level uses zero.
    pub fn border(&self, layout: &TextureLayout, rgba: &[f32]) -> Vec<f32> {
        let mut out = vec![0.0f32; 6 * self.face_texels() * 4];
        for (face, atlas) in out.chunks_exact_mut(self.face_texels() * 4).enumerate() {
            for m in 0..self.levels {
                let n = level_side(self.size, m) as usize;
                let level = layout.face_offset(face as u32) + layout.level_offset(m);
                let inside = &rgba[level * 4..][..n * n * 4];
                for (j, row) in inside.chunks_exact(n * 4).enumerate() {
                    let at = self.texel(m, 0, j as i64) * 4;
                    atlas[at..at + row.len()].copy_from_slice(row);
                }
            }
        }
        self.fill_borders(&mut out);
        out
    }

    /// Writes the borders of the atlas images `texels` (RGBA, face after face) from their
    /// levels' insides.
    pub fn fill_borders(&self, texels: &mut [f32]) {
        let face_len = self.face_texels();
        let at = |f: u32, m: u32, i: i64, j: i64| (f as usize * face_len + self.texel(m, i, j)) * 4;
        for (m, face, (i, j), s) in self.ring() {
            let texel = |(f, i, j): (u32, u32, u32)| {
                let k = at(f, m, i as i64, j as i64);
                [texels[k], texels[k + 1], texels[k + 2], texels[k + 3]]
            };
            let mut c = texel(s.texels[0]);
            if s.count == 3 {
                let (b, d) = (texel(s.texels[1]), texel(s.texels[2]));
                c = std::array::from_fn(|k| (c[k] + b[k] + d[k]) / 3.0);
            }
            let k = at(face, m, i, j);
            texels[k..k + 4].copy_from_slice(&c);
        }
    }

    /// Every border texel, level after level, face after face, in [`border_texel`]'s order:
    /// its level, face, (i, j) and sources.
    fn ring(&self) -> impl Iterator<Item = (u32, u32, (i64, i64), Sources)> + '_ {
        (0..self.levels).flat_map(move |m| {
            let n = level_side(self.size, m);
            (0..6).flat_map(move |face| {
                (0..4 * n + 4).map(move |t| {
                    let (i, j) = border_texel(t, n);
                    (m, face, (i, j), sources(face, i, j, n))
                })
            })
        })
    }

    /// The cube map's texels in `layout`'s order from its atlas images (as
    /// [`Self::border`] makes them): each level's inside.
    pub fn interior(&self, layout: &TextureLayout, atlas: &[f32]) -> Vec<f32> {
        let mut out = Vec::with_capacity(layout.texel_count() * 4);
        for image in atlas.chunks_exact(self.face_texels() * 4) {
            for m in 0..self.levels {
                let n = level_side(self.size, m) as usize;
                for j in 0..n {
                    let at = self.texel(m, 0, j as i64) * 4;
                    out.extend_from_slice(&image[at..at + n * 4]);
                }
            }
        }
        out
    }

    /// The sources of every border texel, level after level, face after face, in
    /// [`border_texel`]'s order: three packed texels (face << 28 | j << 14 | i) and their
    /// count, what cube_border.rs's pass reads.
    pub fn border_map(&self) -> Vec<[u32; 4]> {
        let pack = |(f, i, j): (u32, u32, u32)| f << 28 | j << 14 | i;
        self.ring()
            .map(|(.., s)| [pack(s.texels[0]), pack(s.texels[1]), pack(s.texels[2]), s.count])
            .collect()
    }
}

/// Border texel `t` of an `n`-texel level, (i, j) in [−1, n]² with one of them beyond the
/// level: the row above (t < n + 2), the row below, then the left and right columns (the
/// inverse of the border pass's `border_index`).
pub fn border_texel(t: u32, n: u32) -> (i64, i64) {
    let (t, n) = (t as i64, n as i64);
    if t < n + 2 {
        (t - 1, -1)
    } else if t < 2 * (n + 2) {
        (t - (n + 2) - 1, n)
    } else if t < 2 * (n + 2) + n {
        (-1, t - 2 * (n + 2))
    } else {
        (n, t - 2 * (n + 2) - n)
    }
}

/// What the bordered texel (i, j) of an `n`-texel level of `face` holds: itself inside;
/// [`cube_texel`]'s texel beyond one edge; beyond a corner, the three texels meeting there.
pub fn sources(face: u32, i: i64, j: i64, n: u32) -> Sources {
    let last = n as i64 - 1;
    let (ci, cj) = (i.clamp(0, last), j.clamp(0, last));
    if i == ci || j == cj {
        let t = cube_texel(face, i, j, n);
        return Sources { texels: [t; 3], count: 1 };
    }
    let texels =
        [cube_texel(face, ci, cj, n), cube_texel(face, i, cj, n), cube_texel(face, ci, j, n)];
    Sources { texels, count: 3 }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use glam::DVec3;
    use pis_compile::filter::Taps;
    use pis_compile::shell::cube::{cube_bilinear, cube_face, face_st};

    /// A lattice of nonzero directions over about [−1, 1]³: every face's interior, its
    /// edges (two equal coordinates) and the cube's corners.
    pub(crate) fn direction_lattice() -> impl Iterator<Item = DVec3> {
        let axis = |k: i32| k as f64 / 10.0 + 0.013 * (k % 3) as f64;
        (-10..=10)
            .flat_map(|x| (-10..=10).flat_map(move |y| (-10..=10).map(move |z| (x, y, z))))
            .map(move |(x, y, z)| DVec3::new(axis(x), axis(y), axis(z)))
            .filter(|d| *d != DVec3::ZERO)
    }

    /// shell.wgsl's `cube_bilinear` on the atlas images, in f64: level m's four texels
    /// around (u, v), one texel in from the level's origin.
    fn atlas_bilinear(a: &CubeAtlas, atlas: &[f32], d: DVec3, m: u32) -> [f64; 4] {
        let face = cube_face(d) as usize;
        let [s, t] = face_st(face as u32, d);
        let n = level_side(a.size, m) as f64;
        let (u, v) = (s * n - 0.5, t * n - 0.5);
        let (wa, wb) = (u - u.floor(), v - v.floor());
        let (ox, oy) = a.origin(m);
        let i = (u.floor() + 1.0) as usize + ox as usize;
        let j = (v.floor() + 1.0) as usize + oy as usize;
        let w = a.width as usize;
        let at = |i: usize, j: usize, c: usize| {
            atlas[((face * a.height as usize + j) * w + i) * 4 + c] as f64
        };
        std::array::from_fn(|c| {
            (1.0 - wa) * (1.0 - wb) * at(i, j, c)
                + wa * (1.0 - wb) * at(i + 1, j, c)
                + (1.0 - wa) * wb * at(i, j + 1, c)
                + wa * wb * at(i + 1, j + 1, c)
        })
    }

    #[test]
    fn an_atlas_filters_as_the_seamless_lookup_at_every_level() {
        let layout = TextureLayout::cube(7);
        let rgba: Vec<f32> =
            (0..layout.texel_count() * 4).map(|k| 1.0 + ((k * 37) % 101) as f32).collect();
        let a = CubeAtlas::of(&layout);
        let atlas = a.border(&layout, &rgba);
        for d in direction_lattice() {
            for m in 0..layout.levels {
                let mut taps = Taps::default();
                cube_bilinear(&layout, d, m, 1.0, &mut taps);
                let got = atlas_bilinear(&a, &atlas, d, m);
                for (c, got) in got.into_iter().enumerate() {
                    let want: f64 = (0..taps.len)
                        .map(|k| {
                            taps.weights[k] as f64 * rgba[taps.cols[k] as usize * 4 + c] as f64
                        })
                        .sum();
                    assert!(
                        (want - got).abs() <= 1e-5 * want,
                        "{d} level {m}: {want} against {got}"
                    );
                }
            }
        }
    }

    #[test]
    fn levels_lie_apart_inside_the_atlas() {
        for size in [1u32, 2, 3, 5, 16, 17, 100, 256] {
            let layout = TextureLayout::cube(size);
            let a = CubeAtlas::of(&layout);
            let boxes: Vec<_> = (0..a.levels)
                .map(|m| {
                    let (x, y) = a.origin(m);
                    (x, y, level_side(size, m) + 2)
                })
                .collect();
            for (k, &(x, y, s)) in boxes.iter().enumerate() {
                assert!(x + s <= a.width && y + s <= a.height, "size {size} level {k}");
                for &(x2, y2, s2) in &boxes[k + 1..] {
                    let apart = x + s <= x2 || x2 + s2 <= x || y + s <= y2 || y2 + s2 <= y;
                    assert!(apart, "size {size}: level {k} overlaps another");
                }
            }
        }
    }

    #[test]
    fn border_texels_walk_the_ring_once() {
        for n in [1u32, 2, 7] {
            let mut seen: Vec<_> = (0..4 * n + 4).map(|t| border_texel(t, n)).collect();
            let ring = seen.len();
            seen.sort();
            seen.dedup();
            assert_eq!(seen.len(), ring);
            let beyond = |x: i64| x < 0 || x >= n as i64;
            assert!(seen.iter().all(|&(i, j)| (-1..=n as i64).contains(&i)
                && (-1..=n as i64).contains(&j)
                && (beyond(i) || beyond(j))));
        }
    }

    #[test]
    fn the_interior_of_a_bordered_cube_is_the_cube() {
        let layout = TextureLayout::cube(6);
        let rgba: Vec<f32> = (0..layout.texel_count() * 4).map(|k| k as f32 * 0.25).collect();
        let a = CubeAtlas::of(&layout);
        assert_eq!(a.interior(&layout, &a.border(&layout, &rgba)), rgba);
    }
}
