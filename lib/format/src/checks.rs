//! The rules that hold between fields and chunks (SPEC.md, "Validation"), checked on the
//! model. The reader runs them on every file it opens; the writer on every model it writes.

use std::collections::HashSet;

use crate::blocks::BlockGrid;
use crate::issue::id;
use crate::model::*;
pub use crate::payload_read::MAX_DIMS;
use crate::Issue;

/// Most parameter points a space may have.
pub const MAX_POINTS: u64 = 1 << 24;
/// Largest image side, in pixels.
pub const MAX_IMAGE_SIDE: u32 = 65536;
/// Largest texture side, in texels.
pub const MAX_TEXTURE_SIDE: u32 = 16384;
/// Largest number of pyramid levels.
pub const MAX_LEVELS: usize = 32;

/// A level image may decode to at most this many times the bytes of the file's codestreams
/// (rule 6009), so that no small file can make a reader allocate without bound.
pub const MAX_EXPANSION: u64 = 1 << 13;

/// All level images of a file together may decode to at most this many times the bytes of
/// its codestreams (rule 6010), so that decoding every one (validation, re-encoding) takes
/// time proportional to the codestreams.
pub const MAX_TOTAL_EXPANSION: u64 = 1 << 17;

/// The least C the limits of rules 6009 and 6010 count (SPEC.md 12): a file whose level
/// images read fewer codestream bytes (all of them empty, SPEC.md 11.2, in the extreme) is
/// measured as if they read this many, so that such a file may still declare level images
/// of up to 8 MiB each and 128 MiB in all.
pub const MIN_COUNTED_CODESTREAM_BYTES: u64 = 1 << 10;

/// The least number of codestream bytes a file whose level images decode to `images` (per
/// block: the bytes one level image decodes to and the number of level images) must read
/// for rules 6009 and 6010 to hold: 0 when [`MIN_COUNTED_CODESTREAM_BYTES`] suffices.
pub fn required_codestream_bytes(images: impl IntoIterator<Item = (u64, u64)>) -> u64 {
    let (mut largest, mut total) = (0u64, 0u64);
    for (bytes, count) in images {
        if count > 0 {
            largest = largest.max(bytes);
            total = total.saturating_add(bytes.saturating_mul(count));
        }
    }
    let need = largest.div_ceil(MAX_EXPANSION).max(total.div_ceil(MAX_TOTAL_EXPANSION));
    if need <= MIN_COUNTED_CODESTREAM_BYTES {
        0
    } else {
        need
    }
}

/// Bytes one level image of `layer`'s block `block` decodes to (4 bytes per value, all
/// planes); `u64::MAX` when its planes are malformed.
pub fn level_image_bytes<S>(layer: &Layer<S>, block: &Block<S>) -> u64 {
    let planes = crate::texture::LevelLayout::of(layer, block).planes();
    pis_codec::value_count(&planes).map_or(u64::MAX, |n| (n as u64).saturating_mul(4))
}

/// Bytes of codestream the level images of a file read: the union of the byte ranges its
/// references cover (a codestream shared by several references counts once), the quantity
/// rules 6009 and 6010 measure decoded sizes against.
pub fn referenced_bytes(c: &Container<StreamRef>) -> u64 {
    let mut ranges: Vec<(u32, u64, u64)> = Vec::new();
    for o in &c.objects {
        for l in &o.layers {
            for b in &l.blocks {
                for r in b.levels.iter().flat_map(|level| &level.images) {
                    ranges.push((r.chunk, r.offset, r.offset.saturating_add(r.length as u64)));
                }
            }
        }
    }
    ranges.sort_unstable();
    let (mut total, mut open): (u64, Option<(u32, u64, u64)>) = (0, None);
    for (chunk, start, end) in ranges {
        open = match open {
            Some((c, s, e)) if c == chunk && start <= e => Some((c, s, e.max(end))),
            Some((_, s, e)) => {
                total = total.saturating_add(e - s);
                Some((chunk, start, end))
            }
            None => Some((chunk, start, end)),
        };
    }
    total.saturating_add(open.map_or(0, |(_, s, e)| e - s))
}

