//! The player (thesis 4.7): opens a `.pis` for random access, and per frame decodes on
//! worker threads the level images on the pyramid paths of the parameter samples it draws
//! (through the level-image cache), rebuilds those textures, uploads them and builds their
//! MIP chains on the GPU (a shell's cube map with every face and stored MIP level), and
//! draws every object with its block's texture transform (branch cuts, then the affine map),
//! layers added in linear space, objects depth-tested against each other; an object with
//! environment-map shells in its reflection term also gets that term (the shells composited
//! "over", times Fresnel from its f0, SPEC.md 9) per parameter sample, with the sample's
//! weight. A lens object (role `refractive`, its shells in the refraction term) is drawn by
//! hybrid rendering (thesis 6.4): per frame its vertex rays are traced through it on the
//! workers, its tessellation refined where they diverge, and both terms drawn from its
//! shells per parameter sample ([`crate::frame::hybrid`]).
//!
//! The stages, one file each: `options.rs` (settings, requests, costs), `objects.rs` (the
//! file's objects checked and uploaded at open), `plan.rs` (what a frame draws), `resident.rs`
//! (decoding through the cache, rebuilding and uploading textures), `lens.rs` (lens objects'
//! tessellation and draws), `draws.rs` (the frame's draws), `readout.rs` (submitting and
//! reading back); this file opens the player and runs a frame through them.

mod assemble;
mod budget;
mod depth;
mod draws;
mod lens;
mod lens_ahead;
mod objects;
mod options;
mod plan;
mod precision;
mod prefetch;
mod readout;
mod relight;
mod relit;
mod resident;

use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

use pis_compile::Filter;
use pis_format::PisReader;

pub use self::depth::check_steps as check_depth_steps;
use self::draws::{layer_draws, make_samplers, object_draws, reflection_draws, Samplers};
use self::lens::{lens_corners, lens_draws, lens_requests, LensSet};
use self::lens_ahead::LensAhead;
use self::objects::{check_texture_sizes, object_filters, prepare_objects, LensState, ObjectGpu};
pub use self::options::{FrameRequest, FrameStats, LensRays, PlayerOptions, Rebuild, RunOn};
use self::plan::{camera_record, Plan, TextureKey};
pub use self::precision::{PrecisionChoice, TexturePrecision};
use self::readout::{read_back, wait_for_gpu, Readbacks, Readout, Target};
pub use self::relight::Relight;
use self::relit::RelitTextures;
use self::resident::Textures;
use crate::blend::nearest_sample;
use crate::cache::LevelCache;
use crate::camera::ViewCamera;
use crate::decode::Decoder;
use crate::error::PlayError;
use crate::frame::{encode, offscreen_format, FrameDraws, FramePipelines, FrameTarget, Targets};
use crate::gpu::Gpu;
use crate::image::FloatImage;
use crate::lens_rays::LensRayPipeline;
use crate::mip::MipBuilder;
use crate::multisample::{check_samples, choose, Multisample};
pub use pis_compile::relight::{DirectionalLight, Lights};

/// An open `.pis` ready to draw frames.
pub struct Player {
    gpu: Arc<Gpu>,
    reader: Arc<PisReader>,
    options: PlayerOptions,
    /// The frame's textures on the GPU, the level-image cache and the decoding workers.
    textures: Textures,
    objects: Vec<ObjectGpu>,
    /// Per object, the texture filter its textures were solved for.
    filters: Vec<Filter>,
    pipes: FramePipelines,
    targets: Option<Targets>,
    /// The targets of the other sample count, kept while frames alternate between the
    /// multisampled frame and its single-sample twin ([`Player::render_centres`]).
    spare_targets: Option<Targets>,
    /// The multisampling of frames per target format (offscreen first).
    multisample: HashMap<wgpu::TextureFormat, Multisample>,
    readback: Readbacks,
    /// The display filter multisampled frames are resolved with, and whether the file
    /// records it.
    display: Option<(pis_format::DisplayFilter, bool)>,
    samplers: Samplers,
    /// The light directions the file's relightable layers span, and the lights shown.
    relight: Option<Relight>,
    /// Relightable layers' sums for the frame's lights.
    relit: RelitTextures,
    /// The frames the caller expects next ([`Player::prefetch`]), decoded ahead once the
    /// next frame's textures are resident.
    ahead: Vec<FrameRequest>,
    /// The formats the file's textures are held in, and why.
    precision: PrecisionChoice,
    /// Lens objects' tessellations being made for the frames expected next.
    lens_ahead: LensAhead,
}

