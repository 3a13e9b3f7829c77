//! `pis-inspect`: what a `.pis` file holds, how its bytes divide, and its textures.

use std::collections::BTreeMap;
use std::fmt::Write;
use std::path::Path;

use anyhow::Context;
use pis_format::chunk::{ChunkEntry, ENTRY_LEN, HEADER_LEN};
use pis_format::*;
use serde::Serialize;

use pis_pack::images::{write_exr, write_png};

/// The summary printed by `pis-inspect FILE` and, as JSON, by `--json`. Field names are
/// documented in README.md and stay stable.
#[derive(Serialize)]
pub struct Summary {
    pub file: String,
    pub version: String,
    pub file_size: u64,
    pub points: u64,
    pub dimensions: Vec<DimensionSummary>,
    pub image: ImageSummary,
    pub objects: Vec<ObjectSummary>,
    pub codecs: BTreeMap<String, CodecSummary>,
    pub bytes: Bytes,
    /// Raw image set bytes (3 bytes per pixel per point) over the bytes a player uses (the
    /// file size less the lossless master, `bytes.master`); null without provenance.
    pub ratio: Option<f64>,
    /// The same, leaving out the geometry (`MESH` chunks).
    pub ratio_without_geometry: Option<f64>,
    pub provenance: Option<ProvenanceSummary>,
}

#[derive(Serialize)]
pub struct DimensionSummary {
    pub name: String,
    pub kind: &'static str,
    pub samples: usize,
    pub block_size: u32,
    pub periodic: bool,
    pub unit: String,
    pub values: Vec<f32>,
}

#[derive(Serialize)]
pub struct ImageSummary {
    pub width: u32,
    pub height: u32,
    pub cameras: usize,
    pub camera_depends_on: Vec<String>,
}

#[derive(Serialize)]
pub struct ObjectSummary {
    pub name: String,
    pub role: &'static str,
    /// A surface layer carries the object's opacity (SPEC.md 7.1).
    pub translucent: bool,
    /// Shading constants (SPEC.md 6.4): reflectance at normal incidence (Schlick's F0),
    /// linear RGB.
    pub f0: [f32; 3],
    /// Index of refraction.
    pub ior: f32,
    /// Beer–Lambert absorption coefficients per unit length, linear RGB.
    pub absorption: [f32; 3],
    pub vertices: usize,
    /// Whether the mesh carries vertex normals.
    pub normals: bool,
    pub triangles: usize,
    /// Leading triangles on the convex hull (drawn with the most distant shell only).
    pub hull_triangles: u32,
    pub stagger: Vec<u32>,
    pub transforms: usize,
    pub layers: Vec<LayerSummary>,
    pub bytes: u64,
}

#[derive(Serialize)]
pub struct LayerSummary {
    pub kind: &'static str,
    pub mapping: &'static str,
    pub term: &'static str,
    pub order: u8,
    pub combine: &'static str,
    pub channels: u8,
    pub gamma: f32,
    pub mip_mode: &'static str,
    pub depends_on: Vec<String>,
    pub blocks: usize,
    /// Largest used texture size over the blocks.
    pub width: u32,
    pub height: u32,
    /// Distinct texture placements (size, branch cuts, affine map, wrapping) over the
    /// blocks of a surface layer (thesis 3.2: per parameter block).
    pub placements: usize,
    /// Blocks whose placement makes a branch cut.
    pub cut_blocks: usize,
    /// Most pyramid levels in a block.
    pub levels: usize,
    pub codestreams: usize,
    pub bytes: u64,
    /// Shell shape of the first block, for shell layers.
    pub shell: Option<&'static str>,
    /// Lookups per pixel side of the first block, for shell layers (SPEC.md 8.2).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lookups: Option<u32>,
    /// A depth shell's march steps, of the first block (SPEC.md 7.3 `p[1]`, 8.5).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub march_steps: Option<u32>,
}

#[derive(Serialize, Default)]
pub struct CodecSummary {
    pub codestreams: usize,
    pub bytes: u64,
}

/// Bytes per kind of content; `total` is the file size, `header` the header, chunk table and
/// padding, `other` chunks of types this version does not define.
pub use crate::diff::ChunkBytes as Bytes;