/// Rules 6009 and 6010 for a file whose level images read `codestream_bytes` bytes of
/// codestream ([`referenced_bytes`]): with C = max(`codestream_bytes`,
/// [`MIN_COUNTED_CODESTREAM_BYTES`]), every level image decodes to at most
/// [`MAX_EXPANSION`] × C, all of them together to at most [`MAX_TOTAL_EXPANSION`] × C.
/// Checked before anything is decoded, so every allocation and all the decoding a file can
/// ask for are bounded by its codestreams, not by bytes a writer could pad the file with.
pub fn decoded_sizes<S>(c: &Container<S>, codestream_bytes: u64) -> Option<Issue> {
    let counted = codestream_bytes.max(MIN_COUNTED_CODESTREAM_BYTES);
    let limit = MAX_EXPANSION.saturating_mul(counted);
    let total_limit = MAX_TOTAL_EXPANSION.saturating_mul(counted);
    let of = || {
        if counted == codestream_bytes {
            format!("{codestream_bytes} bytes of codestream")
        } else {
            format!("{codestream_bytes} bytes of codestream (counted as {counted})")
        }
    };
    let mut total = 0u64;
    for (oi, o) in c.objects.iter().enumerate() {
        for (li, l) in o.layers.iter().enumerate() {
            for (bi, b) in l.blocks.iter().enumerate() {
                let bytes = level_image_bytes(l, b);
                let what = || format!("object {oi} '{}' layer {li} block {bi}", o.name);
                if bytes > limit {
                    let detail = format!(
                        "{}: {bytes} bytes per level image; {} allow {limit}",
                        what(),
                        of()
                    );
                    return Some(chunk(
                        Issue::new(id::layers::LEVEL_IMAGE_TOO_LARGE, detail),
                        "LAYR",
                    ));
                }
                let images = b.levels.iter().map(|level| level.images.len() as u64).sum::<u64>();
                total = total.saturating_add(bytes.saturating_mul(images));
                if total > total_limit {
                    let detail = format!("{}: the level images up to this block decode to {total} bytes; {} allow {total_limit}", what(), of());
                    return Some(chunk(
                        Issue::new(id::layers::LEVEL_IMAGES_TOO_LARGE, detail),
                        "LAYR",
                    ));
                }
            }
        }
    }
    None
}

/// Every rule broken by `c`, in chunk order.
pub fn check<S>(c: &Container<S>) -> Vec<Issue> {
    let meshes = vec![true; c.objects.len()];
    check_parsed(&Parsed {
        space: Some(&c.space),
        cameras: Some(&c.cameras),
        objects: Some(&c.objects),
        meshes: &meshes,
        layers: true,
        provenance: Some(c.provenance.as_ref()),
    })
}

/// The parts of a file that parsed: [`check_parsed`] checks them, and skips the rules whose
/// inputs did not parse.
pub(crate) struct Parsed<'a, S> {
    pub space: Option<&'a ParameterSpace>,
    pub cameras: Option<&'a CameraTable>,
    pub objects: Option<&'a [Object<S>]>,
    /// Per object: its mesh parsed.
    pub meshes: &'a [bool],
    /// The objects' layers parsed.
    pub layers: bool,
    /// `Some(p)` when the provenance parsed (`Some(None)`: the file has none).
    pub provenance: Option<Option<&'a Provenance>>,
}

/// Every rule broken by what parsed, in chunk order. Independent rules are all checked;
/// a rule that builds on another is checked only when that one holds: tables, block origins
/// and block grids are measured on the parameter space, so they wait for a valid space; a
/// layer's blocks wait for its mask and its object's block origins, and the texture
/// coordinates of its surface layers for its object's mesh.
pub(crate) fn check_parsed<S>(p: &Parsed<S>) -> Vec<Issue> {
    let mut out = Vec::new();
    let space = p.space.filter(|s| {
        let before = out.len();
        space(s, &mut out);
        out.len() == before
    });
    if let Some(t) = p.cameras {
        cameras(space, t, &mut out);
    }
    if let Some(objects) = p.objects {
        self::objects(space, objects, p.meshes, p.layers, &mut out);
    }
    if let Some(prov) = p.provenance {
        provenance(prov, &mut out);
        if let Some(objects) = p.objects {
            let named: Vec<(&str, crate::ObjectRole)> =
                objects.iter().map(|o| (o.name.as_str(), o.role)).collect();
            let names: Vec<&str> = named.iter().map(|o| o.0).collect();
            if let Err(detail) = crate::FileFilter::per_object(prov, &names) {
                if crate::FileFilter::of(prov).is_ok() {
                    out.push(chunk(Issue::new(id::provenance::FILTER, detail), "PROV"));
                }
            }
            if let Err(detail) = crate::tint::tints(prov, &named) {
                out.push(chunk(Issue::new(id::provenance::TINT, detail), "PROV"));
            }
            if let Err(detail) = crate::lens_model::lens_models(prov, &named) {
                out.push(chunk(Issue::new(id::provenance::LENS_MODEL, detail), "PROV"));
            }
        }
    }
    light_basis(p, &mut out);
    out
}

