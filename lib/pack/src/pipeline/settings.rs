//! How to pack: [`PackSettings`], every choice of the compile pipeline with its default,
//! and the presets (`const fn`s, in the manner of obvhs's build parameters).

use pis_codec::CodecId;
use pis_compile::Filter;

use super::MatrixSource;

/// Samples per parameter block along the dimensions (thesis 4.7).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum BlockSize {
    /// The same size along every dimension.
    Uniform(u32),
    /// One size per dimension of the parameter space.
    PerDimension(Vec<u32>),
}

impl BlockSize {
    /// The sizes as `--block` writes them: one value for every dimension, or one each.
    pub fn as_slice(&self) -> &[u32] {
        match self {
            BlockSize::Uniform(n) => std::slice::from_ref(n),
            BlockSize::PerDimension(v) => v,
        }
    }

    /// One value: the same for every dimension; several: one per dimension.
    pub fn from_sizes(sizes: Vec<u32>) -> Self {
        match sizes.as_slice() {
            [n] => BlockSize::Uniform(*n),
            _ => BlockSize::PerDimension(sizes),
        }
    }
}

/// What a pack aims at: a played quality (the default), a compression ratio or a PSNR of the
/// coded textures, one of them. [`super::plan::Plan`] turns it into the storage
/// allocation's aim (`plan::Aim`: a ratio is a byte budget of level images, a played
/// quality a search over allocations).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Target {
    /// The fewest level-image bytes whose predicted played PSNR (the decoded textures drawn
    /// through the render matrices against the traced images) is within this many dB of
    /// the same file's textures as solved: what the representations can play, less what
    /// coding may cost. The default, [`DEFAULT_WITHIN_DB`].
    Within(f64),
    /// Level-image bytes = raw image bytes / ratio (thesis 4.8; geometry and tables come on
    /// top).
    Ratio(f64),
    /// The fewest bytes that reach this PSNR (dB) of the coded textures.
    Psnr(f64),
}

impl Target {
    /// pis-pack's default: within [`DEFAULT_WITHIN_DB`] of the textures as solved.
    pub const DEFAULT: Target = Target::Within(DEFAULT_WITHIN_DB);

    /// `--ratio`, `--psnr` or `--within` as given: none is the default quality, two an
    /// error, and the one given must [`Target::check`].
    pub fn from_flags(
        ratio: Option<f64>,
        psnr: Option<f64>,
        within: Option<f64>,
    ) -> Result<Target, String> {
        let target = match (Target::given(ratio, psnr)?, within) {
            (Some(_), Some(_)) => {
                return Err("give one of --ratio, --psnr and --within".to_string())
            }
            (Some(t), None) => t,
            (None, Some(db)) => Target::Within(db),
            (None, None) => Target::DEFAULT,
        };
        target.check().map(|()| target)
    }

    /// `--ratio` or `--psnr` as given, checked ([`Target::check`]): `None` where neither
    /// is (each tool has its own default), an error where both are.
    pub fn given(ratio: Option<f64>, psnr: Option<f64>) -> Result<Option<Target>, String> {
        let target = match (ratio, psnr) {
            (Some(_), Some(_)) => return Err("give --ratio or --psnr, not both".to_string()),
            (Some(r), None) => Target::Ratio(r),
            (None, Some(db)) => Target::Psnr(db),
            (None, None) => return Ok(None),
        };
        target.check().map(|()| Some(target))
    }

    /// A ratio of at least 1, a positive number of dB; all finite.
    pub fn check(self) -> Result<(), String> {
        match self {
            Target::Ratio(r) if !(r.is_finite() && r >= 1.0) => {
                Err(format!("--ratio must be at least 1, got {r}"))
            }
            Target::Psnr(db) if !(db.is_finite() && db > 0.0) => {
                Err(format!("--psnr must be a positive number of dB, got {db}"))
            }
            Target::Within(db) if !(db.is_finite() && db > 0.0) => {
                Err(format!("--within must be a positive number of dB, got {db}"))
            }
            _ => Ok(()),
        }
    }

