// Vertex rays through a lens object on the GPU (thesis 6.4.1): one invocation per vertex of a
// tessellation level. The twin of pis-compile's `trace_vertex` and of the walk of
// `pis_scene::lens_tree::lens_paths` with `LensObject::closest` and `LensObject::surface`
// (the lens object's own triangles, the flat BVH of `pis_compile::hybrid::lens_bvh`): the same
// operations in the same order, written twice; lib/play/tests/lens_rays_vs_cpu.rs holds the
// two to the same paths.

struct Params {
    eye: vec3f,
    count: u32,
    ior: f32,
    // At most 14 (MAX_GPU_DEPTH): the branch stack holds max_depth + 2 branches.
    max_depth: u32,
    terms_kept: u32,
    min_weight: f32,
    base: vec3f,
    // 1 where the material absorbs (σ ≠ 0).
    absorbing: u32,
    sigma_a: vec3f,
    nodes: u32,
}

struct VertexIn {
    position: vec3f,
    front_face: u32,
    normal: vec3f,
    pad: u32,
}

struct TermOut {
    origin: vec3f,
    exists: u32,
    direction: vec3f,
    interfaces: u32,
    modulation: vec3f,
    reflected: u32,
}

struct VertexOut {
    terms: array<TermOut, 4>,
    visible: u32,
    rays: u32,
    pad0: u32,
    pad1: u32,
}

@group(0) @binding(0) var<uniform> params: Params;
// Two words per node: min xyz and the primitive count; max xyz and the first index.
@group(0) @binding(1) var<storage, read> nodes: array<vec4<u32>>;
// Six per triangle: corners 0–2 (w: the triangle's index as bits, has-normals, 0), normals 0–2.
@group(0) @binding(2) var<storage, read> triangles: array<vec4f>;
@group(0) @binding(3) var<storage, read> vertices: array<VertexIn>;
@group(0) @binding(4) var<storage, read_write> traced: array<VertexOut>;

// Farther than any hit: what "no box" and "no hit" read as, and an open ray's end.
const FAR: f32 = 3.0e38;
const EPSILON: f32 = 1.1920929e-7;
const STACK: u32 = 16u;
const NODE_STACK: u32 = 64u;

struct Hit {
    found: bool,
    t: f32,
    triangle: u32,
}

// obvhs's `safe_inverse`: ±1/ε for a component within ε of 0 (the sign of its sign bit).
fn safe_inverse(x: f32) -> f32 {
    if abs(x) <= EPSILON {
        return select(1.0, -1.0, (bitcast<u32>(x) & 0x80000000u) != 0u) / EPSILON;
    }
    return 1.0 / x;
}

// obvhs's slab test: the entry distance, FAR where the ray misses the box.
fn box_distance(i: u32, o: vec3f, inv: vec3f) -> f32 {
    let a = nodes[2u * i];
    let b = nodes[2u * i + 1u];
    let t1 = (bitcast<vec3f>(a.xyz) - o) * inv;
    let t2 = (bitcast<vec3f>(b.xyz) - o) * inv;
    let lo = min(t1, t2);
    let hi = max(t1, t2);
    let near = max(max(lo.x, lo.y), lo.z);
    let far = min(min(hi.x, hi.y), hi.z);
    if far >= near && far >= 0.0 {
        return near;
    }
    return FAR;
}

// obvhs's Möller–Trumbore test; FAR where it misses or t is outside (0, tmax] (a ray that
// starts in the triangle's plane does not hit it, as LensObject::closest's does not).
fn triangle_distance(k: u32, o: vec3f, d: vec3f, tmax: f32) -> f32 {
    let v0 = triangles[6u * k].xyz;
    let v1 = triangles[6u * k + 1u].xyz;
    let v2 = triangles[6u * k + 2u].xyz;
    let e1 = v0 - v1;
    let e2 = v2 - v0;
    let n = cross(e1, e2);
    let c = v0 - o;
    let r = cross(d, c);
    let inv_det = 1.0 / dot(n, d);
    let u = dot(r, e2) * inv_det;
    let v = dot(r, e1) * inv_det;
    let w = 1.0 - u - v;
    let signs = (bitcast<u32>(u) | bitcast<u32>(v) | bitcast<u32>(w)) & 0x80000000u;
    if inv_det != 0.0 && signs == 0u {
        let t = dot(n, c) * inv_det;
        if t > 0.0 && t <= tmax {
            return t;
        }
    }
    return FAR;
}

