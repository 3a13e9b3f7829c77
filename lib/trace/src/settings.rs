//! Render settings.

use crate::film::GaussianFilter;
use pis_scene::lens_tree::LensModel;
use serde::{Deserialize, Serialize};

/// What a render does, beyond the scene itself.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TraceSettings {
    /// Image size in pixels (width, height).
    pub resolution: (u32, u32),
    /// Camera samples per pixel.
    pub spp: u32,
    /// Reconstruction filter, importance-sampled by the camera samples.
    pub filter: GaussianFilter,
    /// Longest path (number of scattering events) before a path is cut.
    pub max_depth: u32,
    /// Indirect diffuse bounces after the first diffuse interaction (at least 1).
    pub diffuse_bounces: u32,
    /// Irradiance estimates (light samples and indirect rays) per surface cell at camera
    /// rays' first hits; the diffuse layer's noise falls with it.
    pub diffuse_samples: u32,
    /// Cell size (world units, object space) of the quantized surface point that seeds
    /// shading; `None` picks 1/4096 of the scene's bounding-box diagonal; `Some(0.0)` seeds
    /// per pixel sample instead (no coherence across the parameter space).
    pub coherence_cell: Option<f32>,
    /// Surface cells across the scene's bounding-box diagonal, where `coherence_cell` is
    /// `None` (`pis-trace --shading-cells N`); `None`: 4096 for images up to 160 pixels on
    /// their longer side, more in proportion beyond.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shading_cells: Option<u32>,
    /// Camera samples per pixel (the first ones) that write outgoing-ray records for
    /// refractive lens objects.
    pub records_per_pixel: u32,
    /// Most front-facing hits recorded along one continued outgoing ray.
    pub max_record_hits: u32,
    /// Stream of the camera samples' random numbers (their positions in the pixel and, with
    /// shading seeded per sample, their shading): renders that differ only in `seed` have
    /// independent noise, so two of them measure a render's own noise ([`ShadingSeed`]:
    /// seeded per cell, the surfaces' noise stays the same). 0 is the default stream.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub seed: u64,
    /// Adaptive sampling: a pixel stops taking camera samples once its estimated relative
    /// error ([`crate::adaptive::pixel_error`]) is below this; `spp` is then each pixel's
    /// most samples and `min_spp` its fewest. 0: every pixel takes `spp` samples.
    #[serde(default, skip_serializing_if = "is_zero_f32")]
    pub noise_threshold: f32,
    /// Adaptive sampling: the samples every pixel takes before its error is first estimated.
    #[serde(default, skip_serializing_if = "is_zero_u32")]
    pub min_spp: u32,
    /// Denoise the layers (OIDN): the render also keeps its two half buffers and the
    /// denoiser's guides, albedo and normal at the first non-specular hit.
    #[serde(default, skip_serializing_if = "is_false")]
    pub denoise: bool,
    /// How the paths through lens objects are followed and grouped into terms (the greedy
    /// two paths of thesis 6.2, or the ray tree).
    #[serde(default, skip_serializing_if = "LensModel::is_greedy")]
    pub lens_model: LensModel,
}

fn is_false(v: &bool) -> bool {
    !*v
}

fn is_zero(v: &u64) -> bool {
    *v == 0
}

fn is_zero_f32(v: &f32) -> bool {
    *v == 0.0
}

fn is_zero_u32(v: &u32) -> bool {
    *v == 0
}

/// What seeds the shading's random numbers ([`TraceSettings::coherence_cell`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShadingSeed {
    /// The quantized surface point: a surface's noise is the same in every image of the
    /// space, so textures solved from the images agree across it; more camera samples
    /// average more cells, but each cell's estimate stays what it is.
    Cell,
    /// Each camera sample: the noise falls as 1/spp (a gold standard).
    Sample,
}

impl ShadingSeed {
    /// Every seeding, in the order the tools list them.
    pub const ALL: [ShadingSeed; 2] = [ShadingSeed::Cell, ShadingSeed::Sample];

