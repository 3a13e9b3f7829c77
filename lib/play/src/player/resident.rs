//! The frame's textures on the GPU and the decoding behind them (thesis 4.7): the level
//! images a missing texture sums, taken from the level-image cache or decoded on the
//! workers; surface textures rebuilt from them on the GPU (the level images uploaded once
//! each, kept while the cache keeps them) or on the workers, and shells' cube maps on the
//! workers; their uploads and GPU MIP chains; and the textures a frame did not draw
//! released when it ends.

use std::collections::{HashMap, HashSet};
use std::sync::Arc;
use std::time::Instant;

use pis_compile::TextureLayout;
use pis_format::texture::LevelLayout;
use pis_format::{Mapping, PisReader};

use super::assemble::assemble_job;
use super::objects::content;
use super::options::{FrameStats, Rebuild};
use super::plan::TextureKey;
use super::prefetch::{AheadJob, AheadTexture, Prefetch, Rebuilt};
use crate::cache::{LevelCache, LevelKey};
use crate::decode::{CubeImage, Decoder, LevelJob, TextureImage};
use crate::error::PlayError;
use crate::gpu::Gpu;
use crate::mip::MipBuilder;
use crate::rebuild::{fits, LevelRebuild, LevelStack};
use crate::shell::ShellTexture;
use crate::textured::ObjectTexture;

/// A texture on the GPU: a surface texture with its MIP chain, or a shell's cube map.
pub(super) enum GpuTexture {
    Surface(ObjectTexture),
    Shell(ShellTexture),
}

/// A texture on the GPU and the frame that last drew it.
struct Resident {
    texture: GpuTexture,
    last_frame: u64,
}

/// The textures on the GPU, the level-image cache and the workers that decode into it.
pub(super) struct Textures {
    decoder: Decoder,
    pub(super) cache: LevelCache,
    mips: MipBuilder,
    rebuild: LevelRebuild,
    rebuild_on: Rebuild,
    /// Decoded level images on the GPU for its rebuild of surface textures, each kept while
    /// the level-image cache keeps it (the thesis's lifetime rule for both copies).
    gpu_levels: HashMap<LevelKey, wgpu::Buffer>,
    prefetch: Prefetch,
    resident: HashMap<TextureKey, Resident>,
    /// The frame being drawn.
    frame: u64,
}

/// The level images of missing textures, by level key.
type Levels = HashMap<LevelKey, Arc<Vec<f32>>>;

impl Textures {
    pub(super) fn new(
        gpu: &Gpu,
        (decoder, cache): (Decoder, LevelCache),
        mips: MipBuilder,
        (rebuild_on, level16): (Rebuild, bool),
    ) -> Textures {
        Textures {
            decoder,
            cache,
            mips,
            rebuild: LevelRebuild::new(gpu, level16),
            rebuild_on,
            gpu_levels: HashMap::new(),
            prefetch: Prefetch::new(),
            resident: HashMap::new(),
            frame: 0,
        }
    }

    /// Where textures are rebuilt.
    pub(super) fn rebuild_on(&self) -> Rebuild {
        self.rebuild_on
    }

    /// The MIP chain builder of the frame's textures.
    pub(super) fn mips(&self) -> &MipBuilder {
        &self.mips
    }

    /// The texture of `key` on the GPU (made resident this frame).
    pub(super) fn get(&self, key: &TextureKey) -> &GpuTexture {
        &self.resident[key].texture
    }

