// A cube map's atlas images from its levels (cube_atlas.rs, `BorderPass`): one dispatch per
// level, one invocation per texel of the level's bordered face (n + 2)² on each of the six
// faces. Inside, the level's texel; on the border, the sources `border_map` lists for it
// (cube_atlas.rs `CubeAtlas::border_map`): one texel, or the mean of the three that meet at
// a cube corner, added in the order `CubeAtlas::border` adds them.

struct BorderParams {
    // Top-left texel of the level's bordered face in the atlas.
    origin: vec2<u32>,
    // The level's face size.
    n: u32,
    // The level's first entry in `border_map`.
    map_offset: u32,
};

@group(0) @binding(0) var<uniform> p: BorderParams;
@group(0) @binding(1) var level: texture_2d_array<f32>;
@group(0) @binding(2) var atlas: texture_storage_2d_array<CUBE_FORMAT, write>;
// Per border texel: three packed sources (face << 28 | j << 14 | i) and their count.
@group(0) @binding(3) var<storage, read> border_map: array<vec4<u32>>;

fn source(s: u32) -> vec4<f32> {
    let at = vec2<i32>(i32(s & 0x3fffu), i32((s >> 14u) & 0x3fffu));
    return textureLoad(level, at, i32(s >> 28u), 0);
}

// The border index of bordered texel (x, y) = (i + 1, j + 1): the row above, the row below,
// then the left and right columns (cube_atlas.rs `border_texel` is its inverse).
fn border_index(x: u32, y: u32, n: u32) -> u32 {
    if (y == 0u) {
        return x;
    }
    if (y == n + 1u) {
        return n + 2u + x;
    }
    if (x == 0u) {
        return 2u * (n + 2u) + y - 1u;
    }
    return 2u * (n + 2u) + n + y - 1u;
}

@compute @workgroup_size(8, 8, 1)
fn cube_border(@builtin(global_invocation_id) g: vec3<u32>) {
    let n = p.n;
    if (g.x > n + 1u || g.y > n + 1u) {
        return;
    }
    let face = i32(g.z);
    let at = vec2<i32>(p.origin + g.xy);
    if (g.x >= 1u && g.x <= n && g.y >= 1u && g.y <= n) {
        textureStore(atlas, at, face, textureLoad(level, vec2<i32>(g.xy) - 1, face, 0));
        return;
    }
    let e = border_map[p.map_offset + g.z * (4u * n + 4u) + border_index(g.x, g.y, n)];
    var c = source(e.x);
    if (e.w == 3u) {
        c = (c + source(e.y) + source(e.z)) / 3.0;
    }
    textureStore(atlas, at, face, c);
}