    /// The one allocation a ratio or a coding PSNR asks for over raw images of `raw` bytes;
    /// `None` for a played quality, which needs the traced set to predict against.
    pub fn fixed_allocation(self, raw: u64) -> Option<pis_codec::allocate::Target> {
        use pis_codec::allocate::Target as A;
        match self {
            Target::Psnr(db) => Some(A::Psnr { db, peak: 1.0 }),
            Target::Ratio(r) => Some(A::Bytes((raw as f64 / r) as usize)),
            Target::Within(_) => None,
        }
    }

    /// The ratio aimed at, if any.
    pub const fn ratio(self) -> Option<f64> {
        match self {
            Target::Ratio(r) => Some(r),
            _ => None,
        }
    }

    /// The PSNR (dB) of the coded textures aimed at, if any.
    pub const fn psnr(self) -> Option<f64> {
        match self {
            Target::Psnr(db) => Some(db),
            _ => None,
        }
    }

    /// The played quality aimed at: dB from the textures as solved, if any.
    pub const fn within(self) -> Option<f64> {
        match self {
            Target::Within(db) => Some(db),
            _ => None,
        }
    }

    /// As the file's provenance records it: `within D dB`, `ratio R` or `psnr P dB`.
    pub fn describe(self) -> String {
        match self {
            Target::Within(db) => format!("within {db} dB"),
            Target::Ratio(r) => format!("ratio {r}"),
            Target::Psnr(db) => format!("psnr {db} dB"),
        }
    }
}

/// Every setting of a pack. [`PackSettings::new`] gives pis-pack's defaults; the presets
/// and the `with_*` methods change them, `const` where they can be.
#[derive(Clone, Debug, PartialEq)]
pub struct PackSettings {
    /// What the pack aims at: a played quality (default: within [`DEFAULT_WITHIN_DB`] of
    /// the textures as solved), a compression ratio or a PSNR of the coded textures.
    pub target: Target,
    /// The level-image codec: wavelet (default), dct, or lossless.
    pub codec: CodecId,
    /// Samples per parameter block (default 8 along every dimension).
    pub block: BlockSize,
    /// The player's texture filter; `Anisotropic` needs `matrix: Probe`.
    pub filter: Filter,
    /// With a trilinear `filter`, choose per object between trilinear and bilinear lookups
    /// by the views of the set the object's textures were not solved from
    /// ([`super::filter_choice`]); the file records an object's own filter (SPEC.md 6.6).
    pub filter_choice: bool,
    /// With a texel budget, raise it per object where the views of the set the object's
    /// textures were not solved from say more texels predict them better
    /// ([`super::density_choice`]).
    pub density_choice: bool,
    /// Where the render matrices come from: the hardware model (default) or probe mode,
    /// measured through the player's pipeline on a GPU adapter (thesis 3.4.3).
    pub matrix: MatrixSource,
    /// Largest used texture side (a GPU limit, not the resolution control).
    pub max_texture: u32,
    /// Texel budget: at most this many level-0 texels per pixel an object covers (its most
    /// covered view); `None`: the optimal resolution of thesis 3.2, capped by
    /// `max_texture` only.
    pub texels_per_pixel: Option<f64>,
    /// Display gamma g of the compensation γ(L) = L^(1/g) (thesis 4.6); lossless packs
    /// use 1.
    pub gamma: f32,
    /// Pyramid levels per block: the adaptive search (thesis 4.3) or the full dyadic
    /// sequence.
    pub pyramid: PyramidMode,
    /// Lighting layers: separate diffuse and specular layers, or one combined
    /// view-dependent layer per parameter sample.
    pub layers: LayerMode,
    /// What the storage allocation weighs: screen error (default) or texture error.
    pub allocation: Allocation,
    /// The allocation's max-MSE constraint (thesis 4.8).
    pub max_mse: MaxMse,
    /// How reflective objects are stored: parameterized surface textures (default) or
    /// layered environment maps (thesis ch. 5).
    pub representation: RepresentationMode,
    /// Texture placements per parameter block (default) or per object.
    pub placement: PlacementMode,
    /// Which dimensions the objects' block origins are staggered along (thesis 4.7).
    pub stagger: Stagger,
    /// Inferred environment-map shells: lookups per pixel side (1 to
    /// [`pis_format::MAX_SHELL_LOOKUPS`]; SPEC.md 8.2): k × k sub-pixel lookups averaged,
    /// recorded in each shell block for the player.
    pub shell_lookups: u32,
    /// Weigh each pixel's rows by the set's confidence in it (thesis 6.3.3;
    /// [`super::confidence`]): sets traced with adaptive sampling record the error each
    /// pixel stopped at.
    pub confidence: bool,
    /// Layered environment maps: which distant shell a reflective object gets.
    pub distant_shell: DistantShell,
    /// Hybrid rendering: a lens object's shells fitted per layer of its rays' hits, or one
    /// depth shell.
    pub lens_shell: LensShell,
    /// Where the set turns a light over directions (`light_direction`), store surface
    /// layers as spherical-harmonic coefficients over them ([`super::relit`]); else sample
    /// the light as any dimension.
    pub relight: bool,
    /// Conjugate-gradient iteration cap per colour channel of every solve (`None`: the
    /// solver's default).
    pub max_iterations: Option<u32>,
    /// Also store the lossless master (SPEC.md 6.7): every solved texture before gamma
    /// compensation and coding, so that pis-reencode codes again from the solve.
    pub keep_master: bool,
    /// Tracing a scene.toml: a `[preset.NAME]` applied before the size overrides (also
    /// the preset a set's scene is read with).
    pub preset: Option<String>,
    /// Tracing a scene.toml: image size override.
    pub resolution: Option<(u32, u32)>,
    /// Tracing a scene.toml: samples per pixel override.
    pub spp: Option<u32>,
    /// Tracing a scene.toml: whether its layers are denoised (`pis-trace --denoise`; `Auto`,
    /// the default, denoises where Open Image Denoise is found, as pis-trace does).
    pub denoise: pis_trace::settings::DenoiseMode,
    /// The memory budget in GB (`None`: the memory available): a set whose pack would not
    /// fit is streamed through a scratch file ([`super::memory`]), with the same output.
    pub memory: Option<f64>,
}

