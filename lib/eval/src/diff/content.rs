//! Content differences between two containers: both decoded at every parameter sample, per
//! object, layer and parameter block, errors measured on display values ([`crate::metrics`]).
//!
//! A layer's texture at a sample is read by every parameter point that agrees with the
//! sample along the layer's dimensions; the object and whole-file figures weight each
//! sample's error by that number of points, so they equal the error of decoding every layer
//! at every point while each texture is decoded once.

use std::path::PathBuf;

use pis_format::blocks::BlockGrid;
use pis_format::{Container, Error, LevelLayout, PisReader, StreamRef};
use rayon::prelude::*;
use serde::Serialize;

use super::decode::{decode_block, point_of, BlockTextures};
use crate::metrics::{display, SquaredError};

/// An error in one of the two files, with the file it came from.
#[derive(Debug)]
pub struct FileError {
    pub path: PathBuf,
    pub error: Error,
}

impl std::fmt::Display for FileError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: {}", self.path.display(), self.error)
    }
}

impl std::error::Error for FileError {}

/// Error figures of a set of decoded values against their reference.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Score {
    /// PSNR in dB on display values (peak 1); null when the values are identical.
    pub psnr_db: Option<f64>,
    /// Mean squared display error.
    pub mse: f64,
    /// Largest absolute display error.
    pub max_error: f64,
    /// Every decoded value equal.
    pub exact: bool,
}

impl Score {
    fn of(e: &SquaredError, exact: bool) -> Self {
        let p = e.psnr();
        Score { psnr_db: p.is_finite().then_some(p), mse: e.mse(), max_error: e.max, exact }
    }
}

#[derive(Clone, Debug, Serialize)]
pub struct BlockDiff {
    pub block: usize,
    /// Layer samples the block holds.
    pub samples: usize,
    #[serde(flatten)]
    pub score: Score,
}

#[derive(Clone, Debug, Serialize)]
pub struct LayerDiff {
    pub layer: usize,
    pub kind: &'static str,
    /// False when the two layers cannot be compared texel by texel (see `note`).
    pub compared: bool,
    pub note: Option<String>,
    #[serde(flatten)]
    pub score: Score,
    pub blocks: Vec<BlockDiff>,
}

#[derive(Clone, Debug, Serialize)]
pub struct ObjectDiff {
    pub name: String,
    #[serde(flatten)]
    pub score: Score,
    pub layers: Vec<LayerDiff>,
}

/// The content comparison of two files.
#[derive(Clone, Debug, Serialize)]
pub struct ContentDiff {
    #[serde(flatten)]
    pub score: Score,
    /// Every layer of every object of the first file was compared.
    pub complete: bool,
    pub objects: Vec<ObjectDiff>,
}

/// Root-mean-square display error per texel of one layer's finest planes (faces side by
/// side), over its samples and channels: over the blocks that share one texture placement
/// (all of them where the writer placed the texture once per layer).
#[derive(Clone, Debug)]
pub struct ErrorMap {
    pub object: String,
    pub layer: usize,
    pub kind: &'static str,
    /// The blocks the map covers; `placements` maps are made for the layer in all.
    pub blocks: Vec<usize>,
    pub placements: usize,
    pub width: u32,
    pub height: u32,
    pub values: Vec<f32>,
}

/// The squared errors per texel summed over the blocks of one texture placement (an
/// [`ErrorMap`] in the making), and how many values they sum.
struct MapSum {
    layout: LevelLayout,
    sums: Vec<f64>,
    values: u64,
    blocks: Vec<usize>,
}

/// Per-sample result: the sample's error, exactness, and its squared error per texel.
struct SampleError {
    error: SquaredError,
    exact: bool,
    texels: Option<Vec<f64>>,
}

fn sample_error(layout: &LevelLayout, a: &[f32], b: &[f32], map: bool) -> SampleError {
    let mut error = SquaredError::default();
    error.add_slices(b, a);
    let exact = a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x == y);
    let texels = map.then(|| {
        let (w, h, c) = (layout.width as usize, layout.height as usize, layout.channels as usize);
        let mut out = vec![0.0f64; w * h * layout.faces as usize];
        let planes = layout.planes();
        let mut start = 0usize;
        for (pi, p) in planes.iter().enumerate() {
            let n = (p.width * p.height * p.channels) as usize;
            if (pi as u32).is_multiple_of(layout.mips) {
                let face = pi / layout.mips as usize;
                for y in 0..h {
                    for x in 0..w {
                        let mut s = 0.0;
                        for k in 0..c {
                            let i = start + (y * w + x) * c + k;
                            let e = display(b[i]) - display(a[i]);
                            s += e * e;
                        }
                        out[y * w * layout.faces as usize + face * w + x] = s;
                    }
                }
            }
            start += n;
        }
        out
    });
    SampleError { error, exact, texels }
}

