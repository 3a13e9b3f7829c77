//! A solved object, whatever represented it: its mesh and texture coordinates, the
//! placements of its layers' blocks, the render matrices of every point (what the
//! prediction and the screen-error allocation read), and every layer's solved samples.
//! Encoding reads this.

use std::borrow::Cow;
use std::collections::BTreeMap;
use std::sync::Arc;

use anyhow::{anyhow, Result};

use pis_compile::{RenderMatrix, TextureLayout};
use pis_format::{DepMask, ParameterSpace};

use super::mesh::{Mesh, Placed};
use super::scratch::{Reader, Scratch, Span, Writer};
use super::textures::Textures;

/// One point as the render matrices see an object (hardware model or probe mode): the rows
/// of A per placement its layers read there (the rows, the covered pixels, are the same for
/// every placement) and the gold standard of each layer at those pixels.
#[derive(Clone)]
pub struct PointView {
    /// Per placement its layers read here: the render matrix.
    pub(super) a: Vec<(usize, RenderMatrix)>,
    pub diffuse: Vec<f32>,
    pub specular: Vec<f32>,
    /// A translucent object's opacity per row, in each of 3 channels (empty for an opaque
    /// object; its radiance is then premultiplied by it).
    pub alpha: Vec<f32>,
    /// Per row, the set's confidence in its pixel, which multiplies both sides of the row in
    /// the solves (thesis 6.3.3; [`super::confidence`]); empty: 1 for every row.
    pub weight: Vec<f32>,
}

impl PointView {
    /// The render matrix of placement `placement` (of [`ObjectModel::placements`]).
    pub fn a(&self, placement: usize) -> &RenderMatrix {
        &self
            .a
            .iter()
            .find(|(p, _)| *p == placement)
            .expect("a render matrix for every placement a layer reads at the point")
            .1
    }

    /// Covered pixels.
    pub fn rows(&self) -> usize {
        self.a.first().map_or(0, |(_, a)| a.rows())
    }

    /// The covered pixels, `y · width + x`, in row order.
    pub fn pixels(&self) -> &[u32] {
        self.a.first().map_or(&[], |(_, a)| a.pixels.as_slice())
    }

    /// The view as a scratch record.
    fn record(&self) -> Vec<u8> {
        let mut w = Writer::default();
        w.u64(self.a.len() as u64);
        for (p, a) in &self.a {
            w.u64(*p as u64);
            w.matrix(a);
        }
        w.f32s(&self.diffuse);
        w.f32s(&self.specular);
        w.f32s(&self.alpha);
        w.f32s(&self.weight);
        w.0
    }

    /// A view from its scratch record.
    fn read(bytes: &[u8]) -> Result<PointView> {
        let mut r = Reader::new(bytes);
        let n = r.u64()?;
        let mut a = Vec::new();
        for _ in 0..n.min(bytes.len() as u64) {
            let p = r.u64()? as usize;
            a.push((p, r.matrix()?));
        }
        let (diffuse, specular, alpha, weight) = (r.f32s()?, r.f32s()?, r.f32s()?, r.f32s()?);
        r.done()?;
        Ok(PointView { a, diffuse, specular, alpha, weight })
    }
}

/// Every point's [`PointView`] of an object: held in memory, or, for a pack that streams
/// ([`super::memory`]), in the scratch file, read back one point at a time (the number of
/// covered pixels of each point stays in memory).
pub struct Views {
    store: ViewStore,
}

enum ViewStore {
    Held(Vec<PointView>),
    Spilled { scratch: Arc<Scratch>, spans: Vec<Span>, rows: Vec<usize> },
}

impl Views {
    /// No points yet; points pushed go to `scratch` where given.
    pub fn new(scratch: Option<Arc<Scratch>>) -> Views {
        Views {
            store: match scratch {
                Some(scratch) => {
                    ViewStore::Spilled { scratch, spans: Vec::new(), rows: Vec::new() }
                }
                None => ViewStore::Held(Vec::new()),
            },
        }
    }