// The closest hit along o + t·d, t in (0, tmax): a stack of nodes, the nearer child first.
fn closest(o: vec3f, d: vec3f, tmax_in: f32) -> Hit {
    var hit = Hit(false, 0.0, 0u);
    if params.nodes == 0u {
        return hit;
    }
    var tmax = tmax_in;
    let inv = vec3f(safe_inverse(d.x), safe_inverse(d.y), safe_inverse(d.z));
    var stack: array<u32, NODE_STACK>;
    var len = 0u;
    if box_distance(0u, o, inv) < tmax {
        stack[0] = 0u;
        len = 1u;
    }
    while len > 0u {
        len -= 1u;
        let i = stack[len];
        let a = nodes[2u * i];
        let b = nodes[2u * i + 1u];
        if a.w > 0u {
            for (var k = b.w; k < b.w + a.w; k++) {
                let t = triangle_distance(k, o, d, tmax);
                if t < tmax {
                    tmax = t;
                    hit = Hit(true, t, k);
                }
            }
            continue;
        }
        let l = b.w;
        let r = b.w + 1u;
        let tl = box_distance(l, o, inv);
        let tr = box_distance(r, o, inv);
        var near = l;
        var far = r;
        var tn = tl;
        var tf = tr;
        if tl > tr {
            near = r;
            far = l;
            tn = tr;
            tf = tl;
        }
        if tf < tmax && len < NODE_STACK {
            stack[len] = far;
            len += 1u;
        }
        if tn < tmax && len < NODE_STACK {
            stack[len] = near;
            len += 1u;
        }
    }
    return hit;
}

// glam's `normalize`: v times the reciprocal of its length.
fn unit(v: vec3f) -> vec3f {
    return v * (1.0 / sqrt(dot(v, v)));
}

// glam's `normalize_or_zero`.
fn unit_or_zero(v: vec3f) -> vec3f {
    let rcp = 1.0 / sqrt(dot(v, v));
    if rcp > 0.0 && rcp < FAR {
        return v * rcp;
    }
    return vec3f(0.0);
}

fn max_element(v: vec3f) -> f32 {
    return max(max(v.x, v.y), v.z);
}

// pis_scene::optics.
fn fresnel_dielectric(cos_in: f32, eta: f32) -> f32 {
    let cos_i = clamp(cos_in, 0.0, 1.0);
    let sin2_t = eta * eta * (1.0 - cos_i * cos_i);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = sqrt(1.0 - sin2_t);
    let rs = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let rp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    return 0.5 * (rs * rs + rp * rp);
}

fn reflect_about(d: vec3f, n: vec3f) -> vec3f {
    return d - n * (2.0 * dot(d, n));
}

fn offset_origin(p: vec3f, ng: vec3f, dir: vec3f) -> vec3f {
    let eps = 1e-4 * (1.0 + max_element(abs(p)));
    if dot(dir, ng) >= 0.0 {
        return p + ng * eps;
    }
    return p - ng * eps;
}

// A point of the lens object's surface as a ray meets it (LensObject::surface).
struct Surface {
    position: vec3f,
    normal: vec3f,
    geometric_normal: vec3f,
    front_face: bool,
}

fn surface(k: u32, t: f32, o: vec3f, d: vec3f) -> Surface {
    let a = triangles[6u * k].xyz;
    let b = triangles[6u * k + 1u].xyz;
    let c = triangles[6u * k + 2u].xyz;
    let p = o + d * t;
    // barycentric()
    let n = cross(b - a, c - a);
    let inv = 1.0 / dot(n, n);
    let w1 = dot(cross(p - a, c - a), n) * inv;
    let w2 = dot(cross(b - a, p - a), n) * inv;
    let w0 = 1.0 - w1 - w2;
    let ng = unit(cross(b - a, c - a));
    let front_face = dot(ng, d) < 0.0;
    let gn = select(-ng, ng, front_face);
    var normal = ng;
    if triangles[6u * k + 1u].w != 0.0 {
        let ns = unit_or_zero(
            triangles[6u * k + 3u].xyz * w0 + triangles[6u * k + 4u].xyz * w1
                + triangles[6u * k + 5u].xyz * w2,
        );
        if any(ns != vec3f(0.0)) {
            normal = ns;
        }
    }
    if dot(normal, gn) < 0.0 {
        normal = -normal;
    }
    return Surface(p, normal, gn, front_face);
}

// A path not yet out of the object (lens_tree's Branch; the topology's two fields inline).
struct Branch {
    position: vec3f,
    lesser: u32,
    geometric_normal: vec3f,
    depth: u32,
    direction: vec3f,
    interfaces: u32,
    modulation: vec3f,
    reflected: u32,
}

// A child of a path at an interface: direction, factor, reflected, lesser.
struct Child {
    exists: bool,
    direction: vec3f,
    factor: vec3f,
    reflected: bool,
    lesser: bool,
}

struct Children {
    first: Child,
    second: Child,
}