fn weighted(total: &mut SquaredError, e: &SquaredError, points: u64) {
    total.sum += e.sum * points as f64;
    total.count += e.count * points;
    total.max = total.max.max(e.max);
}

/// Why layer `q` of the second file cannot be compared texel by texel with layer `p`.
fn incomparable(
    a: &Container<StreamRef>,
    b: &Container<StreamRef>,
    p: &pis_format::Layer<StreamRef>,
    q: &pis_format::Layer<StreamRef>,
) -> Option<String> {
    if (p.kind, p.mapping, p.channels, p.mip_mode) != (q.kind, q.mapping, q.channels, q.mip_mode) {
        return Some("kind, mapping, channels or mip mode differ".into());
    }
    let dims = |c: &Container<StreamRef>, l: &pis_format::Layer<StreamRef>| {
        l.depends_on
            .dims()
            .map(|k| (c.space.dims[k].name.clone(), c.space.dims[k].values.len()))
            .collect::<Vec<_>>()
    };
    if dims(a, p) != dims(b, q) || a.space.dims.len() != b.space.dims.len() {
        return Some("the layers vary over different dimensions or samples".into());
    }
    None
}

/// A layer that was not compared, with why.
fn not_compared(li: usize, la: &pis_format::Layer<StreamRef>, note: String) -> LayerDiff {
    LayerDiff {
        layer: li,
        kind: la.kind.name(),
        compared: false,
        note: Some(note),
        score: Score::of(&SquaredError::default(), false),
        blocks: vec![],
    }
}

/// Whether layer `la` of object `oa` and layer `lb` of object `ob` group their samples into
/// the same blocks (so a block of one can be decoded against the same block of the other).
fn same_grid(
    ca: &Container<StreamRef>,
    cb: &Container<StreamRef>,
    oa: &pis_format::Object<StreamRef>,
    ob: &pis_format::Object<StreamRef>,
    la: &pis_format::Layer<StreamRef>,
    lb: &pis_format::Layer<StreamRef>,
) -> bool {
    let grid_a = BlockGrid::new(&ca.space, la.depends_on, &oa.stagger);
    let grid_b = BlockGrid::new(&cb.space, lb.depends_on, &ob.stagger);
    grid_a.blocks_per_axis() == grid_b.blocks_per_axis()
        && (0..la.blocks.len()).all(|k| grid_a.extent(k) == grid_b.extent(k))
        && la.depends_on.dims().all(|d| oa.stagger[d] == ob.stagger[d])
        && la.depends_on.dims().all(|d| ca.space.dims[d].block_size == cb.space.dims[d].block_size)
}

/// Layer `li` of object `oj` of `b` at the samples of `ta`, a block of the first file, one
/// texture at a time (the second file blocks them differently).
fn samples_of(
    b: &PisReader,
    oj: usize,
    li: usize,
    ta: &BlockTextures,
) -> Result<BlockTextures, Error> {
    let cb = b.container();
    let depends_on = cb.objects[oj].layers[li].depends_on;
    let mut textures = Vec::with_capacity(ta.keys.len());
    let mut layout = ta.layout.clone();
    for k in &ta.keys {
        let t = b.texture(oj, li, &point_of(cb.space.dims.len(), depends_on, k))?;
        if t.layout != ta.layout {
            layout = t.layout.clone();
        }
        textures.push(t.data);
    }
    Ok(BlockTextures { layout, extent: ta.extent.clone(), keys: ta.keys.clone(), textures })
}

/// Block `bi`'s error from its samples' errors; their per-texel errors, when measured, are
/// added to the layer's map of the block's texture placement (a new map for a new one).
fn block_error(
    per: &[SampleError],
    la: &pis_format::Layer<StreamRef>,
    bi: usize,
    layout: &LevelLayout,
    layer_maps: &mut Vec<MapSum>,
) -> (SquaredError, bool) {
    let mut block_err = SquaredError::default();
    let mut block_exact = true;
    let mut block_map = None;
    for s in per {
        block_err.merge(&s.error);
        block_exact &= s.exact;
        if let Some(t) = &s.texels {
            let k = *block_map.get_or_insert_with(|| {
                let same = layer_maps.iter().position(|m| {
                    m.layout == *layout && la.blocks[m.blocks[0]].same_placement(&la.blocks[bi])
                });
                same.unwrap_or_else(|| {
                    layer_maps.push(MapSum {
                        layout: layout.clone(),
                        sums: vec![0.0; t.len()],
                        values: 0,
                        blocks: vec![],
                    });
                    layer_maps.len() - 1
                })
            });
            let m = &mut layer_maps[k];
            m.sums.iter_mut().zip(t).for_each(|(acc, v)| *acc += v);
            m.values += layout.channels as u64;
        }
    }
    if let Some(k) = block_map {
        layer_maps[k].blocks.push(bi);
    }
    (block_err, block_exact)
}