    /// Decodes (on the workers) and uploads every wanted texture not on the GPU.
    /// `reduction`: the texture resolution reduction ([`super::options::PlayerOptions`]).
    pub(super) fn make_resident(
        &mut self,
        gpu: &Gpu,
        reader: &PisReader,
        reduction: u32,
        wanted: &[&TextureKey],
        stats: &mut FrameStats,
    ) -> Result<(), PlayError> {
        let frame = self.frame;
        let mut missing: Vec<&TextureKey> = Vec::new();
        for &key in wanted {
            match self.resident.get_mut(key) {
                Some(r) => r.last_frame = frame,
                None if !missing.contains(&key) => missing.push(key),
                None => {}
            }
        }
        if missing.is_empty() {
            return Ok(());
        }
        let t = Instant::now();
        let hits0 = self.cache.counters();
        // Work prepared ahead: level images into the cache, textures rebuilt on the workers.
        let mut needed: Vec<LevelKey> = Vec::new();
        for k in &missing {
            needed.extend(k.images.iter().enumerate().map(|(lv, &img)| level_key(k, lv, img)));
        }
        let waited = self.prefetch.collect(&mut self.cache, &needed, &missing);
        stats.decode_waits += waited as u64;
        let (mut surfaces, mut shells) = (Vec::new(), Vec::new());
        let (mut images, mut cubes) = (Vec::new(), Vec::new());
        let (prefetch, cache) = (&mut self.prefetch, &mut self.cache);
        missing.retain(|k| match prefetch.take_image(k) {
            Some(rebuilt) => {
                // The frame draws the texture rebuilt from these level images: they are used
                // now, and their lifetimes count from this frame (thesis 4.7).
                let keys = k.images.iter().enumerate().map(|(lv, &img)| level_key(k, lv, img));
                keys.clone().for_each(|key| _ = cache.get(&key));
                stats.prefetched += keys.filter(|key| prefetch.take_ready(key)).count() as u64;
                stats.rebuilt_ahead += 1;
                match rebuilt {
                    Rebuilt::Surface(image) => {
                        surfaces.push(*k);
                        images.push(image);
                    }
                    Rebuilt::Cube(cube) => {
                        shells.push(*k);
                        cubes.push(cube);
                    }
                }
                false
            }
            None => true,
        });
        let have = self.level_images(reader, &missing, stats)?;
        // The rest rebuilt on the GPU, or on the workers: surface textures' finest levels,
        // shells' cube maps.
        let drop_levels = reduction.trailing_zeros();
        let (rebuilt, on_workers): (Vec<&TextureKey>, Vec<&TextureKey>) =
            missing.iter().partition(|k| self.rebuilds_on_gpu(gpu, reader, k, drop_levels));
        let c = reader.container();
        let is_shell = |k: &&TextureKey| {
            c.objects[k.object as usize].layers[k.layer as usize].mapping == Mapping::Shell
        };
        let (rebuilt_shells, rebuilt): (Vec<&TextureKey>, Vec<&TextureKey>) =
            rebuilt.into_iter().partition(is_shell);
        let (cube_keys, surface_keys): (Vec<&TextureKey>, Vec<&TextureKey>) =
            on_workers.into_iter().partition(is_shell);
        let job = |k: &&TextureKey| assemble_job(reader, path_levels(&have, k), k, drop_levels);
        images.extend(self.decoder.assemble(&surface_keys.iter().map(job).collect::<Vec<_>>()));
        cubes.extend(self.decoder.assemble_cubes(&cube_keys.iter().map(job).collect::<Vec<_>>()));
        surfaces.extend(surface_keys);
        shells.extend(cube_keys);
        stats.decode_ms += t.elapsed().as_secs_f64() * 1e3;
        let hits1 = self.cache.counters();
        stats.cache_hits += hits1.hits - hits0.hits;
        stats.cache_misses += hits1.misses - hits0.misses;
        self.upload(
            gpu,
            reader,
            (&surfaces, &images),
            (&shells, &cubes),
            (&rebuilt, &rebuilt_shells, &have),
            stats,
        )
    }

    /// Whether texture `k` is rebuilt on the GPU: where the player rebuilds there, at full
    /// resolution, and its level images fit the device's storage buffers.
    fn rebuilds_on_gpu(&self, gpu: &Gpu, reader: &PisReader, k: &TextureKey, drop: u32) -> bool {
        let layer = &reader.container().objects[k.object as usize].layers[k.layer as usize];
        let l = LevelLayout::of(layer, &layer.blocks[k.block as usize]);
        let values = l.planes().iter().map(|p| p.width as u64 * p.height as u64).sum::<u64>()
            * l.channels as u64;
        self.rebuild_on == Rebuild::Gpu && drop == 0 && fits(gpu, values, k.images.len())
    }