impl Player {
    /// Opens `path` for random access (metadata read and checked; codestreams stay on disk
    /// until a frame needs them).
    pub fn open(gpu: Arc<Gpu>, path: &Path, options: PlayerOptions) -> Result<Player, PlayError> {
        if options.reduction == 0 || !options.reduction.is_power_of_two() {
            return Err(PlayError::Request(format!(
                "texture resolution reduction {} must be a power of two (1, 2, 4, …)",
                options.reduction
            )));
        }
        check_samples(options.msaa).map_err(PlayError::Request)?;
        depth::check_steps(options.depth_steps).map_err(PlayError::Request)?;
        let reader = Arc::new(PisReader::open(path)?);
        let precision =
            precision::choose(&gpu, reader.container().provenance.as_ref(), options.precision);
        let gpu = match precision.half() && !gpu.half_textures() {
            true => Arc::new(gpu.with_half_textures()),
            false => gpu,
        };
        check_texture_sizes(&gpu, &reader)?;
        budget::check_frame_memory(&gpu, reader.container(), &options)?;
        let mut objects = prepare_objects(&gpu, &reader, options.depth_steps)?;
        let filters = object_filters(reader.container());
        // The reader has checked the settings (rule 9002).
        let file_display =
            pis_format::DisplayFilter::of(reader.container().provenance.as_ref()).ok().flatten();
        let display =
            file_display.map(|f| (f, true)).or(options.display_filter.map(|f| (f, false)));
        let decoder = Decoder::new(options.workers)?;
        let cache =
            LevelCache::new(options.cache_budget_bytes, options.lifetime_a, options.lifetime_b);
        let mut pipes = FramePipelines::new(&gpu);
        let offscreen = offscreen_format(&gpu);
        let ms = choose(&gpu, options.msaa, offscreen);
        // Compiled now rather than in the first frame's time.
        pipes.id_pipeline(&gpu, ms.samples);
        pipes.layer_pipeline(&gpu, offscreen, ms.samples);
        for (o, record) in objects.iter().zip(&reader.container().objects) {
            match (o.shell_code(record), o.lens.is_some()) {
                (Some(code), false) => {
                    pipes.reflection_pipeline(&gpu, (offscreen, ms.samples, code))
                }
                (Some(code), true) => pipes.hybrid_pipeline(&gpu, (offscreen, ms.samples, code)),
                (None, _) => continue,
            };
        }
        let gpu_rays = options.lens_rays.on(gpu.info.device_type) == LensRays::Gpu;
        if gpu_rays && objects.iter().any(|o| o.lens.is_some()) {
            let rays = Arc::new(LensRayPipeline::new(&gpu));
            for lens in objects.iter_mut().filter_map(|o| o.lens.as_mut()) {
                lens.trace_on_gpu(gpu.clone(), rays.clone());
            }
        }
        let textures = Textures::new(
            &gpu,
            (decoder, cache),
            MipBuilder::new(&gpu),
            (options.rebuild, precision.level16),
        );
        // The reader has checked the settings (rule 9006).
        let c = reader.container();
        // Relightable where layers of coefficients span the recorded directions.
        let coefficients = c.objects.iter().flat_map(|o| &o.layers).any(|l| l.basis != 0);
        let relight = pis_format::relight::light_directions(c.provenance.as_ref(), &c.space)
            .ok()
            .flatten()
            .filter(|_| coefficients)
            .map(|file| Relight { file, lights: None });
        let relit = RelitTextures::new(&gpu);
        Ok(Player {
            relit,
            gpu,
            reader,
            options,
            textures,
            objects,
            filters,
            pipes,
            targets: None,
            spare_targets: None,
            multisample: HashMap::from([(offscreen, ms)]),
            readback: None,
            display,
            samplers: HashMap::new(),
            relight,
            ahead: Vec::new(),
            precision,
            lens_ahead: LensAhead::default(),
        })
    }

    /// The lights relightable layers are drawn under: `None`, the file's own light at the
    /// parameter point; else these directional lights and sky, by superposition (SPEC.md 9).
    /// Refused for a file without relightable layers.
    pub fn set_lights(&mut self, lights: Option<Lights>) -> Result<(), PlayError> {
        match &mut self.relight {
            Some(r) => {
                r.lights = lights;
                Ok(())
            }
            None if lights.is_none() => Ok(()),
            None => Err(PlayError::Request(
                "the file has no relightable layers (no light directions, SPEC.md 6.6)".into(),
            )),
        }
    }