impl Default for PackSettings {
    fn default() -> Self {
        Self::new()
    }
}

impl PackSettings {
    /// pis-pack's defaults: the fewest bytes that play within [`DEFAULT_WITHIN_DB`] of the
    /// textures as solved, each reflective or refractive object in the representation that
    /// meets it with the fewest bytes, with the wavelet codec, 8-sample blocks, trilinear
    /// filtering through the hardware model (bilinear for an object whose held-out views it
    /// predicts better), one level-0 texel per covered pixel (two or four for an object whose
    /// held-out views they predict better), screen-error
    /// allocation, texture placements per block.
    pub const fn new() -> Self {
        PackSettings {
            target: Target::DEFAULT,
            codec: CodecId::Wavelet,
            block: BlockSize::Uniform(DEFAULT_BLOCK),
            filter: Filter::Trilinear,
            filter_choice: true,
            density_choice: true,
            matrix: MatrixSource::Model,
            max_texture: DEFAULT_MAX_TEXTURE,
            texels_per_pixel: DEFAULT_TEXELS_PER_PIXEL,
            gamma: DEFAULT_GAMMA,
            pyramid: PyramidMode::Adaptive,
            layers: LayerMode::Separate,
            allocation: Allocation::Screen,
            max_mse: MaxMse::Best(pis_codec::allocate::DEFAULT_ALPHA),
            representation: RepresentationMode::Auto,
            placement: PlacementMode::Block,
            stagger: Stagger::Auto,
            shell_lookups: 1,
            confidence: false,
            distant_shell: DistantShell::Fitted,
            lens_shell: LensShell::Layered,
            relight: true,
            max_iterations: None,
            keep_master: false,
            preset: None,
            resolution: None,
            spp: None,
            denoise: pis_trace::settings::DenoiseMode::Auto,
            memory: None,
        }
    }

    /// Every solved texture stored exactly (lossless codec, linear storage): the decoded
    /// textures are the solved ones bit for bit.
    pub const fn lossless() -> Self {
        Self::new().with_codec(CodecId::Lossless)
    }

    /// The thesis's own choices where they differ from the defaults: one texture placement
    /// per object over every view, texture error weighted by screen area, trilinear lookups
    /// and the one texel budget for every object.
    pub const fn thesis() -> Self {
        let mut s = Self::new();
        s.filter_choice = false;
        s.density_choice = false;
        s.placement = PlacementMode::Object;
        s.allocation = Allocation::Texture;
        s
    }