#[derive(Serialize)]
pub struct ProvenanceSummary {
    pub tool: String,
    pub source: String,
    pub raw_image_bytes: u64,
    pub settings: BTreeMap<String, String>,
}

fn dep_names(space: &ParameterSpace, mask: DepMask) -> Vec<String> {
    mask.dims().filter_map(|k| space.dims.get(k)).map(|d| d.name.clone()).collect()
}

pub fn summarize(r: &PisReader) -> Summary {
    let c = r.container();
    let bytes = Bytes::of(r);

    let mut codecs: BTreeMap<String, CodecSummary> = BTreeMap::new();
    let objects = c
        .objects
        .iter()
        .map(|o| {
            let layers: Vec<LayerSummary> = o
                .layers
                .iter()
                .map(|l| {
                    let refs: Vec<&StreamRef> = l
                        .blocks
                        .iter()
                        .flat_map(|b| &b.levels)
                        .flat_map(|lv| &lv.images)
                        .collect();
                    for s in &refs {
                        let e = codecs.entry(s.codec.name().to_string()).or_default();
                        e.codestreams += 1;
                        e.bytes += s.length as u64;
                    }
                    let first_shell = l.blocks.first().and_then(|b| match b.placement {
                        Placement::Shell { shape, lookups, params, .. } => {
                            Some((shape, lookups, params[1]))
                        }
                        Placement::Surface { .. } => None,
                    });
                    LayerSummary {
                        kind: l.kind.name(),
                        mapping: l.mapping.name(),
                        term: l.term.name(),
                        order: l.order,
                        combine: l.combine.name(),
                        channels: l.channels,
                        gamma: l.gamma,
                        mip_mode: l.mip_mode.name(),
                        depends_on: dep_names(&c.space, l.depends_on),
                        blocks: l.blocks.len(),
                        width: l.blocks.iter().map(|b| b.width).max().unwrap_or(0),
                        height: l.blocks.iter().map(|b| b.height).max().unwrap_or(0),
                        placements: surface_placements(&l.blocks),
                        cut_blocks: l.blocks.iter().filter(|b| matches!(b.placement, Placement::Surface { cut, .. } if cut.iter().any(Option::is_some))).count(),
                        levels: l.blocks.iter().map(|b| b.levels.len()).max().unwrap_or(0),
                        codestreams: refs.len(),
                        bytes: refs.iter().map(|s| s.length as u64).sum(),
                        shell: first_shell.map(|(shape, _, _)| shape.name()),
                        lookups: first_shell.map(|(_, k, _)| k),
                        march_steps: first_shell
                            .filter(|&(shape, _, _)| shape == ShellShape::Depth)
                            .map(|(_, _, steps)| steps as u32),
                    }
                })
                .collect();
            ObjectSummary {
                name: o.name.clone(),
                role: o.role.name(),
                translucent: o
                    .layers
                    .iter()
                    .any(|l| l.mapping == pis_format::Mapping::Surface && l.channels == 4),
                f0: o.shading.f0,
                ior: o.shading.ior,
                absorption: o.shading.absorption,
                vertices: o.mesh.positions.len(),
                normals: o.mesh.normals.is_some(),
                triangles: o.mesh.indices.len() / 3,
                hull_triangles: o.mesh.hull_triangles,
                stagger: o.stagger.clone(),
                transforms: o.transforms.transforms.len(),
                bytes: layers.iter().map(|l| l.bytes).sum(),
                layers,
            }
        })
        .collect();
    let raw = c.provenance.as_ref().map(|p| p.raw_image_bytes).filter(|&b| b > 0);
    Summary {
        file: r.path().display().to_string(),
        version: format!("{}.{}", r.header().major, r.header().minor),
        file_size: r.len(),
        points: c.space.point_count(),
        dimensions: c
            .space
            .dims
            .iter()
            .map(|d| DimensionSummary {
                name: d.name.clone(),
                kind: d.kind.name(),
                samples: d.values.len(),
                block_size: d.block_size,
                periodic: d.periodic,
                unit: d.unit.clone(),
                values: d.values.clone(),
            })
            .collect(),
        image: ImageSummary {
            width: c.cameras.width,
            height: c.cameras.height,
            cameras: c.cameras.cameras.len(),
            camera_depends_on: dep_names(&c.space, c.cameras.depends_on),
        },
        objects,
        codecs,
        ratio: raw.map(|b| b as f64 / (bytes.total - bytes.master).max(1) as f64),
        ratio_without_geometry: raw
            .map(|b| b as f64 / (bytes.total - bytes.master - bytes.geometry).max(1) as f64),
        bytes,
        provenance: c.provenance.as_ref().map(|p| ProvenanceSummary {
            tool: p.tool.clone(),
            source: p.source.clone(),
            raw_image_bytes: p.raw_image_bytes,
            settings: p.settings.iter().cloned().collect(),
        }),
    }
}