    /// The file's light directions, where it has relightable layers (a file that samples
    /// its light over directions has none).
    pub fn light_directions(&self) -> Option<&pis_format::relight::LightDirections> {
        self.relight.as_ref().map(|r| &r.file)
    }

    /// The parameter space's dimensions.
    pub fn dimensions(&self) -> &[pis_format::Dimension] {
        &self.reader.container().space.dims
    }

    /// The objects' names, in file order (the indices `render_ids` reports).
    pub fn object_names(&self) -> Vec<String> {
        self.reader.container().objects.iter().map(|o| o.name.clone()).collect()
    }

    /// Per object of the file: whether it is translucent (a surface layer carries its
    /// opacity; SPEC.md 7.1), composited over what lies behind it.
    pub fn translucent_objects(&self) -> Vec<bool> {
        self.objects.iter().map(|o| o.translucent).collect()
    }

    /// The image size of the file's cameras (the ray-traced set's resolution).
    pub fn image_size(&self) -> (u32, u32) {
        let c = &self.reader.container().cameras;
        (c.width, c.height)
    }

    /// The options the player was opened with.
    pub fn options(&self) -> &PlayerOptions {
        &self.options
    }

    /// Where this player rebuilds textures from their level images (the options' choice,
    /// [`Rebuild::Auto`] resolved for the adapter).
    pub fn rebuild(&self) -> Rebuild {
        self.textures.rebuild_on()
    }

    /// Where this player traces lens objects' vertex rays (the options' choice,
    /// [`LensRays::Auto`] resolved for the adapter).
    pub fn lens_rays(&self) -> LensRays {
        self.options.lens_rays.on(self.gpu.info.device_type)
    }

    /// The formats this player holds the file's textures in, and why (the options' choice,
    /// [`TexturePrecision::Auto`] resolved by the file's measurement).
    pub fn texture_precision(&self) -> &PrecisionChoice {
        &self.precision
    }

    /// The open file (its container and read counters).
    pub fn reader(&self) -> &PisReader {
        &self.reader
    }

    /// The level-image cache.
    pub fn cache(&self) -> &LevelCache {
        &self.textures.cache
    }

    /// The format offscreen frames are drawn in before readback.
    pub fn offscreen_format(&self) -> wgpu::TextureFormat {
        offscreen_format(&self.gpu)
    }

    /// The multisampling of offscreen frames: samples per pixel asked for and drawn with.
    pub fn multisample(&self) -> &Multisample {
        &self.multisample[&offscreen_format(&self.gpu)]
    }

    /// The multisampling of frames drawn into targets of `format` ([`Player::render_to_view`]).
    /// With a display filter the samples are drawn in the offscreen format whatever the
    /// target's, and resolved by a shader: that format must multisample.
    pub fn multisample_for(&mut self, format: wgpu::TextureFormat) -> &Multisample {
        let (gpu, msaa) = (&self.gpu, self.options.msaa);
        let drawn = if self.display.is_some() { offscreen_format(gpu) } else { format };
        self.multisample.entry(format).or_insert_with(|| choose(gpu, msaa, drawn))
    }

    /// The display filter multisampled frames are resolved with (the ray-traced set's, RAYSET.md
    /// section 4), and whether the file records it (else it came from
    /// [`PlayerOptions::display_filter`]); `None`: each pixel's own samples are averaged.
    pub fn display_filter(&self) -> Option<(pis_format::DisplayFilter, bool)> {
        self.display
    }

    /// The nearest parameter sample of `point` (missing values count as the first sample,
    /// extra values are ignored).
    fn nearest(&self, point: &[f32]) -> Vec<u32> {
        let dims = self.dimensions();
        let mut full: Vec<f32> =
            dims.iter().map(|d| d.values.first().copied().unwrap_or(0.0)).collect();
        for (f, &v) in full.iter_mut().zip(point) {
            if v.is_finite() {
                *f = v;
            }
        }
        nearest_sample(dims, &full)
    }

    /// The world-from-camera transform and vertical field of view (radians) of the file's
    /// camera at `point` (its nearest view sample): what `CameraChoice::Sample` draws from.
    pub fn sample_pose(&self, point: &[f32]) -> (glam::Mat4, f32) {
        let cam = camera_record(&self.reader, &self.nearest(point));
        (crate::camera::mat4_from_rows(&cam.world_from_camera), cam.yfov)
    }