    /// Adds the next point.
    pub fn push(&mut self, v: PointView) -> Result<()> {
        match &mut self.store {
            ViewStore::Held(h) => h.push(v),
            ViewStore::Spilled { scratch, spans, rows } => {
                spans.push(scratch.put(&v.record())?);
                rows.push(v.rows());
            }
        }
        Ok(())
    }

    /// Changes point `p` by `change`.
    pub fn update(
        &mut self,
        p: usize,
        change: impl FnOnce(&mut PointView) -> Result<()>,
    ) -> Result<()> {
        match &mut self.store {
            ViewStore::Held(h) => {
                change(h.get_mut(p).ok_or_else(|| anyhow!("no view of point {p}"))?)
            }
            ViewStore::Spilled { scratch, spans, rows } => {
                let span = *spans.get(p).ok_or_else(|| anyhow!("no view of point {p}"))?;
                let mut v = PointView::read(&scratch.get(span)?)?;
                change(&mut v)?;
                spans[p] = scratch.put(&v.record())?;
                rows[p] = v.rows();
                Ok(())
            }
        }
    }

    /// The number of points.
    pub fn len(&self) -> usize {
        match &self.store {
            ViewStore::Held(h) => h.len(),
            ViewStore::Spilled { spans, .. } => spans.len(),
        }
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Point `p`'s view (read back from the scratch file where spilled).
    pub fn get(&self, p: usize) -> Result<Cow<'_, PointView>> {
        match &self.store {
            ViewStore::Held(h) => {
                h.get(p).map(Cow::Borrowed).ok_or_else(|| anyhow!("no view of point {p}"))
            }
            ViewStore::Spilled { scratch, spans, .. } => {
                let span = *spans.get(p).ok_or_else(|| anyhow!("no view of point {p}"))?;
                Ok(Cow::Owned(PointView::read(&scratch.get(span)?)?))
            }
        }
    }

    /// The covered pixels of point `p`, `y · width + x`, in row order.
    pub fn pixels(&self, p: usize) -> Result<Cow<'_, [u32]>> {
        Ok(match self.get(p)? {
            Cow::Borrowed(v) => Cow::Borrowed(v.pixels()),
            Cow::Owned(v) => Cow::Owned(v.pixels().to_vec()),
        })
    }

    /// The number of covered pixels of point `p`.
    pub fn rows(&self, p: usize) -> usize {
        match &self.store {
            ViewStore::Held(h) => h.get(p).map_or(0, PointView::rows),
            ViewStore::Spilled { rows, .. } => rows.get(p).copied().unwrap_or(0),
        }
    }
}

/// A solved layer: one texture (the whole MIP chain of its placement's layout) per sample of
/// the dimensions it depends on.
pub struct InferredLayer {
    pub kind: pis_format::LayerKind,
    pub depends_on: DepMask,
    /// Key: sample index per masked dimension, in dimension order.
    pub textures: Textures,
    /// Per block of the layer's grid (SPEC.md 7.2), its placement in
    /// [`ObjectModel::placements`].
    pub block_placements: Vec<usize>,
    /// Per texture key, its block's placement.
    pub placement_of: BTreeMap<Vec<u32>, usize>,
    pub iterations: u64,
    /// How the layer's samples are stored and rebuilt: its representation's part of
    /// encoding.
    pub form: Box<dyn LayerForm>,
    /// For a shell layer, its index among the object's shells ([`ShellTerms`]); `None`
    /// for a surface layer.
    pub shell: Option<usize>,
    /// For a relightable layer's coefficient ([`super::relit`]): which, and its weight at
    /// every point.
    pub light: Option<LightBasis>,
}

/// A relightable layer's coefficient c: its texture is drawn times Y_c(ω) at a point whose
/// light sample has direction ω.
#[derive(Clone, Debug)]
pub struct LightBasis {
    pub c: usize,
    /// Per point of the set, Y_c at its light sample's direction.
    pub weights: Arc<Vec<f32>>,
}