/// Rules 9006 (the light directions, which need the space) and 6011 (the layers that span
/// them).
fn light_basis<S>(p: &Parsed<S>, out: &mut Vec<Issue>) {
    let (Some(space), Some(prov)) = (p.space, p.provenance) else { return };
    let lights = match crate::relight::light_directions(prov, space) {
        Ok(l) => l,
        Err(detail) => {
            out.push(chunk(Issue::new(id::provenance::LIGHT_DIRECTIONS, detail), "PROV"));
            return;
        }
    };
    if let Some(objects) = p.objects {
        if let Err(detail) = crate::relight::check_basis_layers(objects, lights.as_ref()) {
            out.push(chunk(Issue::new(id::layers::LIGHT_BASIS, detail), "LAYR"));
        }
    }
}

/// Rules 9001–9003 on the provenance settings (9004 and 9005, which need the objects, above).
fn provenance(p: Option<&Provenance>, out: &mut Vec<Issue>) {
    if let Some(p) = p {
        let mut seen = HashSet::new();
        let mut repeated = HashSet::new();
        for (k, _) in &p.settings {
            if !seen.insert(k.as_str()) && repeated.insert(k.as_str()) {
                let n = p.settings.iter().filter(|(key, _)| key == k).count();
                out.push(chunk(
                    Issue::new(
                        id::provenance::KEY_REPEATED,
                        format!("key {k:?} appears {n} times"),
                    ),
                    "PROV",
                ));
            }
        }
    }
    if let Err(detail) = crate::FileFilter::of(p) {
        out.push(chunk(Issue::new(id::provenance::FILTER, detail), "PROV"));
    }
    if let Err(detail) = crate::DisplayFilter::of(p) {
        out.push(chunk(Issue::new(id::provenance::DISPLAY_FILTER, detail), "PROV"));
    }
}

fn chunk(i: Issue, fourcc: &str) -> Issue {
    // Chunk indices follow the writer's order; the reader re-tags with the real index.
    Issue { chunk: Some((fourcc.to_string(), usize::MAX)), ..i }
}

/// Whether `s` holds every 4xxx rule: the block grids measured on it are then defined.
pub(crate) fn space_holds(s: &ParameterSpace) -> bool {
    let mut out = Vec::new();
    space(s, &mut out);
    out.is_empty()
}

fn space(s: &ParameterSpace, out: &mut Vec<Issue>) {
    let e = |id, d: String| chunk(Issue::new(id, d), "PSPC");
    let n = s.dims.len() as u32;
    if n == 0 || n > MAX_DIMS {
        out.push(e(
            id::space::DIMENSION_COUNT,
            format!("{n} dimensions, expected 1 to {MAX_DIMS}"),
        ));
        return;
    }
    let mut names = HashSet::new();
    for (k, d) in s.dims.iter().enumerate() {
        if d.name.is_empty() || !names.insert(d.name.as_str()) {
            out.push(e(
                id::space::DIMENSION_NAME,
                format!("dimension {k} name {:?} is empty or repeated", d.name),
            ));
        }
        if d.values.is_empty() {
            out.push(e(
                id::space::NO_SAMPLES,
                format!("dimension {k} '{}' has no samples", d.name),
            ));
        }
        if d.block_size == 0 {
            out.push(e(
                id::space::ZERO_BLOCK_SIZE,
                format!("dimension {k} '{}' has block size 0", d.name),
            ));
        }
        if d.values.iter().any(|v| !v.is_finite()) || d.values.windows(2).any(|w| w[1] <= w[0]) {
            out.push(e(
                id::space::VALUES_NOT_INCREASING,
                format!("dimension {k} '{}' values {:?}", d.name, d.values),
            ));
        }
    }
    let points = s.dims.iter().try_fold(1u64, |p, d| p.checked_mul(d.values.len() as u64));
    if points.is_none_or(|p| p > MAX_POINTS) {
        out.push(e(id::space::TOO_MANY_POINTS, format!("more than {MAX_POINTS} points")));
    }
}

