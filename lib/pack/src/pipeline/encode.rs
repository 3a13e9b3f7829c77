//! From inferred textures to the container: parameter-space blocks with staggered origins
//! (thesis 4.7), the adaptive Laplacian pyramid of gamma-compensated textures per object,
//! layer and block (4.3, 4.6), equal-slope storage allocation (4.5) and encoding; then the
//! checks that read the result back.

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::{anyhow, Result};
use pis_codec::CodecId;
use pis_format::blocks::BlockGrid;
use pis_format::reconstruct::prepare;
use pis_format::*;

use super::blocks::transforms;
use super::input::LoadedSet;
use super::model::{key, ObjectModel};
pub use super::packed::LayerTextures;
use super::packed::{MaxMseChoice, Packed, PackedBlock, Quality};
use super::plan::{Aim, Plan};
use super::played;
use super::predict::{predicted_psnr, solved_error, total_psnr};
use super::shading::object_shading;
use super::storage::{
    allocate_storage, build_pyramid, level_streams, measure_items, reachable_coding_db,
    BlockPyramid,
};
use super::stored_mesh::stored_mesh;
pub use super::surface::{finest, mip_chain};
use super::{MaxMse, PackRequest, Stages};
use crate::error::{Exit, Failure};

/// The screen weight of every level-0 texel of a texture placed by `placement` at one
/// point: the column sums of its render matrix `a` (how much of the covered pixels each
/// texel of the MIP chain makes up: rows sum to 1), carried down the decimation to level 0
/// (Dᵀ), as the player draws coarser levels from level 0.
fn screen_weights_at(a: &pis_compile::RenderMatrix) -> Vec<f64> {
    let dec = pis_compile::decimation::Decimation::new(a.layout);
    let cols = column_sums(a);
    let mut out = vec![0.0f64; dec.base_len()];
    dec.reduce(&cols, &mut out);
    out
}

/// The column sums of a render matrix: how much of the covered pixels each texel makes up.
fn column_sums(a: &pis_compile::RenderMatrix) -> Vec<f64> {
    let mut cols = vec![0.0f64; a.cols()];
    for r in 0..a.rows() {
        let (c, w) = a.row(r);
        c.iter().zip(w).for_each(|(&c, &w)| cols[c as usize] += w as f64);
    }
    cols
}

/// Texel weights of one layer sample: the sum of the per-point weights of the points that
/// read it (all views of a view-independent sample), scaled to mean 1; all zero where no
/// point shows the object.
fn sample_weights(per_point: &[Vec<f64>]) -> Vec<f32> {
    let n = per_point.first().map_or(0, Vec::len);
    let mut sum = vec![0.0f64; n];
    for w in per_point {
        sum.iter_mut().zip(w).for_each(|(a, w)| *a += w);
    }
    let total: f64 = sum.iter().sum();
    let scale = if total > 0.0 { n as f64 / total } else { 0.0 };
    sum.iter().map(|w| (w * scale) as f32).collect()
}

/// The screen weights of sample `k` of layer `li` of `m`: [`sample_weights`] over `points`,
/// the points that read it, through the render matrices of its placement. Made as each
/// block's pyramid is built, so that a pack holds the weights of one block at a time.
fn sample_screen_weights(
    m: &ObjectModel,
    li: usize,
    k: &[u32],
    points: &[usize],
) -> Result<Vec<f32>> {
    let il = &m.layers[li];
    Ok(if points.is_empty() {
        vec![0.0; il.form.stored_texels(k)]
    } else if let (Some(s), Some(shells)) = (il.shell, &m.shells) {
        shells.weights(s, il.form.stored_texels(k), points)
    } else {
        let pid = il.placement_of[k];
        sample_weights(
            &points
                .iter()
                .map(|&p| Ok(screen_weights_at(m.views.get(p)?.a(pid))))
                .collect::<Result<Vec<_>>>()?,
        )
    })
}

/// Layer `li`'s order within its term: the object's layers in turn, a relightable layer's
/// coefficients (SPEC.md 7.1) sharing their first one's.
fn order_of(m: &ObjectModel, li: usize) -> u8 {
    let starts = |l: &super::model::InferredLayer| l.light.as_ref().is_none_or(|b| b.c == 0);
    (m.layers[..=li].iter().filter(|l| starts(l)).count() - 1) as u8
}

