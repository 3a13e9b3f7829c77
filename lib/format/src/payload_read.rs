//! Chunk payload decoders: the inverse of `payload_write.rs`. They check structure (lengths,
//! counts against the bytes left, enum codes, UTF-8); range and consistency rules are
//! checked on the model by `checks.rs`. A broken rule that leaves the payload readable
//! (reserved fields, undefined flag bits) goes through [`Cursor::flag`], so that a
//! validator's cursor reports it and parses on.

use pis_codec::CodecId;

use crate::binary::Cursor;
use crate::issue::id;
use crate::model::*;
use crate::payload_write::{MESH_HULL, MESH_NORMALS, MESH_TEXCOORDS};
use crate::Issue;

/// Most dimensions a space may have (so masks fit and tables stay small).
pub const MAX_DIMS: u32 = 8;

pub fn pspc(c: &mut Cursor) -> Result<ParameterSpace, Issue> {
    let n = c.u32("dimension count")?;
    if n == 0 || n > MAX_DIMS {
        return Err(c.issue(
            id::space::DIMENSION_COUNT,
            format!("{n} dimensions, expected 1 to {MAX_DIMS}"),
        ));
    }
    c.reserved(4, "reserved")?;
    let mut dims = Vec::with_capacity(n as usize);
    for k in 0..n {
        let name = c.string(&format!("dimension {k} name"), id::space::DIMENSION_NAME)?;
        let unit = c.string(&format!("dimension {k} unit"), id::space::DIMENSION_NAME)?;
        let at = c.offset();
        let kind_code = c.u8("kind")?;
        let kind = DimensionKind::from_code(kind_code).ok_or_else(|| {
            c.issue(
                id::space::UNKNOWN_DIMENSION_KIND,
                format!("dimension {k} kind {kind_code}; 0 to 4 are defined"),
            )
            .at(at)
        })?;
        let flags = c.u8("flags")?;
        if flags & !1 != 0 {
            let issue = c.issue(
                id::chunk::RESERVED_NOT_ZERO,
                format!("dimension {k} flags {flags:#x} set undefined bits"),
            );
            c.flag(issue)?;
        }
        c.reserved(2, "reserved")?;
        let block_size = c.u32("block size")?;
        let samples = c.u32("sample count")?;
        let count = c.expect_records(samples as u64, 4, "sample values")?;
        let mut values = Vec::with_capacity(count);
        for _ in 0..count {
            values.push(c.f32("sample value")?);
        }
        dims.push(Dimension { name, kind, periodic: flags & 1 != 0, unit, block_size, values });
    }
    c.finish()?;
    Ok(ParameterSpace { dims })
}

pub fn cams(c: &mut Cursor) -> Result<CameraTable, Issue> {
    let width = c.u32("image width")?;
    let height = c.u32("image height")?;
    let depends_on = DepMask(c.u32("dependency mask")?);
    let n = c.u32("camera count")?;
    let n = c.expect_records(n as u64, 64, "cameras")?;
    let mut cameras = Vec::with_capacity(n);
    for _ in 0..n {
        let world_from_camera = c.f32s::<12>("world_from_camera")?;
        let [yfov, znear, zfar] = c.f32s::<3>("yfov, znear, zfar")?;
        c.reserved(4, "camera reserved")?;
        cameras.push(Camera { world_from_camera, yfov, znear, zfar });
    }
    c.finish()?;
    Ok(CameraTable { width, height, depends_on, cameras })
}