fn mask_ok(s: &ParameterSpace, mask: DepMask) -> bool {
    mask.0 >> s.dims.len() == 0
}

/// Checks a table's mask and length (rules 5002 and 5001).
fn table(
    s: &ParameterSpace,
    mask: DepMask,
    len: usize,
    what: &str,
    fourcc: &str,
    out: &mut Vec<Issue>,
) -> bool {
    if !mask_ok(s, mask) {
        out.push(chunk(
            Issue::new(
                id::cameras::MASK_NAMES_MISSING_DIMENSION,
                format!("{what} mask {:#x}, the space has {} dimensions", mask.0, s.dims.len()),
            ),
            fourcc,
        ));
        return false;
    }
    let expected = s.table_len(mask);
    if len as u64 != expected {
        out.push(chunk(
            Issue::new(
                id::cameras::TABLE_SIZE,
                format!("{what}: {len} entries, expected {expected}"),
            ),
            fourcc,
        ));
        return false;
    }
    true
}

fn finite(v: &[f32]) -> bool {
    v.iter().all(|x| x.is_finite())
}

/// Whether a row-major 3×4 transform is rigid (rules 5003 and 5106, SPEC.md 6.4): with the
/// rows r0, r1, r2 of its 3×3 part widened to f64, every rᵢ·rⱼ differs from δᵢⱼ, and the
/// determinant (cofactor expansion along r0) from 1, by less than 10⁻³.
pub fn rigid(m: &[f32; 12]) -> bool {
    let r = |i: usize| [m[4 * i] as f64, m[4 * i + 1] as f64, m[4 * i + 2] as f64];
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let (a, b, c) = (r(0), r(1), r(2));
    let det = a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
        + a[2] * (b[0] * c[1] - b[1] * c[0]);
    let ok = |x: f64, want: f64| (x - want).abs() < 1e-3;
    ok(dot(a, a), 1.0)
        && ok(dot(b, b), 1.0)
        && ok(dot(c, c), 1.0)
        && ok(dot(a, b), 0.0)
        && ok(dot(a, c), 0.0)
        && ok(dot(b, c), 0.0)
        && ok(det, 1.0)
}

fn cameras(s: Option<&ParameterSpace>, t: &CameraTable, out: &mut Vec<Issue>) {
    let e = |id, d: String| chunk(Issue::new(id, d), "CAMS");
    if t.width == 0 || t.height == 0 || t.width > MAX_IMAGE_SIDE || t.height > MAX_IMAGE_SIDE {
        out.push(e(
            id::cameras::IMAGE_SIZE,
            format!("{}×{} pixels, each side must be 1 to {MAX_IMAGE_SIDE}", t.width, t.height),
        ));
    }
    if let Some(s) = s {
        table(s, t.depends_on, t.cameras.len(), "camera table", "CAMS", out);
    }
    for (i, c) in t.cameras.iter().enumerate() {
        let ok = finite(&c.world_from_camera)
            && rigid(&c.world_from_camera)
            && c.yfov.is_finite()
            && c.yfov > 0.0
            && c.yfov < std::f32::consts::PI
            && c.znear.is_finite()
            && c.znear > 0.0
            && c.zfar > c.znear
            && !c.zfar.is_nan();
        if !ok {
            out.push(e(id::cameras::INVALID_CAMERA, format!("camera {i}: {c:?}")));
        }
    }
}