/// Every block's pyramid, in (object model, layer, block) order, and where each goes.
#[derive(Default)]
struct Pyramids {
    built: Vec<BlockPyramid>,
    at: Vec<(usize, usize, usize)>,
}

/// A layer sample's texel weights, by key, kept for the master.
type MasterWeights = BTreeMap<Vec<u32>, Vec<f32>>;

/// Block `b` of `grid`'s samples of layer `li` of `m`: per block-local sample its key, its
/// stored values prepared for the pyramid of `layer` (`layout`), and, with screen-error
/// allocation (`points_of`: the points that read each sample), its texel weights, which
/// `master` keeps a copy of where given.
fn block_samples(
    (m, li): (&ObjectModel, usize),
    (grid, b): (&BlockGrid, usize),
    (layer, layout): (&Layer, &LevelLayout),
    ndims: usize,
    points_of: Option<&BTreeMap<Vec<u32>, Vec<usize>>>,
    mut master: Option<&mut MasterWeights>,
) -> Result<BlockSamples, Failure> {
    let runtime = |e: anyhow::Error| Failure::new(Exit::Runtime, e);
    let il = &m.layers[li];
    let count: usize = grid.extent(b).iter().map(|&e| e as usize).product();
    let mut keys = vec![Vec::new(); count];
    let mut samples = vec![Vec::new(); count];
    let mut weights = vec![Vec::new(); count];
    for k in il.textures.keys() {
        let mut point = vec![0u32; ndims];
        for (d, &v) in il.depends_on.dims().zip(k) {
            point[d] = v;
        }
        let pos = grid.locate(&point);
        if pos.block != b {
            continue;
        }
        let x = il.textures.get(k).map_err(runtime)?;
        let idx = pos
            .local
            .iter()
            .zip(&pos.extent)
            .fold(0usize, |a, (&l, &e)| a * e as usize + l as usize);
        keys[idx] = k.clone();
        samples[idx] = prepare(layer, layout, &il.form.stored(k, &x));
        if let Some(points_of) = points_of {
            let points = points_of.get(k).map_or(&[][..], Vec::as_slice);
            let w = sample_screen_weights(m, li, k, points).map_err(runtime)?;
            if let Some(master) = master.as_deref_mut() {
                master.insert(k.clone(), w.clone());
            }
            weights[idx] = w;
        }
    }
    if samples.iter().any(Vec::is_empty) {
        return Err(runtime(anyhow!(
            "object {} layer {} block {b}: a sample has no texture",
            m.name,
            il.kind.name()
        )));
    }
    Ok(BlockSamples { keys, samples, weights })
}

/// An object as the container stores it (levels empty), its layers' blocks as coded and
/// their screen weights kept for the master.
type PackedObject = (Object, Vec<Vec<PackedBlock>>, Vec<MasterWeights>);

/// One block's samples: per block-local sample its key, prepared values and texel weights.
struct BlockSamples {
    keys: Vec<Vec<u32>>,
    samples: Vec<Vec<f32>>,
    weights: Vec<Vec<f32>>,
}