/// Parses `OBJS`; meshes and layers are filled in from their own chunks.
pub fn objs(c: &mut Cursor, dim_count: usize) -> Result<Vec<Object<StreamRef>>, Issue> {
    let n = c.u32("object count")?;
    if n == 0 || n > 65535 {
        return Err(c.issue(id::objects::OBJECT_COUNT, format!("{n} objects, expected 1 to 65535")));
    }
    // name length + role + reserved + shading + stagger + mask + count
    let min = 4 + 4 + 28 + 4 * dim_count as u64 + 8;
    let n = c.expect_records(n as u64, min, "objects")?;
    let mut objects = Vec::with_capacity(n);
    for i in 0..n {
        let name = c.string(&format!("object {i} name"), id::objects::OBJECT_NAME)?;
        let at = c.offset();
        let role_code = c.u8("role")?;
        let role = ObjectRole::from_code(role_code).ok_or_else(|| {
            c.issue(
                id::objects::UNKNOWN_ROLE,
                format!("object {i} role {role_code}; 0 to 2 are defined"),
            )
            .at(at)
        })?;
        c.reserved(3, "object reserved")?;
        let f0 = c.f32s::<3>("f0")?;
        let [ior] = c.f32s::<1>("ior")?;
        let absorption = c.f32s::<3>("absorption")?;
        let mut stagger = Vec::with_capacity(dim_count);
        for k in 0..dim_count {
            stagger.push(c.u32(&format!("block origin offset, dimension {k}"))?);
        }
        let depends_on = DepMask(c.u32("transform dependency mask")?);
        let t = c.u32("transform count")?;
        let t = c.expect_records(t as u64, 48, "transforms")?;
        let mut transforms = Vec::with_capacity(t);
        for _ in 0..t {
            transforms.push(c.f32s::<12>("world_from_object")?);
        }
        objects.push(Object {
            name,
            role,
            shading: Shading { f0, ior, absorption },
            stagger,
            transforms: TransformTable { depends_on, transforms },
            mesh: Mesh::default(),
            layers: Vec::new(),
        });
    }
    c.finish()?;
    Ok(objects)
}

/// Parses one `MESH` chunk: (object index, mesh).
pub fn mesh(c: &mut Cursor) -> Result<(u32, Mesh), Issue> {
    let object = c.u32("object index")?;
    let vc = c.u32("vertex count")?;
    let ic = c.u32("index count")?;
    let attrs = c.u32("attributes")?;
    if attrs & !(MESH_NORMALS | MESH_TEXCOORDS | MESH_HULL) != 0 {
        let issue = c.issue(
            id::chunk::RESERVED_NOT_ZERO,
            format!("attributes {attrs:#x} set undefined bits"),
        );
        c.flag(issue)?;
    }
    let per_vertex = 12
        + if attrs & MESH_NORMALS != 0 { 12 } else { 0 }
        + if attrs & MESH_TEXCOORDS != 0 { 8 } else { 0 };
    let vc = c.expect_records(vc as u64, per_vertex, "vertices")?;
    let read3 = |c: &mut Cursor, what: &str| -> Result<Vec<[f32; 3]>, Issue> {
        (0..vc).map(|_| c.f32s::<3>(what)).collect()
    };
    let positions = read3(c, "position")?;
    let normals = if attrs & MESH_NORMALS != 0 { Some(read3(c, "normal")?) } else { None };
    let texcoords = if attrs & MESH_TEXCOORDS != 0 {
        Some((0..vc).map(|_| c.f32s::<2>("texcoord")).collect::<Result<Vec<_>, _>>()?)
    } else {
        None
    };
    let ic = c.expect_records(ic as u64, 4, "indices")?;
    let indices = (0..ic).map(|_| c.u32("index")).collect::<Result<Vec<_>, _>>()?;
    let hull_triangles = if attrs & MESH_HULL != 0 {
        let h = c.u32("hull triangles")?;
        if h == 0 {
            let issue = c.issue(
                id::mesh::MALFORMED,
                "attribute bit 2 (hull) set with a hull triangle count of 0".to_string(),
            );
            c.flag(issue)?;
        }
        h
    } else {
        0
    };
    c.finish()?;
    Ok((object, Mesh { positions, normals, texcoords, indices, hull_triangles }))
}

