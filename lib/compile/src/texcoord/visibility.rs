//! A minimal triangle-identifier z-buffer (thesis 3.2: "rasterizing triangle identifiers
//! into a zbuffer to select visible triangles"), used by texture-coordinate optimization.
//! It samples pixel centres with a depth test on z/w; triangles crossing the near plane
//! (any vertex with w ≤ 0) are skipped. It is not the player's rasterizer model (that is
//! the hardware model's job, with the top-left rule); here only "which triangle is seen at
//! this pixel" and the texture-coordinate Jacobian there are needed.

use glam::{DMat2, DVec2, Vec2, Vec4};

/// One view of an object's mesh: clip-space vertex positions (wgpu convention: x, y in
/// [−w, w], z in [0, w], y up) on a `width × height` screen.
#[derive(Clone, Debug)]
pub struct ViewGeometry {
    pub clip: Vec<Vec4>,
    pub width: u32,
    pub height: u32,
}

/// The visible triangle at every pixel (`None` where the object is not seen).
#[derive(Clone, Debug)]
pub struct IdBuffer {
    pub width: u32,
    pub height: u32,
    pub ids: Vec<Option<u32>>,
}

/// A vertex in screen space: pixel coordinates (y down), depth z/w and 1/w.
#[derive(Clone, Copy, Debug)]
pub struct ScreenVertex {
    pub p: DVec2,
    pub depth: f64,
    pub inv_w: f64,
}

/// Projects a clip-space position to the screen; `None` behind the eye.
pub fn to_screen(c: Vec4, width: u32, height: u32) -> Option<ScreenVertex> {
    if c.w <= 1e-9 {
        return None;
    }
    let inv_w = 1.0 / c.w as f64;
    let (nx, ny) = (c.x as f64 * inv_w, c.y as f64 * inv_w);
    Some(ScreenVertex {
        p: DVec2::new((nx + 1.0) * 0.5 * width as f64, (1.0 - ny) * 0.5 * height as f64),
        depth: c.z as f64 * inv_w,
        inv_w,
    })
}

/// Rasterizes triangle identifiers with a depth test.
pub fn rasterize_ids(view: &ViewGeometry, indices: &[u32]) -> IdBuffer {
    let (w, h) = (view.width, view.height);
    let mut ids = vec![None; w as usize * h as usize];
    let mut depth = vec![f64::INFINITY; ids.len()];
    for (t, tri) in indices.chunks_exact(3).enumerate() {
        let Some(v) = screen_triangle(view, tri) else { continue };
        let (lo, hi) = (v[0].p.min(v[1].p).min(v[2].p), v[0].p.max(v[1].p).max(v[2].p));
        let x0 = (lo.x - 0.5).ceil().max(0.0) as i64;
        let x1 = ((hi.x - 0.5).floor() as i64).min(w as i64 - 1);
        let y0 = (lo.y - 0.5).ceil().max(0.0) as i64;
        let y1 = ((hi.y - 0.5).floor() as i64).min(h as i64 - 1);
        let area = edge(v[0].p, v[1].p, v[2].p);
        if area.abs() < 1e-12 {
            continue;
        }
        for y in y0..=y1 {
            for x in x0..=x1 {
                let p = DVec2::new(x as f64 + 0.5, y as f64 + 0.5);
                let l = [
                    edge(v[1].p, v[2].p, p) / area,
                    edge(v[2].p, v[0].p, p) / area,
                    edge(v[0].p, v[1].p, p) / area,
                ];
                if l.iter().any(|&l| l < 0.0) {
                    continue;
                }
                let z = l[0] * v[0].depth + l[1] * v[1].depth + l[2] * v[2].depth;
                let k = y as usize * w as usize + x as usize;
                if (0.0..=1.0).contains(&z) && z < depth[k] {
                    depth[k] = z;
                    ids[k] = Some(t as u32);
                }
            }
        }
    }
    IdBuffer { width: w, height: h, ids }
}

/// The triangle's three screen vertices, or `None` if any lies behind the eye or an index
/// is out of range.
pub fn screen_triangle(view: &ViewGeometry, tri: &[u32]) -> Option<[ScreenVertex; 3]> {
    let get =
        |i: u32| view.clip.get(i as usize).and_then(|&c| to_screen(c, view.width, view.height));
    Some([get(tri[0])?, get(tri[1])?, get(tri[2])?])
}

/// Twice the signed area of (a, b, p).
pub fn edge(a: DVec2, b: DVec2, p: DVec2) -> f64 {
    (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x)
}

/// ∂(u, v)/∂(x, y) at pixel point p of a triangle, with perspective-correct interpolation:
/// (u, v) = N/D with N = Σ λᵢ (u, v)ᵢ/wᵢ and D = Σ λᵢ/wᵢ, λ the screen barycentrics.
/// Columns are ∂/∂x and ∂/∂y.
pub fn uv_jacobian(v: &[ScreenVertex; 3], uv: [Vec2; 3], p: DVec2) -> Option<DMat2> {
    let area = edge(v[0].p, v[1].p, v[2].p);
    if area.abs() < 1e-12 {
        return None;
    }
    // λ and its constant gradient.
    let lam = [
        edge(v[1].p, v[2].p, p) / area,
        edge(v[2].p, v[0].p, p) / area,
        edge(v[0].p, v[1].p, p) / area,
    ];
    let grad = |a: DVec2, b: DVec2| DVec2::new(a.y - b.y, b.x - a.x) / area;
    let dl = [grad(v[1].p, v[2].p), grad(v[2].p, v[0].p), grad(v[0].p, v[1].p)];
    let mut n = DVec2::ZERO;
    let mut d = 0.0;
    let (mut dn_dx, mut dn_dy, mut dd) = (DVec2::ZERO, DVec2::ZERO, DVec2::ZERO);
    for i in 0..3 {
        let q = uv[i].as_dvec2() * v[i].inv_w;
        n += lam[i] * q;
        d += lam[i] * v[i].inv_w;
        dn_dx += dl[i].x * q;
        dn_dy += dl[i].y * q;
        dd += dl[i] * v[i].inv_w;
    }
    if d.abs() < 1e-300 {
        return None;
    }
    let col_x = (dn_dx * d - n * dd.x) / (d * d);
    let col_y = (dn_dy * d - n * dd.y) / (d * d);
    Some(DMat2::from_cols(col_x, col_y))
}