    /// The file's camera at `point` (its nearest view sample).
    pub fn sample_camera(&self, point: &[f32]) -> ViewCamera {
        ViewCamera::from_file(&camera_record(&self.reader, &self.nearest(point)))
    }

    /// Draws a frame offscreen; linear RGBA read back, colour premultiplied by coverage:
    /// alpha is the fraction of the pixel's samples objects cover (1 inside objects, 0
    /// where none is drawn, between on silhouettes of multisampled frames; with a display
    /// filter, the objects' filtered coverage of the pixel's 3×3 neighbourhood's samples).
    pub fn render_image(
        &mut self,
        req: &FrameRequest,
        size: (u32, u32),
    ) -> Result<(FloatImage, FrameStats), PlayError> {
        let (out, stats) = self.frame(req, size, Target::Offscreen { ids: false })?;
        let (img, _) = out.ok_or_else(|| PlayError::Readback("no offscreen frame".into()))?;
        Ok((img, stats))
    }

    /// Draws a frame offscreen ([`Player::render_image`]); also the object index per pixel,
    /// the nearest surface at the pixel's centre (`u32::MAX`: none).
    pub fn render_ids(
        &mut self,
        req: &FrameRequest,
        size: (u32, u32),
    ) -> Result<(FloatImage, Vec<u32>, FrameStats), PlayError> {
        let (out, stats) = self.frame(req, size, Target::Offscreen { ids: true })?;
        let (img, ids) = out.ok_or_else(|| PlayError::Readback("no offscreen frame".into()))?;
        Ok((img, ids.unwrap_or_default(), stats))
    }

    /// Draws a frame offscreen with one sample per pixel, whatever the player's
    /// multisampling: every pixel wholly the nearest surface at its centre, at that surface's
    /// radiance there, unmixed with its neighbours (what pis-compile's hardware model draws),
    /// and the object index per pixel as [`Player::render_ids`]. A resolved multisampled
    /// pixel mixes the objects around it; this is each object's own radiance, which an
    /// object's ray-traced surface layers (divided by its coverage) are compared with.
    pub fn render_centres(
        &mut self,
        req: &FrameRequest,
        size: (u32, u32),
    ) -> Result<(FloatImage, Vec<u32>, FrameStats), PlayError> {
        let (out, stats) = self.frame(req, size, Target::Centres)?;
        let (img, ids) = out.ok_or_else(|| PlayError::Readback("no offscreen frame".into()))?;
        Ok((img, ids.unwrap_or_default(), stats))
    }

    /// Draws a frame offscreen and waits for the GPU to finish it, without reading it back:
    /// what the frame costs where it is shown rather than copied to memory (timings).
    pub fn render_timed(
        &mut self,
        req: &FrameRequest,
        size: (u32, u32),
    ) -> Result<FrameStats, PlayError> {
        Ok(self.frame(req, size, Target::Timed)?.1)
    }

    /// Draws a frame into `view` (any colour format; linear radiance, so an `*Srgb` format
    /// does the sRGB encoding) of `size`, with [`Player::multisample_for`] the format's
    /// samples per pixel resolved into it.
    pub fn render_to_view(
        &mut self,
        req: &FrameRequest,
        view: &wgpu::TextureView,
        format: wgpu::TextureFormat,
        size: (u32, u32),
    ) -> Result<FrameStats, PlayError> {
        Ok(self.frame(req, size, Target::View(view, format))?.1)
    }

    /// Draws a frame: its plan; its textures decoded and uploaded while the lens objects are
    /// traced; its draws recorded into `target` and submitted (read back for an offscreen
    /// target); the frame ended.
    fn frame(
        &mut self,
        req: &FrameRequest,
        size: (u32, u32),
        target: Target,
    ) -> Result<(Option<Readout>, FrameStats), PlayError> {
        let t0 = Instant::now();
        let reads0 = self.reader.stats().codestreams;
        let mut stats = FrameStats::default();
        let relight = self.relight.as_ref();
        let plan = Plan::new(&self.reader, &self.objects, self.options.blend, req, size, relight)?;
        let corner_sets = self.textures_and_lenses(&plan, size, &mut stats)?;
        self.decode_ahead(size);
        let format = match target {
            Target::Offscreen { .. } | Target::Centres | Target::Timed => {
                offscreen_format(&self.gpu)
            }
            Target::View(_, f) => f,
        };
        let samples = match target {
            Target::Centres => 1,
            _ => self.multisample_for(format).samples,
        };
        self.make_targets(size, samples)?;
        let out = self.draw(&plan, &corner_sets, target, (format, size), &mut stats);
        self.relit.end_frame();
        let out = out?;
        self.textures.end_frame();
        stats.cache_bytes = self.textures.cache.bytes();
        stats.codestreams_read = self.reader.stats().codestreams - reads0;
        stats.frame_ms = t0.elapsed().as_secs_f64() * 1e3;
        Ok((out, stats))
    }