    /// The level images of the `missing` textures (work prepared ahead collected): cached
    /// (decoded ahead or drawn before), or decoded on the workers (each once) and cached.
    fn level_images(
        &mut self,
        reader: &PisReader,
        missing: &[&TextureKey],
        stats: &mut FrameStats,
    ) -> Result<Levels, PlayError> {
        let mut needed: Vec<AheadJob> = Vec::new();
        for k in missing {
            for job in level_jobs(reader, k)? {
                if !needed.iter().any(|j| j.0 == job.0) {
                    needed.push(job);
                }
            }
        }
        let mut have: Levels = HashMap::new();
        let mut jobs: Vec<AheadJob> = Vec::new();
        for job in needed {
            match self.cache.get(&job.0) {
                Some(v) => {
                    if self.prefetch.take_ready(&job.0) {
                        stats.prefetched += 1;
                    }
                    have.insert(job.0, v);
                }
                None => jobs.push(job),
            }
        }
        stats.decode_waits += jobs.len() as u64;
        let level_jobs: Vec<LevelJob> = jobs.iter().map(|j| j.2.clone()).collect();
        let decoded = self.decoder.decode_levels(reader, &level_jobs);
        let mut first_error = None;
        for ((key, height, _), r) in jobs.into_iter().zip(decoded) {
            match r {
                Ok(v) => {
                    let v = Arc::new(v);
                    self.cache.insert(key, height, v.clone());
                    have.insert(key, v);
                }
                Err(e) => {
                    first_error.get_or_insert(e);
                }
            }
        }
        match first_error {
            Some(e) => Err(e),
            None => Ok(have),
        }
    }

    /// Keeps the `predicted` textures already on the GPU through this frame, and queues the
    /// preparation of the others on the workers: their level images neither cached nor in
    /// flight decoded, within the cache's budget (what is cached and in flight counted), and
    /// where the workers rebuild textures (`reduction` as the frame's), the texture rebuilt
    /// once every level image is at hand. Queued work for an earlier prediction is dropped.
    /// A texture whose level images the file lacks is left to the frame that draws it.
    pub(super) fn prefetch(
        &mut self,
        gpu: &Gpu,
        reader: &Arc<PisReader>,
        predicted: &[&TextureKey],
        reduction: u32,
    ) {
        let drop_levels = reduction.trailing_zeros();
        let mut wanted = HashSet::new();
        let mut owned = HashSet::new();
        let mut jobs: Vec<AheadTexture> = Vec::new();
        let mut bytes = self.cache.bytes() + self.prefetch.in_flight_bytes();
        for k in predicted {
            // A texture on the GPU that the motion needs again is kept through this frame.
            if let Some(r) = self.resident.get_mut(*k) {
                r.last_frame = self.frame;
                continue;
            }
            if !wanted.insert((*k).clone())
                || self.prefetch.has_image(k)
                || self.prefetch.rebuilding(k)
            {
                continue;
            }
            let mut t = AheadTexture {
                key: (*k).clone(),
                decode: Vec::new(),
                levels: Vec::new(),
                rebuild: None,
            };
            let mut complete = true;
            for job in level_jobs(reader, k).unwrap_or_default() {
                let cached = self.cache.peek(&job.0);
                t.levels.push((job.0, cached.clone()));
                if cached.is_some() {
                    continue;
                }
                let size = pis_codec::value_count(&job.2.planes).unwrap_or(0) as u64 * 4;
                let ours = !self.prefetch.in_flight(&job.0) && !owned.contains(&job.0);
                if !ours || bytes + size > self.cache.budget() {
                    complete = false;
                    continue;
                }
                bytes += size;
                owned.insert(job.0);
                t.decode.push(job);
            }
            let on_workers = !self.rebuilds_on_gpu(gpu, reader, k, drop_levels);
            t.rebuild = (complete && on_workers && !t.levels.is_empty()).then_some(drop_levels);
            if !t.decode.is_empty() || t.rebuild.is_some() {
                jobs.push(t);
            }
        }
        self.prefetch.start(&self.decoder, reader, wanted, jobs);
    }