/// Distinct surface placements among `blocks` (0 for a shell layer).
fn surface_placements<S>(blocks: &[pis_format::Block<S>]) -> usize {
    let mut seen: Vec<&pis_format::Block<S>> = Vec::new();
    for b in blocks {
        if matches!(b.placement, Placement::Surface { .. })
            && !seen.iter().any(|s| s.same_placement(b))
        {
            seen.push(b);
        }
    }
    seen.len()
}

/// ", N placements" / ", N with a branch cut" where a surface layer's blocks differ or cut.
fn placements_text(l: &LayerSummary) -> String {
    let mut s = String::new();
    if l.placements > 1 {
        s += &format!(" in {} placements", l.placements);
    }
    if l.cut_blocks > 0 {
        s += &format!(", {} with a branch cut", l.cut_blocks);
    }
    s
}

/// An RGB triple as `(r, g, b)`, each with at most 4 decimals.
fn rgb(v: [f32; 3]) -> String {
    let c: Vec<String> = v
        .iter()
        .map(|x| {
            let s = format!("{x:.4}");
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        })
        .collect();
    format!("({})", c.join(", "))
}

fn human(n: u64) -> String {
    match n {
        n if n >= 10 << 20 => format!("{:.1} MiB", n as f64 / (1u64 << 20) as f64),
        n if n >= 10 << 10 => format!("{:.1} KiB", n as f64 / 1024.0),
        n => format!("{n} B"),
    }
}