impl InferredLayer {
    /// Shell `shell` of an object as a layer over every dimension (`all`) of `space`: one
    /// texture per parameter sample (`textures`, keyed by sample), every block of its grid
    /// (origins `stagger`) on the one shell and cube layout that `form` describes.
    pub fn shell(
        kind: pis_format::LayerKind,
        (space, all): (&ParameterSpace, DepMask),
        stagger: &[u32],
        textures: BTreeMap<Vec<u32>, Vec<f32>>,
        iterations: u64,
        form: Box<dyn LayerForm>,
        shell: usize,
    ) -> InferredLayer {
        let grid_blocks =
            pis_format::blocks::BlockGrid::new(space, all, stagger).block_count() as usize;
        InferredLayer {
            kind,
            depends_on: all,
            placement_of: textures.keys().map(|k| (k.clone(), 0)).collect(),
            textures: textures.into(),
            block_placements: vec![0; grid_blocks],
            iterations,
            form,
            shell: Some(shell),
            light: None,
        }
    }
}

/// How a layer's samples are stored in the container and rebuilt for drawing: what encoding
/// asks of a representation ([`super::represent`]). The pyramids, the storage allocation
/// and the codecs only see the values [`LayerForm::stored`] gives, in the planes of the
/// container layer and blocks it describes.
pub trait LayerForm: Send + Sync {
    /// The container layer, without blocks, of a layer of `kind` drawn in `order` over the
    /// dimensions `depends_on`, stored with gamma `gamma`.
    fn layer(
        &self,
        kind: pis_format::LayerKind,
        order: u8,
        depends_on: DepMask,
        gamma: f32,
    ) -> pis_format::Layer;
    /// Block `b` of the layer's grid as the container holds it (size, placement), without
    /// levels.
    fn block(&self, b: usize) -> pis_format::Block;
    /// What the level images store of the solved sample `key` (`solved`: what the render
    /// matrices read).
    fn stored(&self, key: &[u32], solved: &[f32]) -> Vec<f32>;
    /// What the render matrices read, rebuilt from stored values as the player rebuilds it.
    fn drawn(&self, key: &[u32], stored: Vec<f32>) -> Vec<f32>;
    /// Texels of sample `key` as stored (values per channel).
    fn stored_texels(&self, key: &[u32]) -> usize;
    /// Values per texel of the solved and stored samples.
    fn channels(&self) -> usize {
        3
    }
}

/// An object's environment-map shells drawn at every point of the set, as its representation
/// draws them (layered environment maps, [`super::pem`]; hybrid rendering, [`super::hybrid`]):
/// what the prediction and the screen-error allocation ask of a representation's shells.
pub trait ShellTerms: Send + Sync {
    /// The shells' terms at point `p` over its covered pixels `rows` (increasing), RGB per
    /// row, drawn from the shells' cube maps `maps` (each with its channel count).
    fn render(&self, p: usize, rows: &[u32], maps: &[(&[f32], usize)]) -> Vec<f32>;
    /// The screen weights of shell `s`'s sample (`texels` texels, every level stored) at
    /// `points`, scaled as a surface texture's are ([`super::encode`]).
    fn weights(&self, s: usize, texels: usize, points: &[usize]) -> Vec<f32>;
    /// Whether the object transmits light through its shells (a lens object, whose tint the
    /// file records).
    fn transmits(&self) -> bool {
        false
    }
    /// The paths a lens object's shells are drawn along, which the file records (SPEC.md
    /// 6.6 `lens_model`).
    fn lens_model(&self) -> pis_compile::hybrid::LensModel {
        pis_compile::hybrid::LensModel::Greedy
    }
}

