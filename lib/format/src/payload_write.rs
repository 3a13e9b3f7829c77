//! Chunk payload encoders. Each mirrors its decoder in `payload_read.rs` field for field;
//! the labels name the fields as SPEC.md does.

use crate::binary::Sink;
use crate::model::*;

pub fn pspc(s: &mut Sink, space: &ParameterSpace) {
    s.u32(space.dims.len() as u32, "dimension count");
    s.zeros(4, "reserved");
    for (k, d) in space.dims.iter().enumerate() {
        let p = format!("dimension {k}");
        s.string(&d.name, &format!("{p} name"));
        s.string(&d.unit, &format!("{p} unit"));
        s.u8(d.kind.code(), &format!("{p} kind ({})", d.kind.name()));
        s.u8(d.periodic as u8, &format!("{p} flags (periodic)"));
        s.zeros(2, &format!("{p} reserved"));
        s.u32(d.block_size, &format!("{p} block size"));
        s.u32(d.values.len() as u32, &format!("{p} sample count"));
        s.f32s(&d.values, &format!("{p} sample values"));
    }
}

pub fn cams(s: &mut Sink, t: &CameraTable) {
    s.u32(t.width, "image width");
    s.u32(t.height, "image height");
    s.u32(t.depends_on.0, "dependency mask");
    s.u32(t.cameras.len() as u32, "camera count");
    for (i, c) in t.cameras.iter().enumerate() {
        s.f32s(&c.world_from_camera, &format!("camera {i} world_from_camera"));
        s.f32s(&[c.yfov, c.znear, c.zfar], &format!("camera {i} yfov, znear, zfar"));
        s.zeros(4, &format!("camera {i} reserved"));
    }
}

pub fn objs<S>(s: &mut Sink, objects: &[Object<S>]) {
    s.u32(objects.len() as u32, "object count");
    for (i, o) in objects.iter().enumerate() {
        let p = format!("object {i}");
        s.string(&o.name, &format!("{p} name"));
        s.u8(o.role.code(), &format!("{p} role ({})", o.role.name()));
        s.zeros(3, &format!("{p} reserved"));
        s.f32s(&o.shading.f0, &format!("{p} f0"));
        s.f32s(&[o.shading.ior], &format!("{p} ior"));
        s.f32s(&o.shading.absorption, &format!("{p} absorption"));
        for (k, off) in o.stagger.iter().enumerate() {
            s.u32(*off, &format!("{p} block origin offset, dimension {k}"));
        }
        s.u32(o.transforms.depends_on.0, &format!("{p} transform dependency mask"));
        s.u32(o.transforms.transforms.len() as u32, &format!("{p} transform count"));
        for (t, m) in o.transforms.transforms.iter().enumerate() {
            s.f32s(m, &format!("{p} world_from_object {t}"));
        }
    }
}

/// Attribute bits of a `MESH` chunk.
pub const MESH_NORMALS: u32 = 1;
pub const MESH_TEXCOORDS: u32 = 2;
pub const MESH_HULL: u32 = 4;

pub fn mesh(s: &mut Sink, object: u32, m: &Mesh) {
    let attrs = m.normals.as_ref().map_or(0, |_| MESH_NORMALS)
        | m.texcoords.as_ref().map_or(0, |_| MESH_TEXCOORDS)
        | if m.hull_triangles > 0 { MESH_HULL } else { 0 };
    s.u32(object, "object index");
    s.u32(m.positions.len() as u32, "vertex count");
    s.u32(m.indices.len() as u32, "index count");
    s.u32(attrs, "attributes (1 normals, 2 texcoords, 4 hull)");
    let flat3 = |v: &[[f32; 3]]| v.iter().flatten().copied().collect::<Vec<f32>>();
    s.f32s(&flat3(&m.positions), "positions");
    if let Some(n) = &m.normals {
        s.f32s(&flat3(n), "normals");
    }
    if let Some(t) = &m.texcoords {
        let flat: Vec<f32> = t.iter().flatten().copied().collect();
        s.f32s(&flat, "texcoords");
    }
    let idx: Vec<u8> = m.indices.iter().flat_map(|i| i.to_le_bytes()).collect();
    s.raw(&idx, || format!("indices = {:?}", m.indices));
    if m.hull_triangles > 0 {
        s.u32(m.hull_triangles, "hull triangles");
    }
}