fn objects<S>(
    s: Option<&ParameterSpace>,
    objects: &[Object<S>],
    meshes: &[bool],
    layers_parsed: bool,
    out: &mut Vec<Issue>,
) {
    let n = objects.len();
    if n == 0 || n > 65535 {
        out.push(chunk(
            Issue::new(id::objects::OBJECT_COUNT, format!("{n} objects, expected 1 to 65535")),
            "OBJS",
        ));
    }
    let mut names = HashSet::new();
    for (oi, o) in objects.iter().enumerate() {
        let e =
            |id, d: String| chunk(Issue::new(id, format!("object {oi} '{}': {d}", o.name)), "OBJS");
        if o.name.is_empty() || !names.insert(o.name.as_str()) {
            out.push(e(id::objects::OBJECT_NAME, "name is empty or repeated".into()));
        }
        let sh = &o.shading;
        let unit = |v: &f32| (0.0..=1.0).contains(v);
        let ior_ok = sh.ior.is_finite() && sh.ior >= 1.0;
        let absorption_ok = sh.absorption.iter().all(|v| v.is_finite() && *v >= 0.0);
        if !(sh.f0.iter().all(unit) && ior_ok && absorption_ok) {
            out.push(e(id::objects::SHADING_OUT_OF_RANGE, format!("{sh:?}")));
        }
        let mut stagger_ok = s.is_some_and(|s| o.stagger.len() == s.dims.len());
        for (k, (&off, d)) in o.stagger.iter().zip(s.map_or(&[][..], |s| &s.dims)).enumerate() {
            if off >= d.block_size {
                out.push(e(
                    id::objects::STAGGER_NOT_BELOW_BLOCK,
                    format!("offset {off} along dimension {k} with block size {}", d.block_size),
                ));
                stagger_ok = false;
            }
        }
        let what = format!("object {oi} transforms");
        if s.is_none_or(|s| {
            table(s, o.transforms.depends_on, o.transforms.transforms.len(), &what, "OBJS", out)
        }) {
            for (t, m) in o.transforms.transforms.iter().enumerate() {
                if !finite(m) || !rigid(m) {
                    out.push(e(
                        id::objects::TRANSFORM_NOT_RIGID,
                        format!("transform {t} is not a finite rigid transform: {m:?}"),
                    ));
                }
            }
        }
        let has_mesh = meshes.get(oi).copied().unwrap_or(false);
        if has_mesh {
            mesh(oi, o, out);
        }
        if layers_parsed {
            layers(s.filter(|_| stagger_ok), oi, o, has_mesh, out);
        }
    }
}

fn mesh<S>(oi: usize, o: &Object<S>, out: &mut Vec<Issue>) {
    let e = |id, d: String| {
        chunk(Issue::new(id, format!("mesh of object {oi} '{}': {d}", o.name)), "MESH")
    };
    let m = &o.mesh;
    if m.positions.is_empty() {
        out.push(e(id::mesh::NO_VERTICES, "vertex count 0".into()));
        return;
    }
    if m.indices.is_empty() || !m.indices.len().is_multiple_of(3) {
        out.push(e(id::mesh::INDEX_COUNT, format!("{} indices", m.indices.len())));
    }
    if let Some(i) = m.indices.iter().position(|&i| i as usize >= m.positions.len()) {
        out.push(e(
            id::mesh::INDEX_OUT_OF_RANGE,
            format!("index {i} is {}, there are {} vertices", m.indices[i], m.positions.len()),
        ));
    }
    let all_finite = m.positions.iter().all(|p| finite(p))
        && m.normals.as_ref().is_none_or(|n| n.iter().all(|p| finite(p)))
        && m.texcoords.as_ref().is_none_or(|t| t.iter().all(|p| finite(p)));
    let lengths = m.normals.as_ref().is_none_or(|n| n.len() == m.positions.len())
        && m.texcoords.as_ref().is_none_or(|t| t.len() == m.positions.len());
    if !all_finite || !lengths {
        out.push(e(
            id::mesh::VERTEX_NOT_FINITE,
            "non-finite values, or attribute arrays of unequal length".into(),
        ));
    }
    if m.hull_triangles as usize > m.indices.len() / 3 {
        out.push(e(
            id::mesh::TOO_MANY_HULL_TRIANGLES,
            format!("{} hull triangles, the mesh has {}", m.hull_triangles, m.indices.len() / 3),
        ));
    }
}