/// The readable report.
pub fn render(s: &Summary) -> String {
    let mut o = String::new();
    let _ = writeln!(
        o,
        "{}: PIS {} container, {} ({} bytes)",
        s.file,
        s.version,
        human(s.file_size),
        s.file_size
    );
    let _ =
        writeln!(o, "\nParameter space: {} dimensions, {} points", s.dimensions.len(), s.points);
    for d in &s.dimensions {
        let range = match (d.values.first(), d.values.last()) {
            (Some(a), Some(b)) => format!("{a} .. {b} {}", d.unit),
            _ => String::new(),
        };
        let periodic = if d.periodic { ", periodic" } else { "" };
        let _ = writeln!(
            o,
            "  {:<12} {:<13} {:>4} samples  {:<20} block {}{periodic}",
            d.name,
            d.kind,
            d.samples,
            range.trim_end(),
            d.block_size
        );
    }
    let _ = writeln!(
        o,
        "\nImages: {}x{}, {} camera(s) varying with [{}]",
        s.image.width,
        s.image.height,
        s.image.cameras,
        s.image.camera_depends_on.join(", ")
    );
    let _ = writeln!(o, "\nObjects: {}", s.objects.len());
    for ob in &s.objects {
        let _ = writeln!(
            o,
            "  {} ({}{}): {} vertices{}, {} triangles{}, {} transform(s), block origins {:?}, {}",
            ob.name,
            ob.role,
            if ob.translucent { ", translucent" } else { "" },
            ob.vertices,
            if ob.normals { " with normals" } else { "" },
            ob.triangles,
            if ob.hull_triangles > 0 {
                format!(" ({} on the convex hull)", ob.hull_triangles)
            } else {
                String::new()
            },
            ob.transforms,
            ob.stagger,
            human(ob.bytes)
        );
        let _ = writeln!(
            o,
            "    shading: f0 {}, ior {}, absorption {}",
            rgb(ob.f0),
            ob.ior,
            rgb(ob.absorption)
        );
        for (i, l) in ob.layers.iter().enumerate() {
            let mapping = match l.shell {
                Some(shape) => {
                    let steps =
                        l.march_steps.map_or(String::new(), |n| format!(" ({n} march steps)"));
                    let lookups = match l.lookups {
                        Some(k) if k > 1 => format!(", {k}×{k} lookups"),
                        _ => String::new(),
                    };
                    format!("{shape} shell{steps}{lookups}")
                }
                None => "surface".to_string(),
            };
            let deps = if l.depends_on.is_empty() {
                "constant".to_string()
            } else {
                l.depends_on.join(" x ")
            };
            let _ = writeln!(
                o,
                "    layer {i}: {:<11} {:<15} term {:<10} {}ch, gamma {}, varies with {deps}: {} block(s) of up to {}x{} texels{}, {} level(s), mips {}, {}",
                l.kind,
                mapping,
                l.term,
                l.channels,
                l.gamma,
                l.blocks,
                l.width,
                l.height,
                placements_text(l),
                l.levels,
                l.mip_mode,
                human(l.bytes)
            );
        }
    }
    let _ = writeln!(o, "\nCodecs:");
    for (name, c) in &s.codecs {
        let _ = writeln!(o, "  {name:<10} {} codestreams, {}", c.codestreams, human(c.bytes));
    }
    let b = &s.bytes;
    let _ = writeln!(o, "\nBytes:");
    for (name, n) in [
        ("header + chunk table + padding", b.header),
        ("parameter space", b.parameter_space),
        ("cameras", b.cameras),
        ("objects", b.objects),
        ("geometry", b.geometry),
        ("layer index", b.layer_index),
        ("codestreams", b.codestreams),
        ("provenance", b.provenance),
        ("lossless master", b.master),
        ("other chunks", b.other),
    ] {
        if n > 0 {
            let _ = writeln!(
                o,
                "  {name:<32} {:>10}  {:5.1}%",
                human(n),
                100.0 * n as f64 / b.total as f64
            );
        }
    }
    match (s.ratio, s.ratio_without_geometry, &s.provenance) {
        (Some(r), Some(g), Some(p)) => {
            let _ = writeln!(
                o,
                "\nCompression ratio: {r:.1}:1 ({g:.1}:1 without geometry) against a raw image set of {}{}",
                human(p.raw_image_bytes),
                if b.master > 0 { "; the lossless master is not counted" } else { "" }
            );
        }
        _ => {
            let _ =
                writeln!(o, "\nCompression ratio: unknown (the file records no raw image size)");
        }
    }
    if let Some(p) = &s.provenance {
        let settings: Vec<String> = p.settings.iter().map(|(k, v)| format!("{k}={v}")).collect();
        let source =
            if p.source.is_empty() { String::new() } else { format!(" from {}", p.source) };
        let _ = writeln!(o, "Written by {}{source}; settings: {}", p.tool, settings.join(", "));
    }
    o
}

/// Rows for `--chunks`.
#[derive(Serialize)]
pub struct ChunkRow {
    pub index: usize,
    #[serde(rename = "type")]
    pub fourcc: String,
    pub required: bool,
    pub known: bool,
    pub offset: u64,
    pub length: u64,
    pub crc32: String,
    /// "ok", "mismatch" or "unreadable".
    pub checksum: &'static str,
}

pub fn chunk_rows(chunks: &[ChunkEntry], crc_ok: &[Option<bool>]) -> Vec<ChunkRow> {
    chunks
        .iter()
        .enumerate()
        .map(|(i, e)| ChunkRow {
            index: i,
            fourcc: e.name(),
            required: e.required(),
            known: pis_format::chunk::rule(e.fourcc).is_some(),
            offset: e.offset,
            length: e.length,
            crc32: format!("{:08x}", e.crc),
            checksum: match crc_ok.get(i).copied().flatten() {
                Some(true) => "ok",
                Some(false) => "mismatch",
                None => "unreadable",
            },
        })
        .collect()
}