    /// The seeding the tools spell `name` ([`ShadingSeed::name`]).
    pub fn from_name(name: &str) -> Option<ShadingSeed> {
        ShadingSeed::ALL.into_iter().find(|s| s.name() == name)
    }

    /// `cell` or `sample`, as the tools spell it.
    pub fn name(self) -> &'static str {
        match self {
            ShadingSeed::Cell => "cell",
            ShadingSeed::Sample => "sample",
        }
    }
}

/// When a trace denoises its layers (`pis-trace --denoise`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DenoiseMode {
    /// Where Open Image Denoise is found; else the run warns once and writes raw layers.
    Auto,
    /// Always: a run without the library is refused before anything is traced.
    On,
    /// Never: raw layers only.
    Off,
}

impl DenoiseMode {
    /// Every mode, in the order the tools list them.
    pub const ALL: [DenoiseMode; 3] = [DenoiseMode::Auto, DenoiseMode::On, DenoiseMode::Off];

    /// `auto`, `on` or `off`, as the tools spell it.
    pub fn name(self) -> &'static str {
        match self {
            DenoiseMode::Auto => "auto",
            DenoiseMode::On => "on",
            DenoiseMode::Off => "off",
        }
    }

    /// The settings denoising as this mode says: `On` where the library cannot be loaded is
    /// an error naming why (`Auto` leaves that to the run, which warns and writes raw layers).
    pub fn apply(self, mut settings: TraceSettings) -> Result<TraceSettings, crate::TraceError> {
        settings.denoise = self != DenoiseMode::Off;
        if self == DenoiseMode::On {
            crate::oidn::shared()
                .map_err(|e| crate::TraceError::Denoise(format!("--denoise on: {e}")))?;
        }
        Ok(settings)
    }
}

impl TraceSettings {
    /// What seeds the shading: a cell size of 0 seeds per camera sample.
    pub fn shading_seed(&self) -> ShadingSeed {
        if self.coherence_cell == Some(0.0) {
            ShadingSeed::Sample
        } else {
            ShadingSeed::Cell
        }
    }

    /// The same settings with shading seeded by `seed` (`Cell`: the default cell size).
    pub fn with_shading_seed(mut self, seed: ShadingSeed) -> TraceSettings {
        self.coherence_cell = match seed {
            ShadingSeed::Cell => None,
            ShadingSeed::Sample => Some(0.0),
        };
        self
    }

    /// The same settings with surface cells of 1/`cells` of the scene's diagonal (`None`: by
    /// the image's size, [`TraceSettings::shading_cells`]).
    pub fn with_shading_cells(mut self, cells: Option<u32>) -> TraceSettings {
        self.shading_cells = cells;
        self
    }

    /// The same settings drawing their camera samples from stream `seed`.
    pub fn with_seed(mut self, seed: u64) -> TraceSettings {
        self.seed = seed;
        self
    }

    /// The same settings sampling adaptively: each pixel takes `min_spp` to `spp` samples
    /// and stops once its estimated error is below `threshold` (0: fixed `spp`).
    pub fn with_adaptive(mut self, threshold: f32, min_spp: u32) -> TraceSettings {
        self.noise_threshold = threshold.max(0.0);
        self.min_spp = min_spp;
        self
    }

    /// The same settings with lens objects followed by `model`.
    pub fn with_lens_model(mut self, model: LensModel) -> TraceSettings {
        self.lens_model = model;
        self
    }

    /// Whether pixels sample adaptively.
    pub fn adaptive(&self) -> bool {
        self.noise_threshold > 0.0
    }

    /// Defaults for a render at `resolution` with `spp` samples per pixel.
    pub fn new(resolution: (u32, u32), spp: u32) -> TraceSettings {
        TraceSettings {
            resolution,
            spp,
            filter: GaussianFilter::default(),
            max_depth: 8,
            diffuse_bounces: 1,
            diffuse_samples: 4,
            coherence_cell: None,
            shading_cells: None,
            records_per_pixel: 2,
            max_record_hits: 4,
            seed: 0,
            noise_threshold: 0.0,
            min_spp: 0,
            denoise: false,
            lens_model: LensModel::Greedy,
        }
    }
}
