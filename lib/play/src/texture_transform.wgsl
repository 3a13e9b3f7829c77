// The block's texture transform (SPEC.md 7.3), shared by the textured-object pipeline
// (textured.wgsl) and the player's frame (frame/frame.wgsl): prepended to both at build
// time (textured.rs, frame/pipelines.rs). The twins of pis-compile's hardware model
// (transform.rs), with the same order of operations: change them together.
//
// The shader this is prepended to declares the uniform `u` with the block's `cut`
// (vec4<f32>), `affine_abcd` (vec4<f32>) and `affine_ef` (vec2<f32>).

// The branch cuts (SPEC.md 7.3): w' = (w − w_cut) − floor(w − w_cut) along u where cut.z
// is 1, along v where cut.w is 1; the other coordinate as it is.
fn cut_uv(uv: vec2<f32>) -> vec2<f32> {
    var w = uv;
    if (u.cut.z != 0.0) {
        let d = w.x - u.cut.x;
        w.x = d - floor(d);
    }
    if (u.cut.w != 0.0) {
        let d = w.y - u.cut.y;
        w.y = d - floor(d);
    }
    return w;
}

// The cuts, then s = a·u + b·v + e, t = c·u + d·v + f.
fn texcoord(mesh_uv: vec2<f32>) -> vec2<f32> {
    let uv = cut_uv(mesh_uv);
    return vec2<f32>(
        u.affine_abcd.x * uv.x + u.affine_abcd.y * uv.y + u.affine_ef.x,
        u.affine_abcd.z * uv.x + u.affine_abcd.w * uv.y + u.affine_ef.y,
    );
}
