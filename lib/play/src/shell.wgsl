// Environment-map shells (SPEC.md 7.3, 8.2): the lookup of one shell's cube map from a
// surface point. One function written twice: every function here has a twin of the same
// name in pis-compile's hardware model, with the same order of operations (reflect_about,
// shell_hit, lookup_direction, fresnel: shell/geometry.rs; depth_distance, depth_hit:
// shell/depth.rs; cube_face, face_components, face_st, cube_lod, cube_bilinear,
// cube_sample: shell/cube.rs; atlas_origin: the player's cube_atlas.rs). Change both
// together. texture_lod.wgsl is prepended to this source (shell.rs), and pipelines append
// their entry points to it.
//
// A cube map is a 2D array texture of six layers (+X, −X, +Y, −Y, +Z, −Z), each one face's
// MIP levels with one-texel borders side by side (cube_atlas.rs); texels are read with
// textureLoad and filtered here, so the weights are the model's on every adapter. The
// borders hold what the model's cube_texel names beyond a face, so the lookups need no
// seam logic (the model's cube_texel, beyond and bilinear_corner have no twin here).

// The code a pipeline carries (pipeline-overridable constants, `ShellCode` in shell.rs): a
// pipeline whose draws hold no depth shell is compiled with DEPTH_SHELLS false, one whose
// shells take one lookup per pixel side with SUB_PIXEL_LOOKUPS false, and the march or the
// sub-pixel loop is then not in its code at all. The lookups are the same either way; the
// defaults keep every path.
override DEPTH_SHELLS: bool = true;
override SUB_PIXEL_LOOKUPS: bool = true;

// One shell: origin; shape 1 sphere (a.x radius), 2 ellipsoid (a radii), 3 box (a min,
// b max corner, world space), 4 cylinder (a.x radius, a.y y min, a.z y max), 6 depth
// (a.x the depth cube's face size, a.y march steps, a.z far distance). A depth shell's
// depth cube is the `depth` texture the lookups take (one level, each face with a one-texel
// border, distance in x); other shapes ignore it.
struct ShellGeometry {
    origin: vec3<f32>,
    shape: u32,
    a: vec3<f32>,
    b: vec3<f32>,
};

// The mirror reflection of v about the unit normal n: v − 2(v·n)n.
fn reflect_about(v: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    return v - n * (2.0 * dot(v, n));
}

// The larger root of a·t² + 2b·t + c = 0, or −1.
fn quadratic_far(a: f32, b: f32, c: f32) -> f32 {
    let disc = b * b - a * c;
    if (a <= 0.0 || disc < 0.0) {
        return -1.0;
    }
    return (-b + sqrt(disc)) / a;
}

// The interval of t where q + t·r lies in [lo, hi] along one axis (empty: x > y).
fn slab(q: f32, r: f32, lo: f32, hi: f32) -> vec2<f32> {
    if (r == 0.0) {
        if (q >= lo && q <= hi) {
            return vec2<f32>(-3.0e38, 3.0e38);
        }
        return vec2<f32>(3.0e38, -3.0e38);
    }
    let t0 = (lo - q) / r;
    let t1 = (hi - q) / r;
    return vec2<f32>(min(t0, t1), max(t0, t1));
}

// Regula-falsi iterations after a depth shell's march finds a step behind its surface.
const DEPTH_REFINE: u32 = 4u;

// The distance of depth cube `depth` (face size n, stored with a one-texel border: shell.rs
// `bordered_depth_faces`) in direction q (not normalized): cube_bilinear's seamless lookup,
// a depth cube being a cube map's atlas of one level.
fn depth_distance(depth: texture_2d_array<f32>, n: u32, q: vec3<f32>) -> f32 {
    return cube_bilinear(depth, n, q, 0u).x;
}

// f(t) = |q0 + t·r| − D(q0 + t·r): negative in front of a depth shell, ≥ 0 behind it.
fn depth_behind(g: ShellGeometry, depth: texture_2d_array<f32>, q0: vec3<f32>, r: vec3<f32>, t: f32) -> f32 {
    let q = q0 + r * t;
    return length(q) - depth_distance(depth, u32(g.a.x), q);
}