/// Layer `li` of object model `mi` cut into the blocks of `plan`, each block's adaptive
/// Laplacian pyramid built into `out`: the container layer (levels empty) and its blocks as
/// coded.
fn layer_pyramids(
    set: &LoadedSet,
    (m, mi, li): (&ObjectModel, usize, usize),
    plan: &Plan,
    req: &PackRequest,
    master: &mut MasterWeights,
    out: &mut Pyramids,
) -> Result<(Layer, Vec<PackedBlock>), Failure> {
    let runtime = |e: anyhow::Error| Failure::new(Exit::Runtime, e);
    let il = &m.layers[li];
    // The weights go to the pyramids; the master (`--keep-master`) keeps a copy.
    let screen = req.allocation == super::Allocation::Screen;
    let weighed = screen && !il.textures.is_empty() && req.codec.is_lossy();
    // The points that read each sample of the layer.
    let mut points_of: BTreeMap<Vec<u32>, Vec<usize>> = BTreeMap::new();
    if screen {
        for (p, s) in set.samples.iter().enumerate() {
            points_of.entry(key(s, il.depends_on)).or_default().push(p);
        }
    }
    let mut layer = il.form.layer(il.kind, order_of(m, li), il.depends_on, req.gamma);
    layer.basis = il.light.as_ref().map_or(0, |b| b.c as u8 + 1);
    let grid = BlockGrid::new(&plan.space, il.depends_on, &m.stagger);
    let layer_samples = il.textures.len().max(1) as f64;
    let mut pblocks = Vec::new();
    for b in 0..grid.block_count() as usize {
        let extent = grid.extent(b);
        let block = il.form.block(b);
        let layout = LevelLayout::of(&layer, &block);
        let BlockSamples { keys, samples, weights } = block_samples(
            (m, li),
            (&grid, b),
            (&layer, &layout),
            plan.space.dims.len(),
            screen.then_some(&points_of),
            req.keep_master.then_some(&mut *master),
        )?;
        let mut pyramid = build_pyramid(
            mi,
            layout.planes(),
            &extent,
            &samples,
            layer_samples,
            !req.codec.is_lossy(),
            req.pyramid == super::PyramidMode::Full,
        )
        .map_err(runtime)?;
        // The level images hold the samples from here on.
        drop(samples);
        if weighed {
            pyramid.texel_weights = Some(weights);
        }
        // A pack that streams keeps the level images in its scratch file, their
        // rate–distortion curves measured.
        if let Some(scratch) = &set.scratch {
            pyramid.spill(scratch, req.codec).map_err(runtime)?;
        }
        out.built.push(pyramid);
        out.at.push((mi, li, b));
        pblocks.push(PackedBlock { extent, keys, levels: vec![] });
        layer.blocks.push(block);
    }
    Ok((layer, pblocks))
}

/// Object model `mi` as the container stores it (levels empty), its layers' blocks as coded
/// and their screen weights kept for the master, the pyramids built into `out`.
fn object_pyramids(
    set: &LoadedSet,
    (m, mi): (&ObjectModel, usize),
    plan: &Plan,
    req: &PackRequest,
    out: &mut Pyramids,
) -> Result<PackedObject, Failure> {
    let mut master_by_layer: Vec<MasterWeights> =
        m.layers.iter().map(|_| BTreeMap::new()).collect();
    let mut layers = Vec::new();
    let mut layer_blocks = Vec::new();
    for (li, master) in master_by_layer.iter_mut().enumerate() {
        let (layer, pblocks) = layer_pyramids(set, (m, mi, li), plan, req, master, out)?;
        layers.push(layer);
        layer_blocks.push(pblocks);
    }
    // The object's role and shading constants as the scene gives them (SPEC.md 6.4).
    let role = set.scene.objects[m.index].role;
    let object = Object {
        name: m.name.clone(),
        role,
        shading: object_shading(&set.scene, m.index),
        stagger: m.stagger.clone(),
        transforms: transforms(set, &plan.space, m.index),
        mesh: stored_mesh(set, m, role),
        layers,
    };
    Ok((object, layer_blocks, master_by_layer))
}

