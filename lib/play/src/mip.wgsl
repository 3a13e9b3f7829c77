// One MIP decimation step on the GPU: the 2×2 box filter of pis-format's `mip::decimate`
// (sizes halve rounding up; on an odd side the last used column or row is repeated), with
// the same order of operations, so GPU and CPU chains agree. The destination is a GPU level
// of the padded layout (textured.rs): the used level in its top-left corner, its last used
// column and row repeated into the padding.

struct Sizes {
    // Used size of the source level.
    src: vec2<u32>,
    // Used size of the destination level.
    dst: vec2<u32>,
    // Allocated size of the destination level.
    alloc: vec2<u32>,
};

@group(0) @binding(0) var<uniform> sizes: Sizes;
@group(0) @binding(1) var src: texture_2d<f32>;
@group(0) @binding(2) var dst: texture_storage_2d<FORMAT, write>;

@compute @workgroup_size(8, 8)
fn decimate(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= sizes.alloc.x || id.y >= sizes.alloc.y) {
        return;
    }
    let i = min(id.x, sizes.dst.x - 1u);
    let j = min(id.y, sizes.dst.y - 1u);
    let x0 = 2u * i;
    let x1 = min(2u * i + 1u, sizes.src.x - 1u);
    let y0 = 2u * j;
    let y1 = min(2u * j + 1u, sizes.src.y - 1u);
    let a = textureLoad(src, vec2<u32>(x0, y0), 0);
    let b = textureLoad(src, vec2<u32>(x1, y0), 0);
    let c = textureLoad(src, vec2<u32>(x0, y1), 0);
    let d = textureLoad(src, vec2<u32>(x1, y1), 0);
    textureStore(dst, vec2<u32>(id.x, id.y), 0.25 * (((a + b) + c) + d));
}
