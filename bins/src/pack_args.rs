//! The options of a pack, shared by `pis-pack` and by `pis-play` given a scene.toml: what
//! to aim at (ratio or PSNR), how to code, infer and place textures, and how to trace a
//! scene.toml first.

use std::path::PathBuf;

use clap::Args;
use pis_codec::CodecId;
use pis_compile::{Filter, MAX_ANISOTROPY};
use pis_trace::settings::DenoiseMode;

use crate::cli::{one_of, Exit, Failure};
use pis_pack::{
    filter_needs_probe, Allocation, BlockSize, DistantShell, LayerMode, LensShell, MatrixSource,
    MaxMse, PackRequest, PackSettings, PlacementMode, PyramidMode, RepresentationMode, Stagger,
};

/// pis-pack's settings on the command line.
#[derive(Args, Debug, Clone)]
pub struct PackOptions {
    /// Target played quality (the default, 1 dB): the fewest level-image bytes whose
    /// predicted played PSNR (the decoded textures drawn through the render matrices,
    /// against the traced images) is within DB of the same file with its textures as solved.
    #[arg(long, value_name = "DB", conflicts_with_all = ["ratio", "psnr"])]
    pub within: Option<f64>,
    /// Target compression ratio instead: level-image bytes = raw image bytes / R (the
    /// thesis's figures are at 384); geometry and tables come on top (the report gives both
    /// ratios).
    #[arg(long, conflicts_with = "psnr")]
    pub ratio: Option<f64>,
    /// Target PSNR in dB instead: the coding PSNR of the stored (gamma-compensated)
    /// textures, screen-area weighted; the predicted screen PSNR is also bounded by inference.
    #[arg(long)]
    pub psnr: Option<f64>,
    /// Level-image codec.
    #[arg(long, default_value = "wavelet", value_parser = one_of(&CodecId::ALL, CodecId::name))]
    pub codec: CodecId,
    /// Samples per parameter block: one size for every dimension (8) or one per dimension (8x8).
    #[arg(long, default_value = "8", value_parser = parse_block)]
    pub block: BlockSizes,
    /// Texture filtering the player uses: auto (trilinear, or bilinear for an object whose
    /// views between those its textures are solved from it predicts at least 0.5 dB better:
    /// faces seen at a grazing angle), or one for every object: trilinear, bilinear, or
    /// anisotropic (trilinear lookups along the footprint's major axis, as the adapter's
    /// sampler takes them; needs `--matrix probe`, since no specification pins the footprint
    /// down).
    #[arg(long, default_value = "auto", value_parser = one_of(&FILTERS, FilterFlag::name))]
    pub filter: FilterFlag,
    /// Anisotropic filtering: the sampler's anisotropy clamp, 1 to 16 (the most lookups per
    /// pixel; an adapter may ignore it: Mesa 22.3's lavapipe filters the same for any clamp
    /// above 1). Default 16; only with `--filter anisotropic`.
    #[arg(long, value_parser = clap::value_parser!(u8).range(1..=MAX_ANISOTROPY as i64))]
    pub anisotropy: Option<u8>,
    /// Render matrix source: `model` (pis-compile's hardware model, computed in software) or
    /// `probe` (measured through the player's wgpu pipeline on this machine's GPU adapter with
    /// texel-identifier renderings, thesis 3.4.3: slower, but exact for whatever the adapter
    /// does; needs an adapter, Mesa's lavapipe without a GPU).
    #[arg(long, default_value = "model", value_parser = one_of(&MATRIX_SOURCES, MatrixSource::name))]
    pub matrix: MatrixSource,
    /// Largest used texture side.
    #[arg(long, default_value_t = pis_pack::DEFAULT_MAX_TEXTURE)]
    pub max_texture: u32,
    /// Texel budget: at most K level-0 texels per pixel an object covers in its most covered
    /// view; an object's texture over budget is reduced uniformly (thesis 3.2's per-object
    /// reduction factor, chosen automatically). `auto`: 1, raised to 2 or 4 for an object
    /// whose views between those its textures are solved from it predicts at least 0.5 dB
    /// and 3 standard errors better each step (fine shading detail on a dense mesh). K:
    /// that budget for every object. `none`: the optimal resolution, capped by
    /// --max-texture only.
    #[arg(long, value_name = "auto|K|none", default_value = "auto", value_parser = parse_budget)]
    pub texels_per_pixel: Budget,
    /// Display gamma of the compensation (1: linear storage; lossless and raw packs always use 1).
    #[arg(long, default_value_t = pis_pack::DEFAULT_GAMMA)]
    pub gamma: f32,
    /// Tracing a scene.toml: image size WIDTHxHEIGHT.
    #[arg(long, value_parser = parse_resolution)]
    pub resolution: Option<(u32, u32)>,
    /// Tracing a scene.toml: camera samples per pixel.
    #[arg(long)]
    pub spp: Option<u32>,
    /// Tracing a scene.toml: denoise its layers with Open Image Denoise, as pis-trace does.
    /// `auto`: when the library is found (`pip install pyoidn`), else a warning and raw
    /// layers only. `on`: an error without it. `off`: raw layers only.
    #[arg(long, default_value = "auto", value_parser = one_of(&DenoiseMode::ALL, DenoiseMode::name))]
    pub denoise: DenoiseMode,
    /// Tracing a scene.toml: a `[preset.NAME]` of the scene (e.g. `paper`), applied before
    /// --resolution and --spp; with a set, the preset its scene is read with.
    #[arg(long, value_name = "NAME")]
    pub preset: Option<String>,
    /// Pyramid levels per block: `adaptive` (greedy search, thesis 4.3) or `full` (every
    /// dimension halved per level down to one sample).
    #[arg(long, default_value = "adaptive", value_parser = one_of(&PyramidMode::ALL, PyramidMode::name))]
    pub pyramid: PyramidMode,
    /// Lighting layers: `separate` (view-independent diffuse + view-dependent specular) or
    /// `combined` (one view-dependent layer of diffuse + specular per parameter sample).
    #[arg(long, default_value = "separate", value_parser = one_of(&LayerMode::ALL, LayerMode::name))]
    pub layers: LayerMode,
    /// Reflective and refractive objects: `auto` (the default: per object, surface textures,
    /// or environment-map shells where they do better; the alternative is solved only for an
    /// object whose textures solved 6 dB or more below the other objects (or the only one),
    /// kept for weighing only if it solves within 1 dB of the textures, then weighed by encoding
    /// the whole file each way: at the default target and under `--psnr` the one that meets
    /// the goal with fewer bytes, under a ratio the one whose file predicts a PSNR at least
    /// 0.05 dB higher; the report says for each object what it chose and why), `texture`
    /// (parameterized surface textures), `pem` (reflective objects as layered environment
    /// maps, thesis ch. 5: a local and a distant shell per parameter sample; refractive objects by hybrid rendering, thesis ch. 6: shells from
    /// the set's ray records, looked up through the lens object's vertex rays traced each
    /// frame), `pem-infinity` (reflective objects as one environment map at infinity per
    /// sample, inferred: the single-shell baseline) or `static-env` (reflective objects as one
    /// environment map at infinity per sample, ray-traced from the object's centre without
    /// the object: the static environment map of thesis 5.1); `pem-infinity` stores
    /// refractive objects by hybrid rendering with a single shell (the single-shell
    /// baseline of thesis 6.5), `static-env` as `pem` does.
    #[arg(long, default_value = "auto", value_parser = one_of(&REPRESENTATIONS, RepresentationMode::name))]
    pub representation: RepresentationMode,
    /// Conjugate-gradient iteration cap per colour channel of every texture solve
    /// (default: the solver's own).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    pub max_iterations: Option<u32>,
    /// What the storage allocation minimizes: `screen` (texture error weighted per texel by
    /// the screen pixels it reaches through the render matrices) or `texture` (texture MSE
    /// weighted by each object's screen area).
    #[arg(long, default_value = "screen", value_parser = one_of(&Allocation::ALL, Allocation::name))]
    pub allocation: Allocation,
    /// The allocation's max-MSE constraint (thesis 4.8): no object's coding MSE above ALPHA
    /// times the mean object MSE, storage taken from the objects with low MSE. `auto`: the
    /// constraint at the thesis's 1.25 and the free allocation are both encoded, and the one
    /// whose decoded textures predict the higher PSNR is kept (the report says which);
    /// `off`: the free equal-slope allocation; a number above 1: the constraint at that α.
    #[arg(long, value_name = "auto|off|ALPHA", default_value = "auto")]
    pub max_mse_ratio: MaxMse,
    /// Which views each texture placement (branch cuts, affine map, used size; thesis 3.2)
    /// is optimized over: `block` (per object per parameter block, the views of the
    /// block's samples) or `object` (one placement per object over every view of the set).
    #[arg(long, default_value = "block", value_parser = one_of(&PLACEMENTS, PlacementMode::name))]
    pub placement: PlacementMode,
    /// Which dimensions the objects' block origins are staggered along (thesis 4.7), so that
    /// crossing a block boundary decodes one object's block at a time: `auto`, those with
    /// more samples than a block (one that fits in a block has no boundary, and an offset
    /// would only split each object's samples in two); `always`, every dimension.
    #[arg(long, value_name = "auto|always", default_value = "auto", value_parser = one_of(&Stagger::ALL, Stagger::name))]
    pub stagger: Stagger,
    /// Layered environment maps, one shell at infinity and lens objects' shells: lookups per
    /// pixel side, 1 to 3. Each pixel averages k × k lookups of a shell at sub-pixel offsets
    /// (SPEC.md 8.2), as a traced pixel averages its samples where the reflected or refracted
    /// direction turns fast across it; the shells are solved through the same lookups and
    /// the player draws them so.
    #[arg(long, value_name = "1|2|3", default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=pis_format::MAX_SHELL_LOOKUPS as i64))]
    pub shell_lookups: u32,
    /// Weigh each pixel's rows in the view-dependent layers' solves by the set's confidence in
    /// it (thesis 6.3.3): a set traced with adaptive sampling (pis-trace --noise-threshold)
    /// records the error each pixel stopped at, and a pixel that stopped above the threshold
    /// counts threshold ÷ error. A layer read from its denoised twin, and a set without that
    /// record, are solved as with `off`.
    #[arg(long, default_value = "off", value_name = "on|off", action = clap::ArgAction::Set, value_parser = parse_on_off)]
    pub confidence: bool,
    /// Layered environment maps: a reflective object's distant shell. `fitted`: a box on the
    /// surface the object rests on or a sphere, whichever is nearer the traced distant layer
    /// (thesis 5.4); `auto`: that, then a depth shell (SPEC.md 8.5: its radius in each
    /// direction the distance to the other objects, one map over the views) where it
    /// predicts a view held out between two samples better, at some cost at the sampled
    /// views; `box`, `sphere` or `depth`: that shell; `depth-per-sample`: a depth shell with
    /// one map per parameter sample, each solved from its own view (the single-view inference
    /// the shared map is measured against).
    #[arg(long, default_value = "fitted", value_parser = one_of(&DistantShell::ALL, DistantShell::name))]
    pub distant_shell: DistantShell,
    /// Hybrid rendering: a lens object's shells. `layered`: the layers clustered from the
    /// ray records' hit distances, a sphere, cylinder or box fitted to each (thesis 6.3.2);
    /// `depth`: one depth shell about the object's centroid (SPEC.md 8.5), each exit ray
    /// marched to the surface of the other objects it meets, its one map solved over the
    /// views; `depth-per-sample`: that shell with one map per parameter sample, each solved
    /// from its own view.
    #[arg(long, default_value = "layered", value_parser = one_of(&LensShell::ALL, LensShell::name))]
    pub lens_shell: LensShell,
    /// Where the set turns a light over directions (scene.toml `light_direction`): `on`
    /// stores each surface layer as spherical-harmonic coefficients over them (Wong et al.:
    /// relit under any directional lights, the band chosen per layer by held-out light
    /// directions); `off` samples the light as any dimension.
    #[arg(long, default_value = "on", value_name = "on|off", action = clap::ArgAction::Set, value_parser = parse_on_off)]
    pub relight: bool,
    /// Also store the lossless master: every solved texture, before gamma compensation and
    /// coding, losslessly coded in MSTR chunks a player never reads. pis-reencode codes
    /// again from it (as a direct pack at the new settings would) instead of from the decoded
    /// textures. The ratio does not count it; the report gives its bytes.
    #[arg(long)]
    pub keep_master: bool,
    /// Memory budget in GB (default: the memory available). A set whose pack would take
    /// more (about three times its float images) is streamed: its images, render matrices
    /// and gold standard go to a scratch file beside the output, read back an object and
    /// point at a time, and removed at the end. The file written is the same byte for byte.
    #[arg(long, value_name = "GB", value_parser = pis_eval::budget::parse_memory)]
    pub memory: Option<f64>,
}