    /// Says which frames the caller expects to draw next (the motion's next points; none
    /// stops decoding ahead): after the next frame's textures are resident, and while it
    /// draws, the workers decode their level images into the cache (within its budget) and,
    /// where the workers rebuild textures, rebuild them, so those frames need not wait on
    /// decoding; their textures already on the GPU are kept. Work queued for textures no
    /// longer expected is dropped before it starts. Their lens objects' vertex rays are
    /// traced and tessellations refined ahead too, on threads of their own.
    pub fn prefetch(&mut self, ahead: &[FrameRequest]) {
        self.ahead = ahead.to_vec();
    }

    /// Level images dropped from decoding ahead so far because the prediction changed.
    pub fn prefetch_dropped(&self) -> u64 {
        self.textures.prefetch_dropped()
    }

    /// Lens objects' tessellations dropped from tracing ahead so far because the prediction
    /// changed.
    pub fn lens_ahead_dropped(&self) -> u64 {
        self.lens_ahead.dropped()
    }

    /// Starts decoding ahead the textures of the frames [`Player::prefetch`] expects. A
    /// request that cannot be planned, or a texture whose level images cannot be found, is
    /// not decoded ahead: the frame that asks for it reports why.
    fn decode_ahead(&mut self, size: (u32, u32)) {
        let relight = self.relight.as_ref();
        let (reader, objects, blend) = (&self.reader, &self.objects, self.options.blend);
        let plans: Vec<Plan> = self
            .ahead
            .iter()
            .filter_map(|req| Plan::new(reader, objects, blend, req, size, relight).ok())
            .collect();
        let keys: Vec<&TextureKey> = plans.iter().flat_map(|p| p.keys()).collect();
        self.textures.prefetch(&self.gpu, &self.reader, &keys, self.options.reduction);
        let tau_px = self.options.tau_px;
        let lens_of = |draw: usize| self.objects.get(draw).and_then(|o| o.lens.as_ref());
        let wanted = lens_requests(&plans, lens_of, size, tau_px);
        // An object is placed at a transform only for a tessellation not yet being made.
        self.lens_ahead.start(&wanted, |draw, world| {
            lens_of(draw).map(|s| (s.placed_at(world), s.settings(tau_px)))
        });
    }

    /// Makes the targets of `size` and `samples` current: those of the other sample count
    /// are kept aside while their size holds (frames alternating with their single-sample
    /// twins), any others made anew.
    fn make_targets(&mut self, size: (u32, u32), samples: u32) -> Result<(), PlayError> {
        let fits = |t: &Option<Targets>| t.as_ref().is_some_and(|t| t.size == size);
        if fits(&self.targets) && self.targets.as_ref().is_some_and(|t| t.samples == samples) {
            return Ok(());
        }
        if fits(&self.targets) {
            std::mem::swap(&mut self.targets, &mut self.spare_targets);
            if self.targets.as_ref().is_some_and(|t| t.size == size && t.samples == samples) {
                return Ok(());
            }
        } else {
            self.spare_targets = None;
            self.readback = None;
        }
        self.targets = Some(Targets::new(&self.gpu, &self.pipes, size, samples)?);
        Ok(())
    }