/// The settings the file's provenance records.
fn provenance_settings(
    set: &LoadedSet,
    models: &[ObjectModel],
    plan: &Plan,
    req: &PackRequest,
) -> Vec<(String, String)> {
    let mut settings = vec![
        ("codec".to_string(), req.codec.name().to_string()),
        ("block".to_string(), plan.sizes.iter().map(u32::to_string).collect::<Vec<_>>().join("x")),
        ("matrix".to_string(), req.matrix.name().to_string()),
        ("gamma".to_string(), req.gamma.to_string()),
        (super::TARGET_SETTING.to_string(), req.target.describe()),
    ];
    settings.splice(2..2, file_filter(req.filter).settings());
    // An object whose textures were solved for another filter than the file's (6.6).
    for m in models.iter().filter(|m| m.filter != req.filter) {
        settings.push(file_filter(m.filter).object_setting(&m.name));
    }
    if req.pyramid != super::PyramidMode::Adaptive {
        settings.push(("pyramid".to_string(), req.pyramid.name().to_string()));
    }
    if req.layers != super::LayerMode::Separate {
        settings.push(("layers".to_string(), req.layers.name().to_string()));
    }
    if req.allocation != super::Allocation::Screen {
        settings.push(("allocation".to_string(), req.allocation.name().to_string()));
    }
    if req.stagger != super::Stagger::Auto {
        settings.push(("stagger".to_string(), req.stagger.name().to_string()));
    }
    // The set's display filter, which players resolve multisampled frames with (SPEC.md
    // 6.6); a set recording an invalid one (rule 9002) is packed without it.
    let f = set.display_filter;
    if let Ok(display) = pis_format::DisplayFilter::new(f.sigma_px, f.radius_px) {
        settings.extend(display.settings());
    }
    // The light directions of the set (SPEC.md 6.6): what relightable layers span, and
    // where the light is sampled, each sample's direction.
    if let Some(r) = super::relit::Relit::of(set) {
        settings.extend(r.settings());
    }
    // The tint lens objects give the light they transmit (SPEC.md 6.6), where not white.
    for m in models.iter().filter(|m| m.shells.as_ref().is_some_and(|s| s.transmits())) {
        let tint = super::hybrid::transmission_tint(set, m.index);
        if tint != [1.0; 3] {
            settings.push(pis_format::tint::tint_setting(&m.name, tint));
        }
        // The paths its shells are drawn along, where not the greedy two.
        let model = m.shells.as_ref().map(|s| s.lens_model()).unwrap_or_default();
        if !model.is_greedy() {
            let terms = pis_compile::hybrid::file_lens_terms(model);
            settings.push(pis_format::lens_model::lens_model_setting(&m.name, terms));
        }
    }
    settings
}

/// Level lists with empty codestreams in every block of `container`: what the bytes of
/// everything but the images are measured on.
fn empty_levels(container: &mut Container, pyramids: &Pyramids, codec: CodecId) {
    let mut next = 0;
    for (o, ob) in container.objects.iter_mut().enumerate() {
        for (l, layer) in ob.layers.iter_mut().enumerate() {
            for (b, block) in layer.blocks.iter_mut().enumerate() {
                // Blocks come in the order their pyramids were built.
                debug_assert_eq!(pyramids.at[next], (o, l, b));
                block.levels = pyramids.built[next]
                    .levels
                    .iter()
                    .map(|(c, imgs, _)| Level {
                        counts: c.clone(),
                        images: imgs.iter().map(|_| Codestream { codec, bytes: vec![] }).collect(),
                    })
                    .collect();
                next += 1;
            }
        }
    }
}