/// An object's inferred representation.
pub struct ObjectModel {
    pub index: usize,
    pub name: String,
    pub mesh: Mesh,
    /// The texture coordinates the file's mesh carries (before any block's branch cut).
    pub mesh_uvs: Vec<[f32; 2]>,
    /// The distinct placements of the object's blocks.
    pub placements: Vec<Placed>,
    /// Block origin offsets (thesis 4.7), of the blocks of [`super::plan::Plan::sizes`].
    pub stagger: Vec<u32>,
    /// Mean covered pixels per point: the screen-area weight of allocation.
    pub area: f64,
    /// Per point of the set.
    pub views: Views,
    pub layers: Vec<InferredLayer>,
    /// The object's shells at every point of the set (`None` without shells).
    pub shells: Option<Box<dyn ShellTerms>>,
    /// The first `hull_triangles` triangles of `mesh` lie on its convex hull and draw the
    /// most distant shell only (thesis 5.7; SPEC.md 6.5).
    pub hull_triangles: u32,
    /// What was chosen and why.
    pub representation: String,
    pub why: String,
    /// The texture filter its surface textures are solved for and drawn with.
    pub filter: pis_compile::Filter,
    /// The texel budget its placements were made under (`None`: no budget).
    pub texels_per_pixel: Option<f64>,
    /// Under `--representation auto`, for an object that has an alternative: what the
    /// screen and the whole-file encodes found ([`super::screen`]).
    pub auto: Option<AutoChoice>,
}

/// What `auto` found for an object that has an alternative representation (pis-pack's
/// `--json`: each object's `auto`).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct AutoChoice {
    /// The alternative's name.
    pub alternative: String,
    /// The object's textures, solved (dB over the pixels it covers).
    pub textures_solved_db: f64,
    /// The other objects of the file together, solved (`None`: the only object).
    pub others_solved_db: Option<f64>,
    /// The alternative, solved; `None` where the screen did not solve it.
    pub alternative_solved_db: Option<f64>,
    /// Whether the whole file was encoded with the alternative.
    pub weighed: bool,
    /// Whether the alternative is what the file stores.
    pub kept: bool,
}

impl ObjectModel {
    /// Moves every layer's textures to `scratch` (a pack that streams).
    pub fn spill_textures(&mut self, scratch: &Arc<Scratch>) -> Result<()> {
        self.layers.iter_mut().try_for_each(|l| l.textures.spill(scratch))
    }

    /// The placement of sample `key` of layer `layer`.
    pub fn placed(&self, layer: usize, key: &[u32]) -> &Placed {
        &self.placements[self.layers[layer].placement_of[key]]
    }

    /// The placements the layers' blocks carry, in increasing order.
    pub fn used_placements(&self) -> Vec<usize> {
        let mut used: Vec<usize> =
            self.layers.iter().flat_map(|l| l.block_placements.iter().copied()).collect();
        used.sort_unstable();
        used.dedup();
        used
    }

    /// The MIP layout of sample `key` of layer `layer`.
    pub fn layout(&self, layer: usize, key: &[u32]) -> TextureLayout {
        self.placed(layer, key).layout
    }

    /// The object's image at point `p` over its covered pixels (rows × RGB), drawn as the
    /// player draws it from `textures[l]`, layer l's sample at the point (the whole drawn
    /// texture; `None` where the layer has none): the surface layers added, then the
    /// reflection term of the shells, or a lens object's two terms (SPEC.md 9).
    pub fn render(
        &self,
        p: usize,
        keys: &[Vec<u32>],
        textures: &[Option<&[f32]>],
    ) -> Result<Vec<f32>> {
        let v = self.views.get(p)?;
        Ok(self.render_view(&v, p, keys, textures))
    }