/// Parses `LAYR` into the objects' layer lists. A layer's dependency mask decides how many
/// sample counts each of its levels holds, and its block count how many blocks follow, so
/// a mask that names a missing dimension (rule 5002) or, where `grid` gives the parameter
/// space (when it holds every 4xxx rule), a block count other than the layer's block grid
/// (rule 6005) leaves the rest of the payload unreadable: parsing stops there.
pub fn layr(
    c: &mut Cursor,
    objects: &mut [Object<StreamRef>],
    grid: Option<&ParameterSpace>,
) -> Result<(), Issue> {
    let n = c.u32("layer count")?;
    let n = c.expect_records(n as u64, 28, "layers")?;
    for li in 0..n {
        let at = c.offset();
        let oi = c.u32("object index")? as usize;
        if oi >= objects.len() {
            return Err(c
                .issue(
                    id::layers::UNKNOWN_OBJECT,
                    format!("layer {li} names object {oi}; there are {}", objects.len()),
                )
                .at(at));
        }
        let codes_at = c.offset();
        let kind = c.u8("kind")?;
        let mapping = c.u8("mapping")?;
        let channels = c.u8("channels")?;
        let mip = c.u8("mip mode")?;
        let term = c.u8("term")?;
        let order = c.u8("order")?;
        let combine = c.u8("combine")?;
        let basis = c.u8("light basis")?;
        let bad = |what: &str, v: u8| {
            c.issue(id::layers::UNKNOWN_CODE, format!("layer {li} {what} {v} is not defined"))
                .at(codes_at)
        };
        let kind = LayerKind::from_code(kind).ok_or_else(|| bad("kind", kind))?;
        let mapping = Mapping::from_code(mapping).ok_or_else(|| bad("mapping", mapping))?;
        let mip_mode = MipMode::from_code(mip).ok_or_else(|| bad("mip mode", mip))?;
        let term = Term::from_code(term).ok_or_else(|| bad("term", term))?;
        let combine = Combine::from_code(combine).ok_or_else(|| bad("combine mode", combine))?;
        let [gamma] = c.f32s::<1>("gamma")?;
        let mask_at = c.offset();
        let depends_on = DepMask(c.u32("dependency mask")?);
        let stagger = &objects[oi].stagger;
        if depends_on.0 >> stagger.len() != 0 {
            return Err(c
                .issue(
                    id::cameras::MASK_NAMES_MISSING_DIMENSION,
                    format!(
                        "layer {li} mask {:#x}, the space has {} dimensions: its blocks cannot be read",
                        depends_on.0,
                        stagger.len()
                    ),
                )
                .at(mask_at));
        }
        let count_at = c.offset();
        let nb = c.u32("block count")?;
        // The grid is defined where the space and the object's block origins hold.
        let origins_hold =
            |s: &ParameterSpace| s.dims.iter().zip(stagger).all(|(d, &o)| o < d.block_size);
        if let Some(s) = grid.filter(|s| origins_hold(s)) {
            let expected = crate::blocks::BlockGrid::new(s, depends_on, stagger).block_count();
            if nb as u64 != expected {
                return Err(c
                    .issue(
                        id::layers::BLOCK_COUNT,
                        format!("layer {li}: {nb} blocks, the grid has {expected}"),
                    )
                    .at(count_at));
            }
        }
        let nb = c.expect_records(nb as u64, 68, "blocks")?;
        let mut blocks = Vec::with_capacity(nb);
        for bi in 0..nb {
            blocks.push(block(c, li, bi, depends_on.count())?);
        }
        objects[oi].layers.push(Layer {
            kind,
            mapping,
            channels,
            mip_mode,
            term,
            order,
            combine,
            basis,
            gamma,
            depends_on,
            blocks,
        });
    }
    c.finish()
}

