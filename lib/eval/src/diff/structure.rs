//! Structural differences between two containers: parameter space, cameras, objects, layers,
//! shells, blocks, pyramid levels, codecs and provenance, each as one readable line; and the
//! bytes each kind of chunk takes in both files.

use std::collections::BTreeMap;

use pis_format::*;
use serde::Serialize;

/// Bytes per kind of chunk content; `header` is the header, chunk table and padding.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct ChunkBytes {
    pub total: u64,
    pub header: u64,
    pub parameter_space: u64,
    pub cameras: u64,
    pub objects: u64,
    pub geometry: u64,
    pub layer_index: u64,
    pub codestreams: u64,
    pub provenance: u64,
    /// The lossless master (`MSTR`): stored for re-encoding, never read by a player.
    pub master: u64,
    pub other: u64,
}

impl ChunkBytes {
    pub fn of(r: &PisReader) -> Self {
        let mut b = ChunkBytes { total: r.len(), ..Default::default() };
        for e in r.chunks() {
            let slot = match &e.fourcc {
                b"PSPC" => &mut b.parameter_space,
                b"CAMS" => &mut b.cameras,
                b"OBJS" => &mut b.objects,
                b"MESH" => &mut b.geometry,
                b"LAYR" => &mut b.layer_index,
                b"CSTR" => &mut b.codestreams,
                b"PROV" => &mut b.provenance,
                b"MSTR" => &mut b.master,
                _ => &mut b.other,
            };
            *slot += e.length;
        }
        b.header = b.total - r.chunks().iter().map(|e| e.length).sum::<u64>();
        b
    }

    /// (kind, bytes) in report order.
    pub fn rows(&self) -> [(&'static str, u64); 11] {
        [
            ("header + table + padding", self.header),
            ("parameter space", self.parameter_space),
            ("cameras", self.cameras),
            ("objects", self.objects),
            ("geometry", self.geometry),
            ("layer index", self.layer_index),
            ("codestreams", self.codestreams),
            ("provenance", self.provenance),
            ("lossless master", self.master),
            ("other chunks", self.other),
            ("total", self.total),
        ]
    }
}

/// Collects difference lines.
struct Lines(Vec<String>);

impl Lines {
    fn check<T: PartialEq + std::fmt::Debug>(
        &mut self,
        what: impl FnOnce() -> String,
        a: &T,
        b: &T,
    ) {
        if a != b {
            self.0.push(format!("{}: {a:?} → {b:?}", what()));
        }
    }
}

fn dim_names(space: &ParameterSpace, mask: DepMask) -> Vec<String> {
    mask.dims().filter_map(|k| space.dims.get(k)).map(|d| d.name.clone()).collect()
}

/// The codecs a layer's level images use, by name, with their counts.
pub fn layer_codecs(l: &Layer<StreamRef>) -> BTreeMap<&'static str, usize> {
    let mut m = BTreeMap::new();
    for s in l.blocks.iter().flat_map(|b| &b.levels).flat_map(|lv| &lv.images) {
        *m.entry(s.codec.name()).or_insert(0) += 1;
    }
    m
}