    /// [`ObjectModel::render`] with point `p`'s view `v` read already.
    pub fn render_view(
        &self,
        v: &PointView,
        p: usize,
        keys: &[Vec<u32>],
        textures: &[Option<&[f32]>],
    ) -> Vec<f32> {
        let mut img = vec![0.0f32; v.rows() * 3];
        let mut maps = Vec::new();
        for ((il, k), x) in self.layers.iter().zip(keys).zip(textures) {
            let Some(x) = x else { continue };
            match il.shell {
                None => {
                    // A translucent object's first layer carries its opacity: the image is
                    // its premultiplied colour.
                    let rgb: Cow<[f32]> = match il.form.channels() {
                        4 => x.chunks_exact(4).flat_map(|t| [t[0], t[1], t[2]]).collect(),
                        _ => Cow::Borrowed(x),
                    };
                    let r = pis_compile::render(v.a(il.placement_of[k]), &rgb);
                    let w = il.light.as_ref().map_or(1.0, |b| b.weights[p]);
                    img.iter_mut().zip(&r).for_each(|(a, b)| *a += w * b);
                }
                Some(_) => maps.push((*x, il.form.channels())),
            }
        }
        if let (false, Some(shells)) = (maps.is_empty(), &self.shells) {
            let r = shells.render(p, v.pixels(), &maps);
            img.iter_mut().zip(&r).for_each(|(a, b)| *a += b);
        }
        img
    }
}

/// The key of `samples` under `mask`.
pub fn key(samples: &[u32], mask: DepMask) -> Vec<u32> {
    mask.dims().map(|k| samples[k]).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use pis_compile::{RenderMatrix, TextureLayout};

    fn view(p: u32) -> PointView {
        let a = RenderMatrix {
            width: 8,
            height: 8,
            layout: TextureLayout::full(2, 2),
            pixels: vec![p, p + 3],
            coverage: vec![1.0, 0.5],
            row_start: vec![0, 1, 3],
            cols: vec![0, 1, 4],
            vals: vec![1.0, 0.25, 0.75],
        };
        PointView {
            a: vec![(0, a)],
            diffuse: vec![0.1 * p as f32; 6],
            specular: vec![-0.0; 6],
            alpha: vec![0.5; 6],
            weight: vec![1.0, 0.25],
        }
    }

    fn same(a: &PointView, b: &PointView) -> bool {
        let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        a.a.len() == b.a.len()
            && a.a.iter().zip(&b.a).all(|((pa, ma), (pb, mb))| pa == pb && ma == mb)
            && bits(&a.diffuse) == bits(&b.diffuse)
            && bits(&a.specular) == bits(&b.specular)
            && bits(&a.weight) == bits(&b.weight)
            && bits(&a.alpha) == bits(&b.alpha)
    }

    #[test]
    fn spilled_views_read_and_change_as_held_ones() {
        let dir = tempfile::tempdir().unwrap();
        let scratch = Arc::new(Scratch::create(&dir.path().join("s")).unwrap());
        let mut held = Views::new(None);
        let mut spilled = Views::new(Some(scratch.clone()));
        for p in 0..3 {
            held.push(view(p)).unwrap();
            spilled.push(view(p)).unwrap();
        }
        assert!(!scratch.is_empty(), "the views went to the scratch file");
        // A second placement's matrix added at point 1, the first one dropped.
        let change = |v: &mut PointView| {
            let mut b = v.a[0].1.clone();
            b.vals.iter_mut().for_each(|x| *x *= 0.5);
            v.a.push((2, b));
            v.a.remove(0);
            Ok(())
        };
        held.update(1, change).unwrap();
        spilled.update(1, change).unwrap();
        assert_eq!((held.len(), spilled.len()), (3, 3));
        for p in 0..3 {
            assert!(same(&held.get(p).unwrap(), &spilled.get(p).unwrap()), "point {p}");
            assert_eq!(held.pixels(p).unwrap(), spilled.pixels(p).unwrap());
            assert_eq!((held.rows(p), spilled.rows(p)), (2, 2));
        }
        assert_eq!(spilled.get(1).unwrap().a[0].0, 2);
        assert!(
            held.get(3).is_err()
                && spilled.get(3).is_err()
                && spilled.update(5, |_| Ok(())).is_err()
        );
    }
}