impl PackOptions {
    /// The request that packs `input` into `output` with these options.
    pub fn request(
        &self,
        input: PathBuf,
        scene: Option<PathBuf>,
        output: PathBuf,
    ) -> Result<PackRequest, Failure> {
        let filter = match (self.filter.0.unwrap_or(Filter::Trilinear), self.anisotropy) {
            (Filter::Anisotropic(_), n) => Filter::Anisotropic(n.unwrap_or(MAX_ANISOTROPY)),
            (f, None) => f,
            (_, Some(_)) => {
                return Err(Failure::new(
                    Exit::Usage,
                    anyhow::anyhow!(
                        "--anisotropy applies to --filter anisotropic, not {}",
                        self.filter.name()
                    ),
                ))
            }
        };
        if let Some(why) = filter_needs_probe(filter, self.matrix) {
            return Err(Failure::new(Exit::Usage, anyhow::anyhow!(why)));
        }
        let settings = PackSettings {
            target: pis_pack::Target::from_flags(self.ratio, self.psnr, self.within)
                .map_err(|e| Failure::new(Exit::Usage, anyhow::anyhow!(e)))?,
            codec: self.codec,
            block: BlockSize::from_sizes(self.block.0.clone()),
            filter,
            filter_choice: self.filter.0.is_none(),
            matrix: self.matrix,
            max_texture: self.max_texture,
            texels_per_pixel: self.texels_per_pixel.0,
            density_choice: self.texels_per_pixel.1,
            gamma: if self.codec.is_lossy() { self.gamma } else { 1.0 },
            pyramid: self.pyramid,
            layers: self.layers,
            representation: self.representation,
            allocation: self.allocation,
            max_mse: self.max_mse_ratio,
            placement: self.placement,
            stagger: self.stagger,
            shell_lookups: self.shell_lookups,
            confidence: self.confidence,
            distant_shell: self.distant_shell,
            lens_shell: self.lens_shell,
            relight: self.relight,
            max_iterations: self.max_iterations,
            keep_master: self.keep_master,
            preset: self.preset.clone(),
            resolution: self.resolution,
            spp: self.spp,
            denoise: self.denoise,
            memory: self.memory,
        };
        let mut req = PackRequest::new(input, output, settings);
        req.scene = scene;
        Ok(req)
    }