/// Builds pyramids, allocates storage, encodes, and assembles the container.
pub fn encode_all(
    set: &LoadedSet,
    models: &[ObjectModel],
    plan: &Plan,
    req: &PackRequest,
    stages: &mut Stages,
) -> Result<Packed, Failure> {
    let runtime = |e: anyhow::Error| Failure::new(Exit::Runtime, e);
    if pis_codec::codec(req.codec).is_none() {
        return Err(runtime(anyhow!("codec {} is not in this build", req.codec)));
    }
    let mut pyramids = Pyramids::default();
    let (mut objects, mut blocks_out, mut screen_weights) = (Vec::new(), Vec::new(), Vec::new());
    for (mi, m) in models.iter().enumerate() {
        let (object, blocks, weights) = object_pyramids(set, (m, mi), plan, req, &mut pyramids)?;
        objects.push(object);
        blocks_out.push(blocks);
        screen_weights.push(weights);
    }
    let level_images: usize =
        pyramids.built.iter().flat_map(|p| &p.levels).map(|l| l.1.len()).sum();
    stages.done("pyramid", &format!("{level_images} level images in adaptive pyramids"));

    let raw = set.raw_image_bytes();
    let mut container = Container {
        space: plan.space.clone(),
        cameras: plan.cameras.clone(),
        objects,
        provenance: Some(Provenance {
            tool: format!("pis-pack {}", env!("CARGO_PKG_VERSION")),
            source: set.dir.display().to_string(),
            raw_image_bytes: raw,
            settings: provenance_settings(set, models, plan, req),
        }),
    };
    empty_levels(&mut container, &pyramids, req.codec);
    let overhead = pis_format::to_bytes_unchecked(&container).len();

    // Per object, its solved textures drawn and measured, then dropped.
    let solved_error =
        models.iter().map(|m| solved_error(set, m)).collect::<Result<Vec<_>>>().map_err(runtime)?;
    let packed = Packed {
        container,
        blocks: blocks_out,
        overhead,
        layer_bytes: Vec::new(),
        stagger: models.iter().map(|m| m.stagger.clone()).collect(),
        screen_weights,
        solved_error,
        max_mse: None,
        quality: None,
        played: None,
    };
    // The ratio counts level images against the raw images (thesis 4.8); geometry and
    // tables come on top and are reported apart.
    let areas: Vec<f64> = models.iter().map(|m| m.area).collect();
    let target = match plan.target {
        Aim::Played { within_db, goal_db } if req.codec.is_lossy() => {
            let goal = (within_db, goal_db);
            return played_file(set, models, packed, pyramids, goal, &areas, req, stages);
        }
        Aim::Fixed(target) => target,
        // An exact codec takes no allocation.
        Aim::Played { .. } => pis_codec::allocate::Target::Bytes(usize::MAX),
    };
    let storage = allocate_storage(&pyramids.built, req.codec, target, &areas, req.max_mse)
        .map_err(|e| target_failure(e, raw))?;
    if let Some(total) = storage.allocated {
        stages
            .done("allocate", &format!("{total} bytes over {} level images", storage.level_images));
    }
    let Some((free_rates, free_bytes)) = &storage.free else {
        let (built, at) = (pyramids.built, pyramids.at);
        let mut packed = emit(packed, &built, &at, models, req.codec, &storage.rates)?;
        drop(built);
        if req.codec.is_lossy() {
            record_max_mse(&mut packed, req.max_mse.alpha().map_or(MaxMse::Off, MaxMse::On));
        }
        stages.done("encode", &format!("{level_images} level images with {}", req.codec));
        return Ok(packed);
    };
    let packed =
        constrained_or_free(set, models, packed, pyramids, (&storage.rates, free_rates), req)?;
    let c = packed.max_mse.clone().expect("the choice between the allocations");
    stages.done("encode", &format!(
        "{level_images} level images with {}, twice: the max-MSE constraint (alpha {}) predicts {:.2} dB, the free allocation ({free_bytes} bytes) {:.2} dB: {} kept",
        req.codec, c.alpha, c.psnr_db_constrained, c.psnr_db_free, if c.constrained { "the constraint" } else { "the free allocation" },
    ));
    Ok(packed)
}

/// The file under a played-quality target (`goal`: dB within the solved textures, or a
/// predicted played PSNR to reach): the fewest bytes [`played::search`] finds, each trial
/// allocated for a coding PSNR, encoded and predicted. Where an object plays more than
/// [`played::OBJECT_WITHIN_FACTOR`] times the target below its own solved figure, its
/// allocation weight is raised and the search runs again (at most
/// [`played::OBJECT_ROUNDS`] searches).
#[allow(clippy::too_many_arguments)]
fn played_file(
    set: &LoadedSet,
    models: &[ObjectModel],
    packed: Packed,
    mut pyramids: Pyramids,
    (within_db, goal_db): (f64, Option<f64>),
    areas: &[f64],
    req: &PackRequest,
    stages: &mut Stages,
) -> Result<Packed, Failure> {
    let runtime = |e: anyhow::Error| Failure::new(Exit::Runtime, e);
    measure_items(&mut pyramids.built, req.codec).map_err(runtime)?;
    let solved_db = total_psnr(&packed.solved_error);
    let goal_db = goal_db.unwrap_or(solved_db - within_db);
    let object_limit = within_db * played::OBJECT_WITHIN_FACTOR;
    let mut weights = areas.to_vec();
    let mut held: Vec<String> = Vec::new();
    let mut searches = Vec::new();
    let (mut file, quality, found) = loop {
        let (file, quality, found) =
            search_file(set, models, &packed, &pyramids, (goal_db, solved_db), &weights, req)?;
        searches.push(found.trials.len());
        let raise = played::raised_weights(&quality.objects, object_limit);
        if raise.is_empty() || searches.len() == played::OBJECT_ROUNDS {
            break (file, quality, found);
        }
        for (o, factor) in raise {
            weights[o] *= factor;
            if !held.contains(&models[o].name) {
                held.push(models[o].name.clone());
            }
        }
    };
    let t = found.trial();
    let held_words = match held.is_empty() {
        true => String::new(),
        false => format!(
            ", the weight of {} raised to hold it within {object_limit} dB of its solved figure",
            held.join(", ")
        ),
    };
    stages.done("encode", &format!(
        "{} allocations encoded and predicted for {goal_db:.2} dB played ({solved_db:.2} dB as solved){held_words}: {} bytes predict {:.2} dB{}",
        searches.iter().sum::<usize>(), t.bytes, t.psnr_db,
        if found.reached { "" } else { ", the closest the codec reaches" },
    ));
    file.quality = Some(quality);
    file.played = Some(played::Played { found, held, searches: searches.len() });
    record_max_mse(&mut file, req.max_mse.alpha().map_or(MaxMse::Off, MaxMse::On));
    Ok(file)
}