/// The rules of `o`'s layers. `has_mesh`: the object's mesh parsed (the texture coordinates
/// a surface layer needs, rule 6003); `grid`: the space, when it and the object's block
/// origins hold (the block grids, rules 6005–6007 and 7xxx).
fn layers<S>(
    grid: Option<&ParameterSpace>,
    oi: usize,
    o: &Object<S>,
    has_mesh: bool,
    out: &mut Vec<Issue>,
) {
    let mut slots = HashSet::new();
    // A translucent object (SPEC.md 7.1, 9): its first surface layer carries its opacity.
    let translucent = o.layers.iter().any(|l| l.mapping == Mapping::Surface && l.channels == 4);
    for (li, l) in o.layers.iter().enumerate() {
        let e = |id, d: String| {
            chunk(
                Issue::new(
                    id,
                    format!("object {oi} '{}' layer {li} ({}): {d}", o.name, l.kind.name()),
                ),
                "LAYR",
            )
        };
        let surface = l.mapping == Mapping::Surface;
        let combo = if surface {
            !l.kind.is_shell()
                && l.term == Term::Surface
                && match l.channels {
                    3 => {
                        l.combine == Combine::Add || !translucent && l.combine == Combine::Multiply
                    }
                    4 => l.combine == Combine::Add && l.order == 0,
                    _ => false,
                }
                && (o.mesh.texcoords.is_some() || !has_mesh)
        } else {
            !translucent
                && l.kind.is_shell()
                && l.combine == Combine::Over
                && matches!(l.channels, 3 | 4)
                && match l.term {
                    Term::Reflection => o.role != ObjectRole::Diffuse,
                    Term::Refraction => o.role == ObjectRole::Refractive,
                    Term::Surface => false,
                }
        };
        if !combo {
            out.push(e(
                id::layers::INVALID_COMBINATION,
                format!(
                    "mapping {}, term {}, combine {}, {} channels on a {} object{}",
                    l.mapping.name(),
                    l.term.name(),
                    l.combine.name(),
                    l.channels,
                    o.role.name(),
                    if surface && o.mesh.texcoords.is_none() {
                        " whose mesh has no texcoords"
                    } else {
                        ""
                    }
                ),
            ));
        }
        if l.basis != 0 && !crate::relight::basis_layer_fits(l) {
            out.push(e(
                id::layers::INVALID_COMBINATION,
                format!(
                    "light basis {} on a {}-channel {} layer combined by {} (a 3-channel surface layer added, basis at most {})",
                    l.basis,
                    l.channels,
                    l.mapping.name(),
                    l.combine.name(),
                    crate::relight::MAX_COEFFICIENTS
                ),
            ));
        }
        if !slots.insert((l.term as u8, l.order, l.basis)) {
            out.push(e(
                id::layers::TERM_ORDER_REPEATED,
                format!(
                    "term {} order {} light basis {} is already used",
                    l.term.name(),
                    l.order,
                    l.basis
                ),
            ));
        }
        if !(l.gamma.is_finite() && l.gamma > 0.0) {
            out.push(e(id::layers::GAMMA, format!("gamma {}", l.gamma)));
        }
        let Some(s) = grid else {
            continue;
        };
        if !mask_ok(s, l.depends_on) {
            out.push(e(
                id::cameras::MASK_NAMES_MISSING_DIMENSION,
                format!("mask {:#x}, the space has {} dimensions", l.depends_on.0, s.dims.len()),
            ));
            continue;
        }
        let grid = BlockGrid::new(s, l.depends_on, &o.stagger);
        if l.blocks.len() as u64 != grid.block_count() {
            out.push(e(
                id::layers::BLOCK_COUNT,
                format!("{} blocks, the grid has {}", l.blocks.len(), grid.block_count()),
            ));
            continue;
        }
        for (bi, b) in l.blocks.iter().enumerate() {
            let e = |id, d: String| e(id, format!("block {bi}: {d}"));
            let square = match b.placement {
                Placement::Shell { shape, .. } => shape == ShellShape::Quad || b.width == b.height,
                Placement::Surface { .. } => true,
            };
            if b.width == 0
                || b.height == 0
                || b.width > MAX_TEXTURE_SIDE
                || b.height > MAX_TEXTURE_SIDE
                || !square
            {
                out.push(e(id::layers::TEXTURE_SIZE, format!("{}×{} texels", b.width, b.height)));
            }
            if let Some(why) = placement(&b.placement, l.mapping) {
                out.push(e(id::layers::BLOCK_PLACEMENT, why));
            }
            if let Placement::Surface { repeat, .. } = b.placement {
                for (axis, wraps, side) in [("s", repeat[0], b.width), ("t", repeat[1], b.height)] {
                    if wraps && !side.is_power_of_two() {
                        out.push(e(id::layers::BLOCK_PLACEMENT, format!("the texture wraps along {axis} but its side {side} is not a power of two")));
                    }
                }
            }
            pyramid(&grid.extent(bi), l.depends_on.count(), &b.levels, &mut |id, d| {
                out.push(e(id, d))
            });
        }
    }
}