    /// The options as written, for telling packs apart (`Debug` of every field but the
    /// memory budget, which changes how the pack runs, not the file).
    pub fn fingerprint(&self) -> String {
        let mut o = self.clone();
        o.memory = None;
        format!("{o:?}")
    }

    /// pis-pack's defaults.
    pub fn defaults() -> Self {
        Self::try_parse(&[]).expect("the defaults parse")
    }

    /// The options `args` (flags only) give.
    fn try_parse(args: &[&str]) -> Result<Self, clap::Error> {
        #[derive(clap::Parser)]
        struct Only {
            #[command(flatten)]
            pack: PackOptions,
        }
        let args = std::iter::once("pis-pack").chain(args.iter().copied());
        <Only as clap::Parser>::try_parse_from(args).map(|o| o.pack)
    }
}

/// `--filter`: `auto` (`None`: trilinear, bilinear per object where held-out views say so) or
/// one filter for every object.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FilterFlag(pub Option<Filter>);

impl FilterFlag {
    fn name(self) -> &'static str {
        self.0.map_or("auto", Filter::name)
    }
}

/// The values of `--filter`, by [`FilterFlag::name`] (the anisotropy clamp comes from
/// `--anisotropy`).
const FILTERS: [FilterFlag; 4] = [
    FilterFlag(None),
    FilterFlag(Some(Filter::Trilinear)),
    FilterFlag(Some(Filter::Bilinear)),
    FilterFlag(Some(Filter::Anisotropic(MAX_ANISOTROPY))),
];