/// One [`played::search`] for `goal_db` (the file's solved figure `solved_db`) with the
/// objects' allocation weights `weights`: the file kept, its prediction and the search.
fn search_file(
    set: &LoadedSet,
    models: &[ObjectModel],
    packed: &Packed,
    pyramids: &Pyramids,
    (goal_db, solved_db): (f64, f64),
    weights: &[f64],
    req: &PackRequest,
) -> Result<(Packed, Quality, played::Found), Failure> {
    let runtime = |e: anyhow::Error| Failure::new(Exit::Runtime, e);
    let reachable = reachable_coding_db(&pyramids.built, req.codec, weights).map_err(runtime)?;
    let goal = played::Goal { goal_db, solved_db, reachable_coding_db: reachable };
    let mut files = Vec::new();
    let found = played::search(goal, |c| -> Result<played::Trial, Failure> {
        let aim = pis_codec::allocate::Target::Psnr { db: c, peak: 1.0 };
        let storage = allocate_storage(&pyramids.built, req.codec, aim, weights, req.max_mse)
            .map_err(runtime)?;
        let file =
            emit(packed.clone(), &pyramids.built, &pyramids.at, models, req.codec, &storage.rates)?;
        let q = predicted_psnr(set, models, &file).map_err(runtime)?;
        let bytes = file.layer_bytes.iter().flatten().sum();
        let trial = played::Trial { coding_db: c, bytes, psnr_db: q.overall };
        files.push((file, q));
        Ok(trial)
    })?;
    let (file, quality) = files.swap_remove(found.kept);
    Ok((file, quality, found))
}

/// Both allocations, with the max-MSE constraint (`rates.0`) and without (`rates.1`),
/// encoded; the decoded textures of each rendered through the render matrices against the
/// traced images: the higher predicted PSNR is kept.
fn constrained_or_free(
    set: &LoadedSet,
    models: &[ObjectModel],
    packed: Packed,
    pyramids: Pyramids,
    (constrained, free): (&[pis_codec::Rate], &[pis_codec::Rate]),
    req: &PackRequest,
) -> Result<Packed, Failure> {
    let runtime = |e: anyhow::Error| Failure::new(Exit::Runtime, e);
    let alpha = req.max_mse.alpha().unwrap_or(pis_codec::allocate::DEFAULT_ALPHA);
    let (built, at) = (pyramids.built, pyramids.at);
    let with = emit(packed.clone(), &built, &at, models, req.codec, constrained)?;
    let without = emit(packed, &built, &at, models, req.codec, free)?;
    drop(built);
    let (q_with, q_without) = (
        predicted_psnr(set, models, &with).map_err(runtime)?,
        predicted_psnr(set, models, &without).map_err(runtime)?,
    );
    let (db_with, db_without) = (q_with.overall, q_without.overall);
    let keep = db_with >= db_without;
    let (mut packed, quality) = if keep { (with, q_with) } else { (without, q_without) };
    packed.quality = Some(quality);
    packed.max_mse = Some(MaxMseChoice {
        alpha,
        constrained: keep,
        psnr_db_constrained: db_with,
        psnr_db_free: db_without,
    });
    record_max_mse(&mut packed, if keep { MaxMse::On(alpha) } else { MaxMse::Off });
    Ok(packed)
}