// Where p + t·r meets the depth shell: the first of the steps t_i = t_end·(i/steps)² with
// f ≥ 0 (t_end on the far sphere), DEPTH_REFINE regula-falsi steps, the last bracket's
// secant root; 0 where f(0) ≥ 0, −1 where p lies outside the far sphere.
fn depth_hit(g: ShellGeometry, depth: texture_2d_array<f32>, p: vec3<f32>, r: vec3<f32>) -> f32 {
    let q0 = p - g.origin;
    let far = g.a.z;
    let steps = u32(g.a.y);
    let t_end = quadratic_far(dot(r, r), dot(q0, r), dot(q0, q0) - far * far);
    if (t_end < 0.0) {
        return -1.0;
    }
    var t0 = 0.0;
    var f0 = depth_behind(g, depth, q0, r, 0.0);
    if (f0 >= 0.0) {
        return 0.0;
    }
    var t1 = t_end;
    var f1 = 0.0;
    for (var i = 1u; i <= steps; i = i + 1u) {
        let s = f32(i) / f32(steps);
        let t = t_end * s * s;
        let ft = depth_behind(g, depth, q0, r, t);
        if (ft >= 0.0) {
            t1 = t;
            f1 = ft;
            break;
        }
        t0 = t;
        f0 = ft;
    }
    for (var k = 0u; k < DEPTH_REFINE; k = k + 1u) {
        let tm = t0 + (t1 - t0) * f0 / (f0 - f1);
        let fm = depth_behind(g, depth, q0, r, tm);
        if (fm >= 0.0) {
            t1 = tm;
            f1 = fm;
        } else {
            t0 = tm;
            f0 = fm;
        }
    }
    return t0 + (t1 - t0) * f0 / (f0 - f1);
}

// The far intersection (largest t ≥ 0) of p + t·r with the shell, or a negative value.
fn shell_hit(g: ShellGeometry, depth: texture_2d_array<f32>, p: vec3<f32>, r: vec3<f32>) -> f32 {
    let q = p - g.origin;
    if (DEPTH_SHELLS && g.shape == 6u) {
        return depth_hit(g, depth, p, r);
    }
    if (g.shape == 1u) {
        return quadratic_far(dot(r, r), dot(q, r), dot(q, q) - g.a.x * g.a.x);
    }
    if (g.shape == 2u) {
        let qs = q / g.a;
        let rs = r / g.a;
        return quadratic_far(dot(rs, rs), dot(qs, rs), dot(qs, qs) - 1.0);
    }
    if (g.shape == 3u) {
        let lo = g.a - g.origin;
        let hi = g.b - g.origin;
        var near = -3.0e38;
        var far = 3.0e38;
        for (var k = 0; k < 3; k = k + 1) {
            let s = slab(q[k], r[k], lo[k], hi[k]);
            near = max(near, s.x);
            far = min(far, s.y);
        }
        if (near <= far) {
            return far;
        }
        return -1.0;
    }
    // Cylinder.
    let a = r.x * r.x + r.z * r.z;
    let b = q.x * r.x + q.z * r.z;
    let c = q.x * q.x + q.z * q.z - g.a.x * g.a.x;
    var near = -3.0e38;
    var far = 3.0e38;
    if (a > 0.0) {
        let disc = b * b - a * c;
        if (disc < 0.0) {
            return -1.0;
        }
        let s = sqrt(disc);
        near = (-b - s) / a;
        far = (-b + s) / a;
    } else if (c > 0.0) {
        return -1.0;
    }
    let sy = slab(q.y, r.y, g.a.y - g.origin.y, g.a.z - g.origin.y);
    near = max(near, sy.x);
    far = min(far, sy.y);
    if (near <= far) {
        return far;
    }
    return -1.0;
}

// The cube-map lookup vector of surface point p with interpolated normal `normal` seen from
// `eye`: the far hit of the reflection ray on the shell minus its origin, or the ray's
// direction where it does not meet the shell.
fn lookup_direction(g: ShellGeometry, depth: texture_2d_array<f32>, p: vec3<f32>, normal: vec3<f32>, eye: vec3<f32>) -> vec3<f32> {
    let n = normalize(normal);
    let v = normalize(p - eye);
    let r = reflect_about(v, n);
    let t = shell_hit(g, depth, p, r);
    if (t >= 0.0) {
        return p + r * t - g.origin;
    }
    return r;
}