fn placement(p: &Placement, mapping: Mapping) -> Option<String> {
    match (p, mapping) {
        (Placement::Surface { cut, .. }, Mapping::Surface)
            if cut.iter().flatten().any(|c| !(0.0..1.0).contains(c)) =>
        {
            Some(format!("branch cuts {cut:?} must lie in [0, 1)"))
        }
        (Placement::Surface { affine, .. }, Mapping::Surface) => {
            let det = affine[0] * affine[3] - affine[1] * affine[2];
            (!finite(affine) || det == 0.0 || !det.is_finite())
                .then(|| format!("affine {affine:?} is not invertible"))
        }
        (Placement::Shell { shape, origin, params, .. }, Mapping::Shell) => {
            if !finite(origin) || !finite(params) {
                return Some(format!("{} with non-finite values", shape.name()));
            }
            let p = params;
            let ok = match shape {
                ShellShape::Sphere => p[0] > 0.0 && p[1..].iter().all(|&v| v == 0.0),
                ShellShape::Ellipsoid => {
                    p[..3].iter().all(|&v| v > 0.0) && p[3..].iter().all(|&v| v == 0.0)
                }
                ShellShape::Box => (0..3).all(|k| p[k] < origin[k] && origin[k] < p[k + 3]),
                ShellShape::Cylinder => {
                    p[0] > 0.0 && p[1] < p[2] && p[3..].iter().all(|&v| v == 0.0)
                }
                ShellShape::Quad => {
                    let (u, v) = ([p[0], p[1], p[2]], [p[3], p[4], p[5]]);
                    let c = [
                        u[1] * v[2] - u[2] * v[1],
                        u[2] * v[0] - u[0] * v[2],
                        u[0] * v[1] - u[1] * v[0],
                    ];
                    c.iter().any(|&x| x != 0.0)
                }
                ShellShape::Depth => {
                    let int_in = |v: f32, hi: f32| v.fract() == 0.0 && (1.0..=hi).contains(&v);
                    int_in(p[0], 256.0)
                        && int_in(p[1], 64.0)
                        && p[2] > 0.0
                        && p[3..].iter().all(|&v| v == 0.0)
                }
            };
            (!ok).then(|| format!("{} parameters {params:?} with origin {origin:?}", shape.name()))
        }
        (Placement::Surface { .. }, Mapping::Shell) => {
            Some("a shell layer's block has no shell shape".into())
        }
        (Placement::Shell { .. }, Mapping::Surface) => {
            Some("a surface layer's block has a shell shape".into())
        }
    }
}

/// Rules 7001–7004 for one block's levels.
fn pyramid<S>(extent: &[u32], dims: usize, levels: &[Level<S>], push: &mut dyn FnMut(u16, String)) {
    if levels.is_empty() || levels.len() > MAX_LEVELS {
        push(
            id::pyramid::LEVEL_COUNT,
            format!("{} levels, expected 1 to {MAX_LEVELS}", levels.len()),
        );
        return;
    }
    if dims == 0 && levels.len() > 1 {
        push(
            id::pyramid::STATIC_LAYER_LEVELS,
            format!("{} levels; a layer with dependency mask 0 has exactly 1", levels.len()),
        );
    }
    for (lv, level) in levels.iter().enumerate() {
        let images: u64 = level.counts.iter().map(|&c| c as u64).product();
        if level.counts.len() != dims || level.images.len() as u64 != images {
            push(
                id::pyramid::LEVEL_COUNTS,
                format!(
                    "level {lv} has {} counts and {} images",
                    level.counts.len(),
                    level.images.len()
                ),
            );
            return;
        }
    }
    if levels[0].counts.iter().any(|&c| c != 1) {
        push(
            id::pyramid::TOP_LEVEL_NOT_ONE_SAMPLE,
            format!("top level counts {:?}", levels[0].counts),
        );
    }
    for (lv, w) in levels.windows(2).enumerate() {
        let bad = w[0].counts.iter().zip(&w[1].counts).any(|(a, b)| b < a);
        if bad {
            push(
                id::pyramid::LEVEL_COUNTS,
                format!("level {} counts {:?} after {:?}", lv + 1, w[1].counts, w[0].counts),
            );
        }
    }
    for (lv, level) in levels.iter().enumerate() {
        if level.counts.iter().zip(extent).any(|(&c, &e)| c == 0 || c > e) {
            push(
                id::pyramid::LEVEL_COUNTS,
                format!("level {lv} counts {:?} for block extent {extent:?}", level.counts),
            );
        }
    }
    let last = &levels[levels.len() - 1].counts;
    if last.as_slice() != extent {
        push(
            id::pyramid::FINEST_LEVEL_EXTENT,
            format!("finest level counts {last:?}, block extent {extent:?}"),
        );
    }
}