/// The values of `--matrix`, by [`MatrixSource::name`].
const MATRIX_SOURCES: [MatrixSource; 2] = [MatrixSource::Model, MatrixSource::Probe];

/// The values of `--representation`, by [`RepresentationMode::name`].
const REPRESENTATIONS: [RepresentationMode; 5] = [
    RepresentationMode::Texture,
    RepresentationMode::Pem,
    RepresentationMode::PemInfinity,
    RepresentationMode::StaticEnv,
    RepresentationMode::Auto,
];

/// The values of `--placement`, by [`PlacementMode::name`].
const PLACEMENTS: [PlacementMode; 2] = [PlacementMode::Block, PlacementMode::Object];

/// `--texels-per-pixel`: the budget (`None`: none) and whether it is raised per object
/// (`auto`).
#[derive(Clone, Copy, Debug)]
pub struct Budget(pub Option<f64>, pub bool);

fn parse_budget(s: &str) -> Result<Budget, String> {
    match s {
        "none" => return Ok(Budget(None, false)),
        "auto" => return Ok(Budget(pis_pack::DEFAULT_TEXELS_PER_PIXEL, true)),
        _ => {}
    }
    s.parse::<f64>()
        .ok()
        .filter(|k| k.is_finite() && *k > 0.0)
        .map(|k| Budget(Some(k), false))
        .ok_or_else(|| format!("--texels-per-pixel {s:?}: expected `auto`, a number > 0 or `none`"))
}