// Schlick's Fresnel factor: F0 + (1 − F0)(1 − cos θ)⁵, cos θ = clamp(−V·N, 0, 1).
fn fresnel(f0: vec3<f32>, p: vec3<f32>, normal: vec3<f32>, eye: vec3<f32>) -> vec3<f32> {
    let n = normalize(normal);
    let v = normalize(p - eye);
    let c = clamp(-dot(v, n), 0.0, 1.0);
    let k = pow(1.0 - c, 5.0);
    return f0 + (vec3<f32>(1.0) - f0) * k;
}

// The face of d: the axis of largest magnitude, x before y before z on ties.
fn cube_face(d: vec3<f32>) -> u32 {
    let a = abs(d);
    if (a.x >= a.y && a.x >= a.z) {
        return select(1u, 0u, d.x >= 0.0);
    }
    if (a.y >= a.z) {
        return select(3u, 2u, d.y >= 0.0);
    }
    return select(5u, 4u, d.z >= 0.0);
}

// (sc, tc, ma) of v on `face` (SPEC.md 8.2), ma signed: |ma| for vectors on the face.
fn face_components(face: u32, v: vec3<f32>) -> vec3<f32> {
    switch face {
        case 0u: { return vec3<f32>(-v.z, -v.y, v.x); }
        case 1u: { return vec3<f32>(v.z, -v.y, -v.x); }
        case 2u: { return vec3<f32>(v.x, v.z, v.y); }
        case 3u: { return vec3<f32>(v.x, -v.z, -v.y); }
        case 4u: { return vec3<f32>(v.x, -v.y, v.z); }
        default: { return vec3<f32>(-v.x, -v.y, -v.z); }
    }
}

// (s, t) of d on `face`.
fn face_st(face: u32, d: vec3<f32>) -> vec2<f32> {
    let c = face_components(face, d);
    return vec2<f32>((c.x / c.z + 1.0) * 0.5, (c.y / c.z + 1.0) * 0.5);
}

// λ of a lookup with vector d and fine derivatives ddx, ddy: (s, t)'s derivatives on d's
// face by the quotient rule, then the isotropic LOD of a `size`-texel face.
fn cube_lod(d: vec3<f32>, ddx: vec3<f32>, ddy: vec3<f32>, size: f32, max_level: f32) -> f32 {
    let face = cube_face(d);
    let c = face_components(face, d);
    let cx = face_components(face, ddx);
    let cy = face_components(face, ddy);
    let m2 = c.z * c.z;
    let dx = vec2<f32>(0.5 * (cx.x * c.z - c.x * cx.z) / m2, 0.5 * (cx.y * c.z - c.y * cx.z) / m2);
    let dy = vec2<f32>(0.5 * (cy.x * c.z - c.x * cy.z) / m2, 0.5 * (cy.y * c.z - c.y * cy.z) / m2);
    return texture_lod(dx, dy, vec2<f32>(size, size), max_level);
}

// The top-left texel of level m's bordered face in a cube map's atlas (cube_atlas.rs
// `CubeAtlas::origin`): level 0 at the top left, the coarser levels below one another to
// its right.
fn atlas_origin(size: u32, m: u32) -> vec2<i32> {
    if (m == 0u) {
        return vec2<i32>(0);
    }
    var y = 0u;
    for (var k = 1u; k < m; k = k + 1u) {
        y = y + ((size + (1u << k) - 1u) >> k) + 2u;
    }
    return vec2<i32>(i32(size + 2u), i32(y));
}