/// Parses block `bi` of layer `li`, whose levels hold `dims` sample counts each.
fn block(c: &mut Cursor, li: usize, bi: usize, dims: usize) -> Result<Block<StreamRef>, Issue> {
    let width = c.u32("width")?;
    let height = c.u32("height")?;
    let shape_at = c.offset();
    let shape = c.u16("shell shape")? as u32;
    let flags = c.u16("placement flags")?;
    // Shells: the lookups per pixel side less one (0 to MAX_SHELL_LOOKUPS − 1).
    if flags & !15 != 0 || (shape != 0 && flags as u32 >= crate::model::MAX_SHELL_LOOKUPS) {
        let issue = c
            .issue(
                id::chunk::RESERVED_NOT_ZERO,
                format!("layer {li} block {bi} placement flags {flags:#x}"),
            )
            .at(shape_at + 2);
        c.flag(issue)?;
    }
    let values = c.f32s::<12>("placement values")?;
    let placement = if shape == 0 {
        Placement::Surface {
            affine: values[0..6].try_into().expect("6 values"),
            repeat: [flags & 1 != 0, flags & 2 != 0],
            cut: [(flags & 4 != 0).then_some(values[6]), (flags & 8 != 0).then_some(values[7])],
        }
    } else {
        let shape = ShellShape::from_code(shape).ok_or_else(|| {
            c.issue(
                id::layers::BLOCK_PLACEMENT,
                format!("layer {li} block {bi} shell shape {shape}; 0 to 6 are defined"),
            )
            .at(shape_at)
        })?;
        Placement::Shell {
            shape,
            origin: values[0..3].try_into().expect("3 values"),
            params: values[3..9].try_into().expect("6 values"),
            lookups: (flags as u32).min(crate::model::MAX_SHELL_LOOKUPS - 1) + 1,
        }
    };
    let unused = if shape == 0 {
        // A branch-cut slot without its flag is unused too.
        let cuts = [(flags & 4 == 0).then_some(values[6]), (flags & 8 == 0).then_some(values[7])];
        cuts.into_iter().flatten().chain(values[8..].iter().copied()).collect::<Vec<f32>>()
    } else {
        values[9..].to_vec()
    };
    if unused.iter().any(|v| v.to_bits() != 0) {
        let issue = c
            .issue(
                id::chunk::RESERVED_NOT_ZERO,
                format!("layer {li} block {bi} unused placement values are not +0.0"),
            )
            .at(shape_at + 4);
        c.flag(issue)?;
    }
    let lc = c.u32("level count")?;
    if lc == 0 || lc > 32 {
        return Err(c.issue(
            id::pyramid::LEVEL_COUNT,
            format!("layer {li} block {bi} has {lc} levels, expected 1 to 32"),
        ));
    }
    let mut levels = Vec::with_capacity(lc as usize);
    for lv in 0..lc {
        let mut counts = Vec::with_capacity(dims);
        let mut images: u64 = 1;
        for _ in 0..dims {
            let n = c.u32("level sample count")?;
            counts.push(n);
            images = images.saturating_mul(n as u64);
        }
        let ni = c.expect_records(images, 24, &format!("level {lv} image references"))?;
        let mut refs = Vec::with_capacity(ni);
        for _ in 0..ni {
            let at = c.offset();
            let code = c.u16("codec")?;
            let codec = CodecId::from_code(code).ok_or_else(|| {
                c.issue(
                    id::codestream::UNKNOWN_CODEC,
                    format!("codec id {code}; 0 to 3 are defined"),
                )
                .at(at)
            })?;
            c.reserved(2, "reference reserved")?;
            let chunk = c.u32("chunk index")?;
            let offset = c.u64("offset")?;
            let length = c.u32("length")?;
            let crc = c.u32("crc32")?;
            refs.push(StreamRef { codec, chunk, offset, length, crc });
        }
        levels.push(Level { counts, images: refs });
    }
    Ok(Block { width, height, placement, levels })
}

pub fn prov(c: &mut Cursor) -> Result<Provenance, Issue> {
    let tool = c.string("tool", id::provenance::MALFORMED)?;
    let source = c.string("source", id::provenance::MALFORMED)?;
    let raw_image_bytes = c.u64("raw image bytes")?;
    let n = c.u32("setting count")?;
    let n = c.expect_records(n as u64, 8, "settings")?;
    let mut settings = Vec::with_capacity(n);
    for _ in 0..n {
        let k = c.string("setting key", id::provenance::MALFORMED)?;
        let v = c.string("setting value", id::provenance::MALFORMED)?;
        settings.push((k, v));
    }
    c.finish()?;
    Ok(Provenance { tool, source, raw_image_bytes, settings })
}