pub fn layr<S>(s: &mut Sink, objects: &[Object<S>], mut stream_ref: impl FnMut(&S) -> StreamRef) {
    let count: usize = objects.iter().map(|o| o.layers.len()).sum();
    s.u32(count as u32, "layer count");
    let mut li = 0;
    for (oi, o) in objects.iter().enumerate() {
        for l in &o.layers {
            let p = format!("layer {li}");
            s.u32(oi as u32, &format!("{p} object index"));
            s.u8(l.kind.code(), &format!("{p} kind ({})", l.kind.name()));
            s.u8(l.mapping as u8, &format!("{p} mapping ({})", l.mapping.name()));
            s.u8(l.channels, &format!("{p} channels"));
            s.u8(l.mip_mode as u8, &format!("{p} mip mode ({})", l.mip_mode.name()));
            s.u8(l.term as u8, &format!("{p} term ({})", l.term.name()));
            s.u8(l.order, &format!("{p} order"));
            s.u8(l.combine as u8, &format!("{p} combine ({})", l.combine.name()));
            s.u8(l.basis, &format!("{p} light basis"));
            s.f32s(&[l.gamma], &format!("{p} gamma"));
            s.u32(l.depends_on.0, &format!("{p} dependency mask"));
            s.u32(l.blocks.len() as u32, &format!("{p} block count"));
            for (bi, b) in l.blocks.iter().enumerate() {
                let p = format!("{p} block {bi}");
                s.u32(b.width, &format!("{p} width"));
                s.u32(b.height, &format!("{p} height"));
                match b.placement {
                    Placement::Surface { affine, repeat, cut } => {
                        s.u16(0, &format!("{p} shell shape (none)"));
                        let bits = repeat[0] as u16
                            | (repeat[1] as u16) << 1
                            | (cut[0].is_some() as u16) << 2
                            | (cut[1].is_some() as u16) << 3;
                        s.u16(
                            bits,
                            &format!("{p} flags (1 repeat s, 2 repeat t, 4 cut u, 8 cut v)"),
                        );
                        s.f32s(&affine, &format!("{p} affine a b c d e f"));
                        s.f32s(
                            &[cut[0].unwrap_or(0.0), cut[1].unwrap_or(0.0)],
                            &format!("{p} branch cuts u, v"),
                        );
                        s.zeros(16, &format!("{p} unused placement values"));
                    }
                    Placement::Shell { shape, origin, params, lookups } => {
                        s.u16(shape as u16, &format!("{p} shell shape ({})", shape.name()));
                        s.u16(
                            lookups.saturating_sub(1) as u16,
                            &format!("{p} flags (lookups per pixel side − 1)"),
                        );
                        s.f32s(&origin, &format!("{p} shell origin"));
                        s.f32s(&params, &format!("{p} shell parameters"));
                        s.zeros(12, &format!("{p} unused placement values"));
                    }
                }
                s.u32(b.levels.len() as u32, &format!("{p} level count"));
                for (lv, level) in b.levels.iter().enumerate() {
                    let p = format!("{p} level {lv}");
                    for (k, c) in level.counts.iter().enumerate() {
                        s.u32(*c, &format!("{p} samples along masked dimension {k}"));
                    }
                    for (ii, img) in level.images.iter().enumerate() {
                        let r = stream_ref(img);
                        let p = format!("{p} image {ii}");
                        s.u16(r.codec.code(), &format!("{p} codec ({})", r.codec.name()));
                        s.zeros(2, &format!("{p} reserved"));
                        s.u32(r.chunk, &format!("{p} chunk index"));
                        s.u64(r.offset, &format!("{p} offset"));
                        s.u32(r.length, &format!("{p} length"));
                        s.u32_hex(r.crc, &format!("{p} crc32"));
                    }
                }
            }
            li += 1;
        }
    }
}

pub fn prov(s: &mut Sink, p: &Provenance) {
    s.string(&p.tool, "tool");
    s.string(&p.source, "source");
    s.u64(p.raw_image_bytes, "raw image bytes");
    s.u32(p.settings.len() as u32, "setting count");
    for (k, v) in &p.settings {
        s.string(k, "setting key");
        s.string(v, "setting value");
    }
}