/// `--block`: one size, or one per dimension.
#[derive(Clone, Debug)]
pub struct BlockSizes(pub Vec<u32>);

fn parse_block(s: &str) -> Result<BlockSizes, String> {
    pis_pack::parse_sizes(s).map(BlockSizes)
}

pub fn parse_resolution(s: &str) -> Result<(u32, u32), String> {
    match pis_pack::parse_sizes(s)?.as_slice() {
        [w, h] => Ok((*w, *h)),
        _ => Err(format!("expected WIDTHxHEIGHT, got {s:?}")),
    }
}

/// `on` or `off`.
fn parse_on_off(s: &str) -> Result<bool, String> {
    match s {
        "on" => Ok(true),
        "off" => Ok(false),
        _ => Err(format!("expected on or off, got {s:?}")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The command line's defaults are the library's: one truth for pis-pack's defaults.
    #[test]
    fn the_flags_defaults_are_pack_settings_new() {
        let req = PackOptions::defaults().request("set".into(), None, "out.pis".into()).unwrap();
        assert_eq!(req.settings, PackSettings::new());
    }

    /// Every mode parses by the name the library gives it, and a wrong name is refused.
    #[test]
    fn every_mode_parses_by_its_name() {
        for mode in REPRESENTATIONS {
            let o = PackOptions::try_parse(&["--representation", mode.name()]).unwrap();
            assert_eq!(o.representation, mode);
        }
        for codec in CodecId::ALL {
            assert_eq!(PackOptions::try_parse(&["--codec", codec.name()]).unwrap().codec, codec);
        }
        for mode in PyramidMode::ALL {
            assert_eq!(PackOptions::try_parse(&["--pyramid", mode.name()]).unwrap().pyramid, mode);
        }
        for mode in LayerMode::ALL {
            assert_eq!(PackOptions::try_parse(&["--layers", mode.name()]).unwrap().layers, mode);
        }
        for a in Allocation::ALL {
            assert_eq!(PackOptions::try_parse(&["--allocation", a.name()]).unwrap().allocation, a);
        }
        for (flag, value) in [
            ("--representation", "static"),
            ("--codec", "jpeg"),
            ("--pyramid", "dyadic"),
            ("--layers", "split"),
            ("--allocation", "pixel"),
        ] {
            let err = PackOptions::try_parse(&[flag, value]).unwrap_err().to_string();
            assert!(err.contains("possible values"), "{err}");
        }
    }
}