/// Every structural difference from `a` to `b`, one line each; empty when the structure is
/// the same. Objects are matched by name, layers by their position in the object.
pub fn differences(a: &Container<StreamRef>, b: &Container<StreamRef>) -> Vec<String> {
    let mut d = Lines(Vec::new());
    // Parameter space.
    d.check(|| "dimension count".into(), &a.space.dims.len(), &b.space.dims.len());
    for (k, (x, y)) in a.space.dims.iter().zip(&b.space.dims).enumerate() {
        let n = || format!("dimension {k} '{}'", x.name);
        d.check(|| format!("{} name", n()), &x.name, &y.name);
        d.check(|| format!("{} kind", n()), &x.kind.name(), &y.kind.name());
        d.check(|| format!("{} samples", n()), &x.values.len(), &y.values.len());
        if x.values.len() == y.values.len() {
            d.check(|| format!("{} sample values", n()), &x.values, &y.values);
        }
        d.check(|| format!("{} block size", n()), &x.block_size, &y.block_size);
        d.check(|| format!("{} periodic", n()), &x.periodic, &y.periodic);
        d.check(|| format!("{} unit", n()), &x.unit, &y.unit);
    }
    // Cameras.
    d.check(
        || "image size".into(),
        &(a.cameras.width, a.cameras.height),
        &(b.cameras.width, b.cameras.height),
    );
    d.check(
        || "cameras vary with".into(),
        &dim_names(&a.space, a.cameras.depends_on),
        &dim_names(&b.space, b.cameras.depends_on),
    );
    d.check(|| "camera count".into(), &a.cameras.cameras.len(), &b.cameras.cameras.len());
    if a.cameras.cameras.len() == b.cameras.cameras.len() && a.cameras.cameras != b.cameras.cameras
    {
        let n = a.cameras.cameras.iter().zip(&b.cameras.cameras).filter(|(x, y)| x != y).count();
        d.0.push(format!("cameras: {n} of {} differ", a.cameras.cameras.len()));
    }
    // Objects.
    let names =
        |c: &Container<StreamRef>| c.objects.iter().map(|o| o.name.clone()).collect::<Vec<_>>();
    for o in &a.objects {
        if !b.objects.iter().any(|p| p.name == o.name) {
            d.0.push(format!("object '{}' only in the first file", o.name));
        }
    }
    for o in &b.objects {
        if !a.objects.iter().any(|p| p.name == o.name) {
            d.0.push(format!("object '{}' only in the second file", o.name));
        }
    }
    let (na, nb) = (names(a), names(b));
    let common_a: Vec<&String> = na.iter().filter(|n| nb.contains(n)).collect();
    let common_b: Vec<&String> = nb.iter().filter(|n| na.contains(n)).collect();
    d.check(|| "object order".into(), &common_a, &common_b);
    for x in &a.objects {
        let Some(y) = b.objects.iter().find(|p| p.name == x.name) else { continue };
        let n = || format!("object '{}'", x.name);
        d.check(|| format!("{} role", n()), &x.role.name(), &y.role.name());
        d.check(|| format!("{} shading", n()), &x.shading, &y.shading);
        d.check(|| format!("{} block origins", n()), &x.stagger, &y.stagger);
        if x.transforms != y.transforms {
            d.0.push(format!("{}: transforms differ", n()));
        }
        if x.mesh != y.mesh {
            d.0.push(format!(
                "{}: mesh differs ({} → {} vertices, {} → {} triangles)",
                n(),
                x.mesh.positions.len(),
                y.mesh.positions.len(),
                x.mesh.indices.len() / 3,
                y.mesh.indices.len() / 3
            ));
        }
        d.check(|| format!("{} layer count", n()), &x.layers.len(), &y.layers.len());
        for (li, (p, q)) in x.layers.iter().zip(&y.layers).enumerate() {
            layer_differences(
                &mut d,
                &format!("{} layer {li} ({})", n(), p.kind.name()),
                (&a.space, p),
                (&b.space, q),
            );
        }
    }
    // Provenance.
    match (&a.provenance, &b.provenance) {
        (Some(p), Some(q)) => {
            d.check(|| "provenance tool".into(), &p.tool, &q.tool);
            d.check(|| "provenance source".into(), &p.source, &q.source);
            d.check(|| "raw image bytes".into(), &p.raw_image_bytes, &q.raw_image_bytes);
            let (sp, sq): (BTreeMap<_, _>, BTreeMap<_, _>) =
                (p.settings.iter().cloned().collect(), q.settings.iter().cloned().collect());
            for (k, v) in &sp {
                match sq.get(k) {
                    Some(w) if w != v => d.0.push(format!("setting {k}: {v} → {w}")),
                    None => d.0.push(format!("setting {k}={v} only in the first file")),
                    _ => {}
                }
            }
            for (k, w) in &sq {
                if !sp.contains_key(k) {
                    d.0.push(format!("setting {k}={w} only in the second file"));
                }
            }
        }
        (None, Some(_)) => d.0.push("provenance only in the second file".into()),
        (Some(_), None) => d.0.push("provenance only in the first file".into()),
        (None, None) => {}
    }
    d.0
}

fn layer_differences(
    d: &mut Lines,
    n: &str,
    (sa, p): (&ParameterSpace, &Layer<StreamRef>),
    (sb, q): (&ParameterSpace, &Layer<StreamRef>),
) {
    d.check(|| format!("{n} kind"), &p.kind.name(), &q.kind.name());
    d.check(|| format!("{n} mapping"), &p.mapping.name(), &q.mapping.name());
    d.check(|| format!("{n} term"), &p.term.name(), &q.term.name());
    d.check(|| format!("{n} order"), &p.order, &q.order);
    d.check(|| format!("{n} combine"), &p.combine.name(), &q.combine.name());
    d.check(|| format!("{n} channels"), &p.channels, &q.channels);
    d.check(|| format!("{n} mip mode"), &p.mip_mode.name(), &q.mip_mode.name());
    d.check(|| format!("{n} gamma"), &p.gamma, &q.gamma);
    d.check(
        || format!("{n} varies with"),
        &dim_names(sa, p.depends_on),
        &dim_names(sb, q.depends_on),
    );
    d.check(|| format!("{n} codecs"), &layer_codecs(p), &layer_codecs(q));
    d.check(|| format!("{n} block count"), &p.blocks.len(), &q.blocks.len());
    let (mut size, mut place, mut shells, mut pyramids) = (0, 0, 0, 0);
    for (x, y) in p.blocks.iter().zip(&q.blocks) {
        size += usize::from((x.width, x.height) != (y.width, y.height));
        let shape = |b: &Block<StreamRef>| match b.placement {
            Placement::Shell { shape, .. } => Some(shape),
            Placement::Surface { .. } => None,
        };
        shells += usize::from(shape(x) != shape(y));
        place += usize::from(x.placement != y.placement && shape(x) == shape(y));
        let counts =
            |b: &Block<StreamRef>| b.levels.iter().map(|l| l.counts.clone()).collect::<Vec<_>>();
        pyramids += usize::from(counts(x) != counts(y));
    }
    let m = p.blocks.len().min(q.blocks.len());
    if size > 0 {
        let dims = |b: Option<&Block<StreamRef>>| b.map(|b| (b.width, b.height));
        d.0.push(format!(
            "{n}: texture size differs in {size} of {m} blocks ({:?} → {:?} in the first block)",
            dims(p.blocks.first()),
            dims(q.blocks.first())
        ));
    }
    if shells > 0 {
        let shape = |b: Option<&Block<StreamRef>>| match b.map(|b| b.placement) {
            Some(Placement::Shell { shape, .. }) => shape.name(),
            _ => "surface",
        };
        d.0.push(format!(
            "{n}: shell shape differs in {shells} of {m} blocks ({} → {})",
            shape(p.blocks.first()),
            shape(q.blocks.first())
        ));
    }
    if place > 0 {
        d.0.push(format!("{n}: placement differs in {place} of {m} blocks"));
    }
    if pyramids > 0 {
        d.0.push(format!("{n}: pyramid levels differ in {pyramids} of {m} blocks"));
    }
}