pub fn render_chunks(rows: &[ChunkRow]) -> String {
    let mut o = String::new();
    let _ = writeln!(
        o,
        "{:>3}  {:<6} {:>10} {:>10}  {:<8}  {:<9} flags",
        "#", "type", "offset", "length", "crc32", "checksum"
    );
    let _ = writeln!(o, "  -  header {:>10} {:>10}", 0, HEADER_LEN);
    let _ = writeln!(o, "  -  table  {:>10} {:>10}", HEADER_LEN, rows.len() as u64 * ENTRY_LEN);
    for r in rows {
        let flags = match (r.required, r.known) {
            (true, true) => "required",
            (false, true) => "optional",
            (true, false) => "required, unknown type",
            (false, false) => "optional, unknown type (skipped)",
        };
        let _ = writeln!(
            o,
            "{:>3}  {:<6} {:>10} {:>10}  {}  {:<9} {flags}",
            r.index, r.fourcc, r.offset, r.length, r.crc32, r.checksum
        );
    }
    o
}

/// Parses `--at v1,v2,...` into the nearest sample indices.
pub fn parse_point(space: &ParameterSpace, at: Option<&str>) -> anyhow::Result<Vec<u32>> {
    let Some(at) = at else {
        return Ok(vec![0; space.dims.len()]);
    };
    let values: Vec<f32> = at
        .split(',')
        .map(|v| v.trim().parse::<f32>().with_context(|| format!("--at: '{v}' is not a number")))
        .collect::<anyhow::Result<_>>()?;
    if values.len() != space.dims.len() || values.iter().any(|v| !v.is_finite()) {
        let names: Vec<&str> = space.dims.iter().map(|d| d.name.as_str()).collect();
        anyhow::bail!("--at needs {} finite values ({}), got '{at}'", names.len(), names.join(","));
    }
    Ok(space.nearest(&values))
}

/// Cube faces in the order stored (SPEC.md, "Shell faces").
pub const FACE_NAMES: [&str; 6] = ["px", "nx", "py", "ny", "pz", "nz"];

/// Writes one plane of `width` × `height` × `channels` values to a file.
type PlaneWriter = fn(&Path, u32, u32, u32, &[f32]) -> anyhow::Result<()>;

/// Writes the textures (and environment-map faces) of every layer at `point` into `dir` as
/// linear EXR and sRGB PNG; returns the file names. Every texture is decoded before a file
/// is written, and the files written before an error are removed (the folder too, when this
/// call made it): an error leaves nothing behind.
pub fn extract(r: &PisReader, point: &[u32], dir: &Path) -> Result<Vec<String>, pis_pack::Failure> {
    use pis_pack::{Exit, Failure};
    // Decode first: a damaged codestream fails before any file exists.
    let mut images = Vec::new();
    for (oi, o) in r.container().objects.iter().enumerate() {
        for (li, l) in o.layers.iter().enumerate() {
            let t = r.texture(oi, li, point)?;
            let lay = &t.layout;
            for face in 0..lay.faces {
                let suffix = if l.mapping == Mapping::Shell && lay.faces == 6 {
                    format!(".{}", FACE_NAMES[face as usize])
                } else {
                    String::new()
                };
                let stem = format!("{}.{li}-{}{suffix}", sanitize(&o.name), l.kind.name());
                images.push((stem, lay.width, lay.height, lay.channels, t.plane(face, 0).to_vec()));
            }
        }
    }
    let made = !dir.exists();
    std::fs::create_dir_all(dir)
        .with_context(|| format!("cannot create {}", dir.display()))
        .map_err(|e| Failure::new(Exit::Io, e))?;
    let mut written = Vec::new();
    let writers: [(&str, PlaneWriter); 2] = [("exr", write_exr), ("png", write_png)];
    for (stem, width, height, channels, plane) in &images {
        for (ext, f) in writers {
            let name = format!("{stem}.{ext}");
            if let Err(e) = f(&dir.join(&name), *width, *height, *channels, plane) {
                for w in &written {
                    let _ = std::fs::remove_file(dir.join(w));
                }
                let _ = std::fs::remove_file(dir.join(&name));
                if made {
                    let _ = std::fs::remove_dir(dir);
                }
                return Err(Failure::new(Exit::Io, e));
            }
            written.push(name);
        }
    }
    Ok(written)
}

/// A file-name-safe version of an object name.
fn sanitize(name: &str) -> String {
    name.chars()
        .map(|c| if c.is_ascii_alphanumeric() || c == '-' || c == '_' { c } else { '_' })
        .collect()
}