/// Compares every layer of every object of `a` with the layer at the same position of the
/// object of the same name in `b`. With `maps`, also returns an [`ErrorMap`] per compared
/// layer. `progress` gets one line per layer.
pub fn compare(
    a: &PisReader,
    b: &PisReader,
    maps: bool,
    progress: &mut dyn FnMut(&str),
) -> Result<(ContentDiff, Vec<ErrorMap>), FileError> {
    let (ca, cb) = (a.container(), b.container());
    let fa = |error| FileError { path: a.path().to_path_buf(), error };
    let fb = |error| FileError { path: b.path().to_path_buf(), error };
    let points = ca.space.point_count();
    let mut total = SquaredError::default();
    let mut total_exact = true;
    let mut complete = true;
    let mut objects = Vec::new();
    let mut out_maps = Vec::new();
    for (oi, oa) in ca.objects.iter().enumerate() {
        let ob = cb.objects.iter().position(|o| o.name == oa.name);
        let mut obj_err = SquaredError::default();
        let mut obj_exact = true;
        let mut layers = Vec::new();
        for (li, la) in oa.layers.iter().enumerate() {
            let lb = ob.and_then(|j| cb.objects[j].layers.get(li).map(|l| (j, l)));
            let note = match lb {
                None => Some("no such layer in the second file".to_string()),
                Some((_, lb)) => incomparable(ca, cb, la, lb),
            };
            if let Some(note) = note {
                complete = false;
                obj_exact = false;
                total_exact = false;
                layers.push(not_compared(li, la, note));
                continue;
            }
            let (oj, lb) = lb.expect("checked above");
            progress(&format!(
                "object '{}' layer {li} ({}): {} blocks",
                oa.name,
                la.kind.name(),
                la.blocks.len()
            ));
            let multiplicity = points / ca.space.table_len(la.depends_on).max(1);
            let same_grid = same_grid(ca, cb, oa, &cb.objects[oj], la, lb);
            let mut layer_err = SquaredError::default();
            let mut layer_exact = true;
            let mut layout_note = None;
            // One map per texture placement (size and texture transform) of the layer's blocks.
            let mut layer_maps: Vec<MapSum> = Vec::new();
            let mut blocks = Vec::new();
            for bi in 0..la.blocks.len() {
                let ta = decode_block(a, oi, li, bi).map_err(fa)?;
                let tb = if same_grid {
                    decode_block(b, oj, li, bi).map_err(fb)?
                } else {
                    samples_of(b, oj, li, &ta).map_err(fb)?
                };
                if tb.layout != ta.layout {
                    layout_note = Some(format!(
                        "texture layout differs in block {bi}: {}x{} → {}x{}",
                        ta.layout.width, ta.layout.height, tb.layout.width, tb.layout.height
                    ));
                    break;
                }
                let per: Vec<SampleError> = ta
                    .textures
                    .par_iter()
                    .zip(&tb.textures)
                    .map(|(x, y)| sample_error(&ta.layout, x, y, maps))
                    .collect();
                let (block_err, block_exact) =
                    block_error(&per, la, bi, &ta.layout, &mut layer_maps);
                weighted(&mut layer_err, &block_err, 1);
                layer_exact &= block_exact;
                blocks.push(BlockDiff {
                    block: bi,
                    samples: per.len(),
                    score: Score::of(&block_err, block_exact),
                });
            }
            if let Some(note) = layout_note {
                complete = false;
                obj_exact = false;
                total_exact = false;
                layers.push(not_compared(li, la, note));
                continue;
            }
            weighted(&mut obj_err, &layer_err, multiplicity);
            obj_exact &= layer_exact;
            let placements = layer_maps.len();
            for MapSum { layout, sums, values: n, blocks } in layer_maps {
                let values = sums.iter().map(|s| (s / n.max(1) as f64).sqrt() as f32).collect();
                out_maps.push(ErrorMap {
                    object: oa.name.clone(),
                    layer: li,
                    kind: la.kind.name(),
                    blocks,
                    placements,
                    width: layout.width * layout.faces,
                    height: layout.height,
                    values,
                });
            }
            layers.push(LayerDiff {
                layer: li,
                kind: la.kind.name(),
                compared: true,
                note: None,
                score: Score::of(&layer_err, layer_exact),
                blocks,
            });
        }
        if ob.is_some_and(|j| cb.objects[j].layers.len() > oa.layers.len()) {
            complete = false;
            obj_exact = false;
        }
        total.merge(&obj_err);
        total_exact &= obj_exact;
        objects.push(ObjectDiff {
            name: oa.name.clone(),
            score: Score::of(&obj_err, obj_exact),
            layers,
        });
    }
    if cb.objects.iter().any(|o| !ca.objects.iter().any(|p| p.name == o.name)) {
        complete = false;
        total_exact = false;
    }
    Ok((ContentDiff { score: Score::of(&total, total_exact), complete, objects }, out_maps))
}