// Bilinear lookup of level m of cube map `cube` (face size `size`) with vector d: the four
// texels around (u, v) of the level's bordered face (cube_atlas.rs). Beyond an edge the
// border holds the texel cube_texel names; beyond a corner, where three faces meet and no
// fourth texel exists, the mean of the three meeting there, which are the footprint's other
// three: the model's seamless lookup, which gives the corner's weight to them in thirds
// (bilinear_corner), with the same four texels and weights.
fn cube_bilinear(cube: texture_2d_array<f32>, size: u32, d: vec3<f32>, m: u32) -> vec4<f32> {
    let face = cube_face(d);
    let st = face_st(face, d);
    let n = (size + (1u << m) - 1u) >> m;
    let u = st.x * f32(n) - 0.5;
    let v = st.y * f32(n) - 0.5;
    let i0 = floor(u);
    let j0 = floor(v);
    let a = u - i0;
    let b = v - j0;
    let at = atlas_origin(size, m) + vec2<i32>(i32(i0) + 1, i32(j0) + 1);
    let f = i32(face);
    var acc = ((1.0 - a) * (1.0 - b)) * textureLoad(cube, at, f, 0);
    acc = acc + (a * (1.0 - b)) * textureLoad(cube, at + vec2<i32>(1, 0), f, 0);
    acc = acc + ((1.0 - a) * b) * textureLoad(cube, at + vec2<i32>(0, 1), f, 0);
    return acc + (a * b) * textureLoad(cube, at + vec2<i32>(1, 1), f, 0);
}

// Trilinear lookup at level of detail λ: bilinear on levels ⌊λ⌋ and ⌊λ⌋ + 1, blended by
// frac(λ); `levels` is the cube map's MIP level count.
fn cube_sample(cube: texture_2d_array<f32>, size: u32, levels: u32, d: vec3<f32>, lambda: f32) -> vec4<f32> {
    let q = levels - 1u;
    let l = clamp(lambda, 0.0, f32(q));
    let hi = min(u32(floor(l)), q);
    let lo = min(hi + 1u, q);
    let delta = l - f32(hi);
    var c = (1.0 - delta) * cube_bilinear(cube, size, d, hi);
    if (delta > 0.0) {
        c = c + delta * cube_bilinear(cube, size, d, lo);
    }
    return c;
}

// A shell's colour at a pixel (SPEC.md 8.2), the twin of pis-compile's
// `shell_render_matrix`, at world position p with normal n (interpolated): with k = 1 one
// trilinear lookup of D at λ from D's fine derivatives (differences across the pixel's 2×2
// quad); with k > 1 the mean of k × k lookups at the sub-pixel offsets
// o = ((i + ½)/k − ½, (j + ½)/k − ½), each from p and n moved by o times their fine
// derivatives, at λ from D's derivatives divided by k. `depth` is a depth shell's depth
// cube. Call it in uniform control flow with a uniform k (it takes derivatives).
fn cube_sample_pixel(g: ShellGeometry, cube: texture_2d_array<f32>, depth: texture_2d_array<f32>, size: u32, levels: u32, k: u32, eye: vec3<f32>, p: vec3<f32>, n: vec3<f32>) -> vec4<f32> {
    let d = lookup_direction(g, depth, p, n, eye);
    let ddx = dpdxFine(d);
    let ddy = dpdyFine(d);
    let max_level = f32(levels - 1u);
    if (!SUB_PIXEL_LOOKUPS || k <= 1u) {
        return cube_sample(cube, size, levels, d, cube_lod(d, ddx, ddy, f32(size), max_level));
    }
    let dpx = dpdxFine(p);
    let dpy = dpdyFine(p);
    let dnx = dpdxFine(n);
    let dny = dpdyFine(n);
    let kf = f32(k);
    let sx = ddx / kf;
    let sy = ddy / kf;
    let w = 1.0 / (kf * kf);
    var acc = vec4<f32>(0.0);
    for (var j = 0u; j < k; j = j + 1u) {
        let oy = (f32(j) + 0.5) / kf - 0.5;
        for (var i = 0u; i < k; i = i + 1u) {
            let ox = (f32(i) + 0.5) / kf - 0.5;
            let ds = lookup_direction(g, depth, p + ox * dpx + oy * dpy, n + ox * dnx + oy * dny, eye);
            acc = acc + w * cube_sample(cube, size, levels, ds, cube_lod(ds, sx, sy, f32(size), max_level));
        }
    }
    return acc;
}
