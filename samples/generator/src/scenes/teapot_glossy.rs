//! teapot-glossy — teapot-pem with a glossy metal teapot (seed section 5.10, figures
//! 5.11–5.12): glossy objects are handled like mirrors, by inferring environment maps, with
//! the reflections ray-traced through the glossy material. Same room, objects, light, view
//! path and presets as teapot-pem; only the teapot's body and lid differ.

use std::io;
use std::path::Path;

use super::teapot_pem::{write_variant, Variant, TEAPOT_COLOR};
use crate::gltf_writer::MaterialDesc;

/// The teapot's roughness. pis-scene classifies a metal (metallic ≥ 0.5) as reflective up to
/// roughness 0.3, and any material as a mirror-like reflector below `MIRROR_ROUGHNESS`
/// (0.1); teapot-pem's mirror is 0.02 (GGX alpha 4e-4, which the tracer treats as a
/// perfect mirror). 0.2 is twice the mirror threshold — GGX alpha 0.04, a visibly blurred
/// reflection — yet clear of the 0.3 limit, so the teapot stays `reflective` and keeps the
/// environment-map treatment.
pub const ROUGHNESS: f32 = 0.2;

/// Writes samples/teapot-glossy.
pub fn write(dir: &Path) -> io::Result<()> {
    write_variant(
        dir,
        &Variant {
            name: "teapot-glossy",
            title: "teapot-glossy — the seed's section 5.10, figures 5.11–5.12: a glossy metal teapot in a room, 1D view path",
            teapot: MaterialDesc::metal("GlossyMetal", TEAPOT_COLOR, ROUGHNESS),
        },
    )
}