    /// Level images dropped from decoding ahead because the prediction changed.
    pub(super) fn prefetch_dropped(&self) -> u64 {
        self.prefetch.dropped()
    }

    /// Uploads the textures rebuilt on the workers (surface textures with their GPU MIP
    /// chains, cube maps with their stored levels) and the level images the GPU's rebuilds
    /// of the `rebuilt` surface textures and cube maps read (from `have`), waits for the GPU,
    /// then records those rebuilds and waits again (the frame's upload and rebuild times
    /// apart); keeps the textures as drawn this frame.
    fn upload(
        &mut self,
        gpu: &Gpu,
        reader: &PisReader,
        (surfaces, images): (&[&TextureKey], &[TextureImage]),
        (shells, cubes): (&[&TextureKey], &[CubeImage]),
        (rebuilt, rebuilt_shells, have): (&[&TextureKey], &[&TextureKey], &Levels),
        stats: &mut FrameStats,
    ) -> Result<(), PlayError> {
        let c = reader.container();
        let frame = self.frame;
        let t = Instant::now();
        let mut encoder = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("uploads") });
        let mut made = Vec::with_capacity(surfaces.len() + shells.len() + rebuilt.len());
        for k in rebuilt.iter().chain(rebuilt_shells) {
            self.upload_levels(gpu, k, have, stats);
        }
        for (k, img) in surfaces.iter().zip(images) {
            let texture = self.mips.texture(gpu, TextureLayout::full(img.width, img.height));
            stats.upload_bytes += self.mips.upload(gpu, &texture, img, &mut encoder)?;
            made.push((
                (*k).clone(),
                Resident { texture: GpuTexture::Surface(texture), last_frame: frame },
            ));
        }
        for (k, cube) in shells.iter().zip(cubes) {
            let texture = ShellTexture::new(gpu, cube.layout, &c.objects[k.object as usize].name)?;
            stats.upload_bytes += texture.upload_atlas(gpu, &cube.texels)?;
            made.push((
                (*k).clone(),
                Resident { texture: GpuTexture::Shell(texture), last_frame: frame },
            ));
        }
        submit_and_wait(gpu, encoder)?;
        stats.upload_ms += t.elapsed().as_secs_f64() * 1e3;
        if !rebuilt.is_empty() || !rebuilt_shells.is_empty() {
            let t = Instant::now();
            let mut encoder = gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("rebuilds"),
            });
            for k in rebuilt.iter().chain(rebuilt_shells) {
                let texture = self.rebuild_on_gpu(gpu, reader, k, &mut encoder)?;
                made.push(((*k).clone(), Resident { texture, last_frame: frame }));
            }
            submit_and_wait(gpu, encoder)?;
            stats.rebuild_ms += t.elapsed().as_secs_f64() * 1e3;
        }
        self.resident.extend(made);
        Ok(())
    }

    /// Uploads the level images of texture `k` (from `have`) that are not yet on the GPU,
    /// each as a compact storage buffer kept while the cache keeps its decoded copy.
    fn upload_levels(&mut self, gpu: &Gpu, k: &TextureKey, have: &Levels, stats: &mut FrameStats) {
        for (lv, &img) in k.images.iter().enumerate() {
            let key = level_key(k, lv, img);
            if let std::collections::hash_map::Entry::Vacant(e) = self.gpu_levels.entry(key) {
                let values = &have[&key];
                stats.upload_bytes += self.rebuild.level_bytes(values.len());
                e.insert(self.rebuild.level_buffer(gpu, values));
            }
        }
    }

    /// Records the GPU's rebuild of texture `k` (a surface texture or a cube map) from its
    /// level images, on the GPU ([`Textures::upload_levels`]).
    fn rebuild_on_gpu(
        &mut self,
        gpu: &Gpu,
        reader: &PisReader,
        k: &TextureKey,
        encoder: &mut wgpu::CommandEncoder,
    ) -> Result<GpuTexture, PlayError> {
        let object = &reader.container().objects[k.object as usize];
        let layer = &object.layers[k.layer as usize];
        let l = LevelLayout::of(layer, &layer.blocks[k.block as usize]);
        let levels: Vec<&wgpu::Buffer> = k
            .images
            .iter()
            .enumerate()
            .map(|(lv, &img)| &self.gpu_levels[&level_key(k, lv, img)])
            .collect();
        let stack = LevelStack { levels: &levels, channels: l.channels, gamma: layer.gamma };
        if layer.mapping == Mapping::Shell {
            let texture = ShellTexture::new(gpu, TextureLayout::cube(l.width), &object.name)?;
            self.rebuild.record_cube(gpu, (&texture, &stack), &l, encoder);
            return Ok(GpuTexture::Shell(texture));
        }
        let texture = self.mips.texture(gpu, TextureLayout::full(l.width, l.height));
        self.rebuild.record(gpu, (&texture, &stack), &self.mips, encoder);
        Ok(GpuTexture::Surface(texture))
    }

    /// Ends the frame: level-image lifetimes and budget (the GPU's copies going with the
    /// cache's), and GPU textures the frame did not draw released.
    pub(super) fn end_frame(&mut self) {
        let frame = self.frame;
        self.resident.retain(|_, r| r.last_frame == frame);
        self.cache.end_frame();
        let cache = &self.cache;
        self.gpu_levels.retain(|k, _| cache.contains(k));
        self.prefetch.end_frame(cache);
        self.frame += 1;
    }
}