    /// Render matrices measured on this machine's GPU adapter (probe mode, thesis 3.4.3).
    pub const fn probe() -> Self {
        let mut s = Self::new();
        s.matrix = MatrixSource::Probe;
        s
    }

    /// Aim at a compression ratio.
    pub const fn with_ratio(mut self, ratio: f64) -> Self {
        self.target = Target::Ratio(ratio);
        self
    }

    /// Aim at a PSNR (dB) of the coded textures.
    pub const fn with_psnr(mut self, db: f64) -> Self {
        self.target = Target::Psnr(db);
        self
    }

    /// Code with `codec` (gamma 1 for exact codecs, [`DEFAULT_GAMMA`] for lossy ones).
    pub const fn with_codec(mut self, codec: CodecId) -> Self {
        self.codec = codec;
        self.gamma = if codec.is_lossy() { DEFAULT_GAMMA } else { 1.0 };
        self
    }

    /// Store reflective objects as `representation`.
    pub const fn with_representation(mut self, representation: RepresentationMode) -> Self {
        self.representation = representation;
        self
    }

    /// The same block size along every dimension.
    pub fn with_block(mut self, samples: u32) -> Self {
        self.block = BlockSize::Uniform(samples);
        self
    }

    /// The texel budget (`None`: the optimal resolution).
    pub const fn with_texels_per_pixel(mut self, k: Option<f64>) -> Self {
        self.texels_per_pixel = k;
        self
    }

    /// Keep the lossless master beside the level images.
    pub const fn with_master(mut self) -> Self {
        self.keep_master = true;
        self
    }
}

/// How each block's pyramid levels are chosen.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum PyramidMode {
    /// Greedy choice of each level's counts (thesis 4.3).
    #[default]
    Adaptive,
    /// Every dimension halved (rounding up) per level down to one sample: no search.
    Full,
}

impl PyramidMode {
    /// The name `--pyramid` and the provenance use.
    pub fn name(self) -> &'static str {
        match self {
            PyramidMode::Adaptive => "adaptive",
            PyramidMode::Full => "full",
        }
    }

    /// Every mode, in the order the tools list them.
    pub const ALL: [PyramidMode; 2] = [PyramidMode::Adaptive, PyramidMode::Full];
}

/// The storage allocation's max-MSE constraint (thesis 4.8): no object's coding MSE above
/// α times the mean object MSE, storage taken from the objects with low MSE.
///
/// The thesis measures objects by texture-space coding error. Where a texture holds values
/// the display clips (a glass object's refracted highlights) that measure ranks objects
/// wrongly and the constraint starves objects the screen shows; where the free allocation
/// leaves a small object no bytes at all, the constraint is what keeps it from decoding to
/// black. Neither wins everywhere (docs/benchmarks/pack.md), so pis-pack's default tries both.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MaxMse {
    /// The free equal-slope allocation: the least texture error for the bytes.
    Off,
    /// The constraint at this α (the thesis: 1.25).
    On(f64),
    /// The constraint at this α and the free allocation, both encoded: the one whose decoded
    /// textures, rendered through the render matrices, predict the higher PSNR (a byte
    /// budget; a PSNR target applies the constraint).
    Best(f64),
}

impl MaxMse {
    /// The α the allocation applies, if any.
    pub fn alpha(self) -> Option<f64> {
        match self {
            MaxMse::Off => None,
            MaxMse::On(a) | MaxMse::Best(a) => Some(a),
        }
    }

    /// Its name in provenance and reports ([`std::fmt::Display`]): `off`, `1.25`, `best of
    /// 1.25 and off`. A file's provenance records the constraint its allocation applied
    /// (`max_mse_ratio`: `off` or α), which [`str::parse`] reads back.
    pub fn name(self) -> String {
        self.to_string()
    }
}

impl std::fmt::Display for MaxMse {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            MaxMse::Off => f.write_str("off"),
            MaxMse::On(a) => write!(f, "{a}"),
            MaxMse::Best(a) => write!(f, "best of {a} and off"),
        }
    }
}

/// `--max-mse-ratio`'s grammar, also the provenance's `max_mse_ratio`: `auto` (the best of
/// the constraint at the thesis's α and none), `off`, or α above 1.
impl std::str::FromStr for MaxMse {
    type Err = String;