// The children at interface `s` met along `d`, the greater first (lens_tree's `children`).
fn children(s: Surface, d: vec3f) -> Children {
    let eta = select(params.ior, 1.0 / params.ior, s.front_face);
    let f = fresnel_dielectric(-dot(d, s.normal), eta);
    let tint = select(vec3f(1.0), params.base, s.front_face);
    let r = reflect_about(d, s.normal);
    let none = Child(false, vec3f(0.0), vec3f(0.0), false, false);
    // refract()
    let cos_i = -dot(d, s.normal);
    let sin2_t = eta * eta * (1.0 - cos_i * cos_i);
    if sin2_t >= 1.0 {
        return Children(Child(true, r, vec3f(f), true, false), none);
    }
    let cos_t = sqrt(1.0 - sin2_t);
    let t = unit(d * eta + s.normal * (eta * cos_i - cos_t));
    if f < 0.5 {
        return Children(
            Child(true, t, (1.0 - f) * tint, false, false),
            Child(true, r, vec3f(f), true, true),
        );
    }
    return Children(
        Child(true, r, vec3f(f), true, false),
        Child(true, t, (1.0 - f) * tint, false, true),
    );
}

fn child_of(b: Branch, c: Child) -> Branch {
    var out = b;
    out.direction = c.direction;
    out.modulation = b.modulation * c.factor;
    if c.reflected && b.interfaces < 32u {
        out.reflected = b.reflected | (1u << b.interfaces);
    }
    out.interfaces = min(b.interfaces + 1u, 255u);
    out.lesser = b.lesser + select(0u, 1u, c.lesser);
    out.depth = b.depth + 1u;
    return out;
}

// The term of the paths under `b` (4 for none).
fn term_of(b: Branch) -> u32 {
    if (b.reflected & 1u) == 1u {
        return select(4u, 0u, b.lesser == 0u);
    }
    return min(1u + b.lesser, 4u);
}

@compute @workgroup_size(64)
fn trace(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if i >= params.count {
        return;
    }
    let vin = vertices[i];
    var out: VertexOut;
    for (var k = 0u; k < 4u; k++) {
        out.terms[k].exists = 0u;
    }
    // trace_vertex: the visibility ray, then the vertex's own surface.
    let to = vin.position - params.eye;
    let distance = length(to);
    let dir = to / distance;
    let eps = 1e-4 * (1.0 + max_element(abs(vin.position)));
    out.visible = select(0u, 1u, !closest(params.eye, dir, distance - eps).found);
    var n = unit_or_zero(vin.normal);
    if all(n == vec3f(0.0)) {
        n = -dir;
    }
    let facing = select(-n, n, vin.front_face != 0u);
    let first = Surface(vin.position, facing, facing, vin.front_face != 0u);
    var rays = 1u;
    // lens_paths: both children of the first interface, neither the lesser.
    var stack: array<Branch, STACK>;
    var len = 0u;
    let root = Branch(first.position, 0u, first.geometric_normal, 0u, dir, 0u, vec3f(1.0), 0u);
    let cs = children(first, dir);
    var c0 = cs.first;
    c0.lesser = false;
    stack[len] = child_of(root, c0);
    len += 1u;
    if cs.second.exists {
        var c1 = cs.second;
        c1.lesser = false;
        stack[len] = child_of(root, c1);
        len += 1u;
    }
    while len > 0u {
        len -= 1u;
        let b = stack[len];
        let term = term_of(b);
        if term >= params.terms_kept || max_element(b.modulation) < params.min_weight
            || b.depth > params.max_depth {
            continue;
        }
        let o = offset_origin(b.position, b.geometric_normal, b.direction);
        rays += 1u;
        let hit = closest(o, b.direction, FAR);
        if !hit.found {
            let w = max_element(b.modulation);
            if out.terms[term].exists == 0u || w > max_element(out.terms[term].modulation) {
                out.terms[term] = TermOut(o, 1u, b.direction, b.interfaces, b.modulation, b.reflected);
            }
            continue;
        }
        let s = surface(hit.triangle, hit.t, o, b.direction);
        var absorption = vec3f(1.0);
        if !s.front_face && params.absorbing != 0u {
            absorption = exp(-params.sigma_a * hit.t);
        }
        var at = b;
        at.position = s.position;
        at.geometric_normal = s.geometric_normal;
        at.modulation = b.modulation * absorption;
        // The greater branch pushed last, so walked first.
        let next = children(s, b.direction);
        if next.second.exists && len < STACK {
            stack[len] = child_of(at, next.second);
            len += 1u;
        }
        if len < STACK {
            stack[len] = child_of(at, next.first);
            len += 1u;
        }
    }
    out.rays = rays;
    traced[i] = out;
}