/// The level images on texture `k`'s pyramid path as decoding jobs, top first.
fn level_jobs(reader: &PisReader, k: &TextureKey) -> Result<Vec<AheadJob>, PlayError> {
    let c = reader.container();
    let layer = &c.objects[k.object as usize].layers[k.layer as usize];
    let block = &layer.blocks[k.block as usize];
    let planes = LevelLayout::of(layer, block).planes();
    let n = block.levels.len() as u32;
    let mut jobs = Vec::with_capacity(k.images.len());
    for (lv, (level, &img)) in block.levels.iter().zip(&k.images).enumerate() {
        let key = level_key(k, lv, img);
        let stream = *level
            .images
            .get(img as usize)
            .ok_or_else(|| content(reader, format!("{key:?}: no such level image")))?;
        let at = (k.object as usize, k.layer as usize, k.block as usize, lv);
        jobs.push((key, n - 1 - lv as u32, LevelJob { stream, planes: planes.clone(), at }));
    }
    Ok(jobs)
}

/// Submits `encoder` and waits for the GPU to finish it.
fn submit_and_wait(gpu: &Gpu, encoder: wgpu::CommandEncoder) -> Result<(), PlayError> {
    gpu.queue.submit([encoder.finish()]);
    gpu.device
        .poll(wgpu::PollType::wait_indefinitely())
        .map(|_| ())
        .map_err(|e| PlayError::Readback(e.to_string()))
}

/// The cache key of level `lv`'s image `img` of texture `k`.
fn level_key(k: &TextureKey, lv: usize, img: u32) -> LevelKey {
    LevelKey { object: k.object, layer: k.layer, block: k.block, level: lv as u32, image: img }
}

/// The level images of texture `k`'s pyramid path (in `have`), top first.
fn path_levels(have: &Levels, k: &TextureKey) -> Vec<Arc<Vec<f32>>> {
    k.images.iter().enumerate().map(|(lv, &img)| have[&level_key(k, lv, img)].clone()).collect()
}