/// Provenance: the max-MSE constraint the allocation applied (`off`, or its α), by its
/// [`MaxMse::name`].
fn record_max_mse(packed: &mut Packed, applied: MaxMse) {
    if let Some(p) = packed.container.provenance.as_mut() {
        p.settings.push(("max_mse_ratio".to_string(), applied.name()));
    }
}

/// The codestreams of `pyramids` at `rates`, put into `packed`'s container and blocks (with
/// the level images as encoded where the codec is exact, which [`check_lossless`] reads).
fn emit(
    mut packed: Packed,
    pyramids: &[BlockPyramid],
    where_: &[(usize, usize, usize)],
    models: &[ObjectModel],
    codec: CodecId,
    rates: &[pis_codec::Rate],
) -> Result<Packed, Failure> {
    let streams =
        level_streams(pyramids, codec, rates).map_err(|e| Failure::new(Exit::Runtime, e))?;
    let mut layer_bytes: Vec<Vec<usize>> = models.iter().map(|m| vec![0; m.layers.len()]).collect();
    for ((mi, li, b), (pyramid, streams)) in where_.iter().zip(pyramids.iter().zip(streams)) {
        let block = &mut packed.container.objects[*mi].layers[*li].blocks[*b];
        for (level, streams) in block.levels.iter_mut().zip(&streams) {
            for (image, bytes) in level.images.iter_mut().zip(streams) {
                layer_bytes[*mi][*li] += bytes.len();
                image.bytes = bytes.clone();
            }
        }
        let images = if codec.is_lossy() {
            None
        } else {
            Some(pyramid.level_images().map_err(|e| Failure::new(Exit::Runtime, e))?)
        };
        packed.blocks[*mi][*li][*b].levels = pyramid
            .levels
            .iter()
            .zip(streams)
            .enumerate()
            .map(|(lv, ((counts, _, _), streams))| {
                (counts.clone(), images.as_ref().map_or_else(Vec::new, |i| i[lv].to_vec()), streams)
            })
            .collect();
    }
    packed.layer_bytes = layer_bytes;
    Ok(packed)
}

/// The lossless master of every object (SPEC.md 6.7): each layer sample's finest solved
/// texture, linear as solved, and the object's screen-area weight of allocation.
pub fn masters(models: &[ObjectModel], packed: &Packed) -> Result<Vec<Master>> {
    models
        .iter()
        .enumerate()
        .map(|(mi, m)| {
            // Keys are sample indices over the layer's dimensions: their order is table order.
            let textures: Vec<Vec<Vec<f32>>> = m
                .layers
                .iter()
                .map(|l| l.textures.iter().map(|r| r.map(|(k, x)| l.form.stored(k, &x))).collect())
                .collect::<Result<_>>()?;
            // The screen weights the allocation used, so that coding the master again allocates
            // as this pack did.
            let by_layer = &packed.screen_weights[mi];
            // SPEC.md 6.7's screen weights are one surface plane per sample: an object with
            // shells keeps none in its master.
            let surfaces = m.layers.iter().all(|l| l.shell.is_none());
            let weights: Option<Vec<Vec<Vec<f32>>>> = (surfaces
                && by_layer.iter().all(|w| !w.is_empty()))
            .then(|| by_layer.iter().map(|w| w.values().cloned().collect()).collect());
            Ok(Master::encode(&packed.container, mi, m.area, &textures, weights.as_deref())?)
        })
        .collect()
}