    fn from_str(s: &str) -> Result<MaxMse, String> {
        match s {
            "auto" => Ok(MaxMse::Best(pis_codec::allocate::DEFAULT_ALPHA)),
            "off" => Ok(MaxMse::Off),
            _ => match s.parse::<f64>() {
                Ok(a) if a.is_finite() && a > 1.0 => Ok(MaxMse::On(a)),
                _ => Err(format!(
                    "{s:?} is not `auto`, `off` or a ratio above 1 (the thesis uses 1.25)"
                )),
            },
        }
    }
}

/// The error the storage allocation (thesis 4.5) minimizes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Allocation {
    /// Each level image's error weighted per texel by how much of the screen the texel
    /// reaches through the render matrices (column sums of A, carried down the decimation),
    /// so storage goes where errors are seen: texels no pixel reads weigh nothing, texels
    /// that magnified pixels read weigh more.
    #[default]
    Screen,
    /// Texture MSE weighted by each object's screen area (every texel of an object alike).
    Texture,
}

impl Allocation {
    /// The name `--allocation` and the provenance use.
    pub fn name(self) -> &'static str {
        match self {
            Allocation::Screen => "screen",
            Allocation::Texture => "texture",
        }
    }

    /// Every choice, in the order the tools list them.
    pub const ALL: [Allocation; 2] = [Allocation::Screen, Allocation::Texture];
}

/// Which views a texture placement (thesis 3.2) is optimized over.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum PlacementMode {
    /// Per object per parameter block: the views of the block's samples (thesis 3.2).
    #[default]
    Block,
    /// One placement per object over every view of the set, shared by all its blocks.
    Object,
}

impl PlacementMode {
    /// The name `--placement` and the provenance use.
    pub fn name(self) -> &'static str {
        match self {
            PlacementMode::Block => "block",
            PlacementMode::Object => "object",
        }
    }
}

/// Which dimensions the objects' parameter-block origins are staggered along (thesis 4.7).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Stagger {
    /// The dimensions with more samples than a block: there the objects' blocks end at
    /// different points, so a player crossing a boundary decodes one object's block at a
    /// time. A dimension that fits in one block has no boundary, and an offset would only
    /// cut each object's samples in two.
    #[default]
    Auto,
    /// Every dimension, whatever its samples (object i of n offset by i·B/n).
    Always,
}

impl Stagger {
    /// The name `--stagger` and the provenance use.
    pub fn name(self) -> &'static str {
        match self {
            Stagger::Auto => "auto",
            Stagger::Always => "always",
        }
    }

    /// Every mode, in the order the tools list them.
    pub const ALL: [Stagger; 2] = [Stagger::Auto, Stagger::Always];

    /// The mode the tools spell `name`.
    pub fn from_name(name: &str) -> Option<Stagger> {
        Stagger::ALL.into_iter().find(|m| m.name() == name)
    }
}

/// The distant shell of a reflective object's layered environment maps (thesis 5.4; SPEC.md
/// 7.3, 8.5).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum DistantShell {
    /// The box or the sphere, whichever is nearer the traced distant layer at a few points;
    /// then the depth shell where it predicts a point held out between two samples better.
    Auto,
    /// The box or the sphere, whichever is nearer the traced distant layer (thesis 5.4): the
    /// default, since a depth shell's one map over the views costs 0.3–1.5 dB at the
    /// sampled views where `Auto` takes it.
    #[default]
    Fitted,
    /// A box with its bottom on the surface the object rests on.
    Box,
    /// A sphere at the mean distance of the reflected environment.
    Sphere,
    /// A depth shell (where the scene has other objects to cast its depth cube from), its
    /// one map solved over the views (thesis 6.3.3.1's simultaneous inference).
    Depth,
    /// A depth shell with one map per parameter sample, each solved from its own view as the
    /// box's and the sphere's are: the single-view inference the shared map is measured
    /// against.
    DepthPerSample,
}

