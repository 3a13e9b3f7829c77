//! The player's errors.

use thiserror::Error;

/// How to get a GPU adapter on a machine without one.
pub const ADAPTER_HINT: &str =
    "no GPU adapter found; on a machine without a GPU install Mesa's software \
Vulkan driver (lavapipe): `apt-get install -y mesa-vulkan-drivers`";

/// Why the player cannot draw.
#[derive(Debug, Error)]
pub enum PlayError {
    #[error("{ADAPTER_HINT} ({0})")]
    NoAdapter(String),
    #[error("the GPU adapter '{adapter}' refused a device: {message}")]
    Device { adapter: String, message: String },
    #[error("probe mode needs Rgba32Float textures (texel identifiers up to 2^24), but the device '{0}' uses Rgba16Float (no FLOAT32_FILTERABLE, or half textures were asked for)")]
    ProbeNeedsFloat32(String),
    #[error("probe mode: the render matrix measured for filter {filter} at lookup reach {reach} predicts the pipeline's rendering of a check texture only to {error:.2e} (tolerance {tolerance:.0e}): the adapter's filter footprint is wider than the probe allows for")]
    ProbeCheck { filter: String, reach: u32, error: f32, tolerance: f32 },
    #[error("repeat addressing along {axis} needs a power-of-two used texture size, got {size} (a wrapped dimension's size is chosen by texture-coordinate optimization)")]
    RepeatSize { axis: char, size: u32 },
    #[error("texture data has {got} values, the layout {width}×{height} with {levels} levels needs {want} (4 per texel)")]
    TextureData { got: usize, want: usize, width: u32, height: u32, levels: u32 },
    #[error("object {object}: a {width}×{height} texture exceeds the adapter's largest texture side {limit} (textures are allocated at the next power of two)")]
    TextureSize { object: String, width: u32, height: u32, limit: u32 },
    #[error("render target {width}×{height} is empty or exceeds the adapter's limit {limit}")]
    TargetSize { width: u32, height: u32, limit: u32 },
    /// The file's textures need more memory than the player may use or the adapter holds
    /// (a texture, its sizes and the limit, in words).
    #[error("{0}")]
    Memory(String),
    #[error("reading back the frame failed: {0}")]
    Readback(String),
    #[error(transparent)]
    Model(#[from] pis_compile::ModelError),
    /// The .pis file could not be read, is invalid, or asks for something unsupported.
    #[error(transparent)]
    File(#[from] pis_format::Error),
    /// The file is structurally valid but the player cannot draw it as it is.
    #[error("{path}: {message}")]
    Content { path: String, message: String },
    /// A frame request that does not fit the file (wrong number of values, non-finite value).
    #[error("{0}")]
    Request(String),
    /// A decoding worker failed outside the decoder (it panicked or its pool could not start).
    #[error("decoding worker: {0}")]
    Worker(String),
}