/// Reads the written file's master back; returns its bytes and whether every texture decodes
/// to the finest solved texture bit for bit.
pub fn check_master(path: &Path, models: &[ObjectModel]) -> Result<(u64, bool)> {
    let reader = PisReader::open(path)?;
    let c = reader.container();
    let masters = reader.masters()?;
    let mut exact = masters.len() == models.len();
    for (m, model) in masters.iter().zip(models) {
        for (li, l) in model.layers.iter().enumerate() {
            for (s, r) in l.textures.iter().enumerate() {
                let (k, x) = r?;
                let got = m.texture(c, li, s)?;
                let want = l.form.stored(k, &x);
                exact &= got.len() == want.len()
                    && got.iter().zip(&want).all(|(a, b)| a.to_bits() == b.to_bits());
            }
        }
    }
    Ok((reader.master_bytes(), exact))
}

/// Reads the written file back and checks that every level image decodes to exactly the
/// values that were encoded (bit for bit), as the lossless codec promises.
pub fn check_lossless(path: &Path, packed: &Packed) -> Result<bool> {
    let reader = PisReader::open(path)?;
    let c = reader.container();
    for (mi, ob) in c.objects.iter().enumerate() {
        for (li, layer) in ob.layers.iter().enumerate() {
            for (b, block) in layer.blocks.iter().enumerate() {
                let planes = LevelLayout::of(layer, block).planes();
                for (lv, level) in block.levels.iter().enumerate() {
                    for (ii, r) in level.images.iter().enumerate() {
                        let bytes = reader.codestream(r)?;
                        let got = pis_codec::decode(r.codec, &planes, &bytes)?;
                        let want = &packed.blocks[mi][li][b].levels[lv].1[ii];
                        if got.len() != want.len()
                            || got.iter().zip(want).any(|(a, b)| a.to_bits() != b.to_bits())
                        {
                            return Ok(false);
                        }
                    }
                }
            }
        }
    }
    Ok(true)
}

/// The file's record of the player's filter (SPEC.md 6.6).
fn file_filter(f: pis_compile::Filter) -> pis_format::FileFilter {
    match f {
        pis_compile::Filter::Nearest => pis_format::FileFilter::Nearest,
        pis_compile::Filter::Bilinear => pis_format::FileFilter::Bilinear,
        pis_compile::Filter::Trilinear => pis_format::FileFilter::Trilinear,
        pis_compile::Filter::Anisotropic(n) => pis_format::FileFilter::Anisotropic(n),
    }
}

/// An allocation that cannot meet its target says which target to ask for instead
/// (exit 1: the request, not the input, is at fault); other failures are runtime errors.
fn target_failure(e: anyhow::Error, raw: u64) -> Failure {
    use pis_codec::allocate::AllocError;
    match e.downcast_ref::<AllocError>() {
        Some(AllocError::Budget { needed, budget }) => Failure::new(Exit::Usage, anyhow!(
            "the ratio leaves {budget} bytes for the level images, but their smallest encodings need {needed}: the highest ratio this set reaches is {:.1}:1 (raw images {raw} bytes)",
            raw as f64 / (*needed).max(1) as f64
        )),
        Some(AllocError::Unreachable { db, best_db }) => Failure::new(Exit::Usage, anyhow!(
            "--psnr {db} dB is out of reach: the stored textures reach at most {best_db:.2} dB (coding PSNR at the codec's full rate); ask for at most that, or use --codec lossless"
        )),
        _ => Failure::new(Exit::Runtime, e),
    }
}

#[cfg(test)]
mod tests {
    use super::sample_weights;

    #[test]
    fn sample_weights_sum_the_points_that_read_a_sample_scaled_to_mean_one() {
        let per_point =
            [vec![2.0, 0.0, 0.0, 2.0], vec![0.0, 0.0, 4.0, 0.0], vec![1.0, 1.0, 1.0, 1.0]];
        // two views of a view-independent sample: texels seen by both weigh most, the
        // texel no view reads weighs nothing
        let w = sample_weights(&per_point[..2]);
        assert_eq!(w, vec![1.0, 0.0, 2.0, 1.0]);
        assert!((w.iter().sum::<f32>() / 4.0 - 1.0).abs() < 1e-6);
        assert_eq!(sample_weights(&per_point[2..]), vec![1.0; 4]);
        // a sample no point shows weighs nothing anywhere
        assert_eq!(sample_weights(&[vec![0.0; 3]]), vec![0.0; 3]);
        assert!(sample_weights(&[]).is_empty());
    }
}