impl DistantShell {
    /// The name `--distant-shell` uses.
    pub fn name(self) -> &'static str {
        match self {
            DistantShell::Auto => "auto",
            DistantShell::Fitted => "fitted",
            DistantShell::Box => "box",
            DistantShell::Sphere => "sphere",
            DistantShell::Depth => "depth",
            DistantShell::DepthPerSample => "depth-per-sample",
        }
    }

    /// Every choice, in the order the tools list them.
    pub const ALL: [DistantShell; 6] = [
        DistantShell::Fitted,
        DistantShell::Auto,
        DistantShell::Box,
        DistantShell::Sphere,
        DistantShell::Depth,
        DistantShell::DepthPerSample,
    ];

    /// Whether a depth shell chosen under this setting has one map over the views.
    pub fn depth_map_shared(self) -> bool {
        self != DistantShell::DepthPerSample
    }
}

/// The shells of a lens object drawn by hybrid rendering (thesis 6.3.2; SPEC.md 7.3, 8.5).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LensShell {
    /// The layers clustered from the ray records' hit distances, a sphere, cylinder or box
    /// fitted to each (thesis 6.3.2).
    #[default]
    Layered,
    /// One depth shell about the lens object's centroid: its radius in every direction the
    /// distance to the other objects, so that each exit ray is marched to the surface it
    /// meets (where one is cast: else the layered shells); its one map solved over the views
    /// (thesis 6.3.3.1's simultaneous inference).
    Depth,
    /// The depth shell with one map per parameter sample, each solved from its own view.
    DepthPerSample,
}

impl LensShell {
    /// The name `--lens-shell` uses.
    pub fn name(self) -> &'static str {
        match self {
            LensShell::Layered => "layered",
            LensShell::Depth => "depth",
            LensShell::DepthPerSample => "depth-per-sample",
        }
    }

    /// Every choice, in the order the tools list them.
    pub const ALL: [LensShell; 3] =
        [LensShell::Layered, LensShell::Depth, LensShell::DepthPerSample];
}

/// How reflective objects are stored; refractive objects are stored by hybrid rendering
/// (thesis ch. 6) in every mode but `Texture` (with one shell in `PemInfinity`), and chosen
/// against textures in `Auto`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum RepresentationMode {
    /// Parameterized surface textures, as every other object (thesis ch. 3–4).
    Texture,
    /// Layered, parameterized environment maps: a local and a distant shell per parameter
    /// sample, plus a diffuse surface layer when the object has one (thesis ch. 5).
    Pem,
    /// One environment map per parameter sample on a sphere at infinity (looked up by the
    /// reflection direction alone), inferred against the traced incident light: the
    /// single-shell baseline of thesis 5.10.
    PemInfinity,
    /// The static environment map of thesis 5.1 (fig. 5.1): per parameter sample one cube
    /// map on a sphere at infinity, ray-traced from the object's centre with the object left
    /// out (its reflections of itself are lost), not inferred from the images.
    StaticEnv,
    /// Per reflective or refractive object, surface textures, or its environment-map shells
    /// where they do better: the shells are solved where the textures fall short
    /// ([`super::screen`]) and the whole file encoded with each ([`super::choice`]).
    #[default]
    Auto,
}

impl RepresentationMode {
    /// The name `--representation` takes.
    pub fn name(self) -> &'static str {
        match self {
            RepresentationMode::Texture => "texture",
            RepresentationMode::Pem => "pem",
            RepresentationMode::PemInfinity => "pem-infinity",
            RepresentationMode::StaticEnv => "static-env",
            RepresentationMode::Auto => "auto",
        }
    }
}

/// How the lighting layers are separated.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LayerMode {
    /// A view-independent diffuse layer and a view-dependent specular layer (thesis 4.8).
    #[default]
    Separate,
    /// One view-dependent layer of diffuse + specular radiance per parameter sample.
    Combined,
}

impl LayerMode {
    /// The name `--layers` and the provenance use.
    pub fn name(self) -> &'static str {
        match self {
            LayerMode::Separate => "separate",
            LayerMode::Combined => "combined",
        }
    }

    /// Every mode, in the order the tools list them.
    pub const ALL: [LayerMode; 2] = [LayerMode::Separate, LayerMode::Combined];
}

/// The provenance setting recording what a pack aimed at ([`Target::describe`]).
pub const TARGET_SETTING: &str = "target";

/// The provenance settings holding the predicted PSNR (dB, display values over the pixels the
/// objects cover) of a packed file, and what half floats would cost it.
pub use pis_format::precision::{
    HALF_FLOAT_PSNR_SETTING, LEVEL16_PSNR_SETTING, PREDICTED_PSNR_SETTING,
};

