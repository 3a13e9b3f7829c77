//! The scene.toml pieces every wild scene shares: the header (what generated it, its licence,
//! what it exercises) and an orbit dimension.

use glam::Vec3;

use super::common::toml_header;

const LICENCE: &str =
    "# Licence: the project's own scene (generated here, no outside assets), under the project's licence.\n";

/// The header of a wild scene's scene.toml: its title, the generator, its licence and what
/// it exercises (`what`, one comment line per line).
pub(super) fn header(title: &str, what: &str) -> String {
    let mut s = toml_header(title).replace(
        "`cargo run -p pis-samples --release -- samples/`",
        "`cargo run -p pis-samples --release -- samples/` (into samples/wild/)",
    );
    s.push_str(LICENCE);
    for line in what.lines() {
        s.push_str("# ");
        s.push_str(line.trim());
        s.push('\n');
    }
    s
}

/// An orbit dimension `name` of `samples` views about `target`.
pub(super) fn orbit(
    name: &str,
    samples: u32,
    target: Vec3,
    radius: f32,
    elevation: f32,
    az: [f32; 2],
) -> String {
    format!(
        "[[dimension]]\nname = \"{name}\"\ndriver = \"orbit\"\nsamples = {samples}\ntarget = [{}, {}, {}]\nradius = {radius}\nelevation_deg = {elevation}\nazimuth_deg = [{}, {}]\n",
        target.x, target.y, target.z, az[0], az[1]
    )
}