    /// Makes the textures `plan` draws resident while, on a thread of their own (the tracing
    /// on the workers), the lens objects' vertex rays, tessellations and vertex buffers are
    /// made: their states are taken out of the objects for the frame. Returns the lens
    /// objects' corner sets; on failure the frame is ended.
    fn textures_and_lenses(
        &mut self,
        plan: &Plan,
        size: (u32, u32),
        stats: &mut FrameStats,
    ) -> Result<Vec<LensSet>, PlayError> {
        let mut lens_states: Vec<(usize, LensState)> = Vec::new();
        for r in &plan.lenses {
            if !lens_states.iter().any(|(d, _)| *d == r.draw) {
                if let Some(state) = self.objects[r.draw].lens.take() {
                    lens_states.push((r.draw, state));
                }
            }
        }
        let tau_px = self.options.tau_px;
        let gpu_for_lenses = self.gpu.clone();
        let ahead = &mut self.lens_ahead;
        let (result, lens_work) = std::thread::scope(|scope| {
            let lens_thread = scope.spawn(|| {
                lens_corners(&gpu_for_lenses, (&mut lens_states, ahead), plan, size, tau_px)
            });
            let result = self.textures.make_resident(
                &self.gpu,
                &self.reader,
                self.options.reduction,
                &plan.keys(),
                stats,
            );
            (result, lens_thread.join())
        });
        for (draw, state) in lens_states {
            self.objects[draw].lens = Some(state);
        }
        let lens_work = match lens_work {
            Ok(w) => w,
            Err(_) => {
                self.textures.end_frame();
                return Err(PlayError::Request("the lens objects' tessellation failed".into()));
            }
        };
        if let Err(e) = result {
            self.textures.end_frame();
            return Err(e);
        }
        stats.lens_ms = lens_work.ms;
        stats.lens_rays = lens_work.rays;
        stats.lens_triangles = lens_work.triangles;
        stats.lens_traced_ahead = lens_work.traced_ahead;
        Ok(lens_work.sets)
    }

    /// Records the draws of `plan` (the lens objects' `corner_sets`) into `target`, of
    /// `format` and `size`, and submits them: an offscreen frame waited for (and read back
    /// unless timed).
    fn draw(
        &mut self,
        plan: &Plan,
        corner_sets: &[LensSet],
        target: Target,
        (format, size): (wgpu::TextureFormat, (u32, u32)),
        stats: &mut FrameStats,
    ) -> Result<Option<Readout>, PlayError> {
        let gpu = self.gpu.clone();
        let objects = object_draws(&self.objects, &plan.clips);
        make_samplers(&gpu, &mut self.samplers, &self.filters, &plan.surfaces);
        let mut encoder = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("frame") });
        let items = self.relit.items(&gpu, &self.textures, &plan.surfaces, &mut encoder);
        let (reader, textures) = (&self.reader, &self.textures);
        let layers = layer_draws(
            reader,
            (textures, &self.relit),
            &self.samplers,
            &self.filters,
            (&plan.surfaces, &items),
        )?;
        let reflections = reflection_draws(reader, (textures, &self.objects), plan)?;
        let lenses = lens_draws(reader, textures, plan, corner_sets)?;
        stats.lens_draws = lenses.len() as u64;
        stats.surface_draws = layers.len() as u64;
        stats.shell_draws = reflections.len() as u64;
        let targets = self.targets.as_mut().expect("targets made before the draws");
        let t_draw = Instant::now();
        let offscreen_view;
        let (view, want_ids) = match target {
            Target::View(v, _) => (v, false),
            Target::Offscreen { ids } => {
                offscreen_view = targets.colour.create_view(&Default::default());
                (&offscreen_view, ids)
            }
            Target::Centres => {
                offscreen_view = targets.colour.create_view(&Default::default());
                (&offscreen_view, true)
            }
            Target::Timed => {
                offscreen_view = targets.colour.create_view(&Default::default());
                (&offscreen_view, false)
            }
        };
        let display = self.display.map(|(f, _)| f);
        let frame = FrameDraws {
            objects: &objects,
            layers: &layers,
            reflections: &reflections,
            lenses: &lenses,
        };
        let to = FrameTarget { colour: view, format, object_ids: want_ids, display };
        encode(&gpu, &mut self.pipes, targets, to, frame, &mut encoder);
        gpu.queue.submit([encoder.finish()]);
        let ids = match target {
            Target::View(..) => return Ok(None),
            Target::Timed => None,
            Target::Offscreen { ids } => Some(ids),
            Target::Centres => Some(true),
        };
        wait_for_gpu(&gpu)?;
        stats.draw_ms = t_draw.elapsed().as_secs_f64() * 1e3;
        match ids {
            Some(ids) => {
                read_back(&gpu, targets, &mut self.readback, ids, (format, size), stats).map(Some)
            }
            None => Ok(None),
        }
    }
}