/// The default texel budget per covered pixel (`--texels-per-pixel`).
pub const DEFAULT_TEXELS_PER_PIXEL: Option<f64> = Some(1.0);

/// The default largest used texture side (`--max-texture`): a limit on what a GPU must
/// hold, not the resolution control (the texel budget is).
pub const DEFAULT_MAX_TEXTURE: u32 = 1024;

/// The default samples per parameter block along each dimension (`--block`).
pub const DEFAULT_BLOCK: u32 = 8;

/// The default display gamma of the compensation of lossy codecs (`--gamma`).
pub const DEFAULT_GAMMA: f32 = pis_codec::gamma::DEFAULT_GAMMA;

/// The default played quality when no target is given (`--within`): the predicted played
/// PSNR at most this many dB below the textures as solved. At 1 dB every bundled and wild
/// scene plays within 1.5 dB of its lossless figure in the fewest bytes that do
/// (docs/benchmarks/defaults.md); the thesis's 384:1 (`--ratio 384`) leaves a small set
/// almost nothing.
pub const DEFAULT_WITHIN_DB: f64 = 1.0;

#[cfg(test)]
mod tests {
    use super::*;

    /// `--ratio`, `--psnr` and `--within`: one or none, in range; every tool checks them
    /// here.
    #[test]
    fn a_target_is_one_flag_in_range() {
        assert_eq!(Target::given(None, None), Ok(None));
        assert_eq!(Target::from_flags(None, None, None), Ok(Target::DEFAULT));
        assert_eq!(Target::from_flags(Some(96.0), None, None), Ok(Target::Ratio(96.0)));
        assert_eq!(Target::from_flags(None, None, Some(0.5)), Ok(Target::Within(0.5)));
        assert_eq!(
            Target::from_flags(None, Some(40.0), Some(1.0)),
            Err("give one of --ratio, --psnr and --within".to_string())
        );
        assert_eq!(
            Target::from_flags(None, None, Some(0.0)),
            Err("--within must be a positive number of dB, got 0".to_string())
        );
        assert_eq!(Target::given(None, Some(40.0)), Ok(Some(Target::Psnr(40.0))));
        assert_eq!(
            Target::given(Some(96.0), Some(40.0)),
            Err("give --ratio or --psnr, not both".to_string())
        );
        assert_eq!(
            Target::from_flags(Some(0.5), None, None),
            Err("--ratio must be at least 1, got 0.5".to_string())
        );
        assert_eq!(
            Target::given(None, Some(f64::NAN)),
            Err("--psnr must be a positive number of dB, got NaN".to_string())
        );
        assert!(Target::Psnr(0.0).check().is_err() && Target::Ratio(1.0).check().is_ok());
    }

    /// `--max-mse-ratio` reads what a file's provenance records of the constraint applied,
    /// and refuses what is neither a name nor an α above 1.
    #[test]
    fn max_mse_parses_its_provenance_names() {
        for m in [MaxMse::Off, MaxMse::On(1.25), MaxMse::On(2.0)] {
            assert_eq!(m.name().parse::<MaxMse>(), Ok(m));
        }
        assert_eq!("auto".parse::<MaxMse>(), Ok(PackSettings::new().max_mse));
        assert_eq!(MaxMse::Best(1.25).name(), "best of 1.25 and off");
        for bad in ["1", "0.5", "inf", "on", ""] {
            assert!(bad.parse::<MaxMse>().is_err(), "{bad:?}");
        }
    }

    /// Each mode's name is its own, and the default is listed first.
    #[test]
    fn mode_names_are_distinct_and_the_default_first() {
        fn check<T: Copy + Default + PartialEq + std::fmt::Debug>(
            all: &[T],
            name: fn(T) -> &'static str,
        ) {
            assert_eq!(all[0], T::default());
            let names: std::collections::BTreeSet<_> = all.iter().map(|&m| name(m)).collect();
            assert_eq!(names.len(), all.len(), "{all:?}");
        }
        check(&PyramidMode::ALL, PyramidMode::name);
        check(&LayerMode::ALL, LayerMode::name);
        check(&Allocation::ALL, Allocation::name);
        check(&Stagger::ALL, Stagger::name);
    }
}
