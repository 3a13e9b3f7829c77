//! The screen of `--representation auto` (pis-pack's default): which objects are also
//! solved in their alternative representation (layered environment maps, hybrid rendering),
//! decided from what their surface textures achieved, before anything more is solved.
//!
//! Surface textures hold a reflective or refractive object's look per parameter sample, so
//! at the sampled views they fit it as well as anything unless their texels cannot hold what
//! it shows (a mirror ball's reflections squeezed towards its silhouette). Measured on the
//! bundled, wild and Blender scenes at CI size (docs/benchmarks/defaults.md, "The
//! representation of each object"), every object whose textures solved within
//! [`SOLVE_BELOW_DB`] of the other objects' solved figure solved worse in its alternative
//! (0.5–10 dB), and only objects far below it solved better; an alternative that solves
//! more than [`KEEP_BELOW_DB`] below the textures on its object is dropped without the
//! whole-file encodes of [`super::choice`].

/// An object whose textures solved at least this far (dB) below the other objects of the
/// file together is also solved in its alternative representation.
pub const SOLVE_BELOW_DB: f64 = 6.0;

/// An alternative whose solved figure on its object is more than this (dB) below the
/// textures' is not weighed by whole-file encodes: at the default target, within 1 dB of
/// the file as solved, it would need more bytes to play the object as well.
pub const KEEP_BELOW_DB: f64 = 1.0;

/// Why an object whose textures solved to `object_db`, beside other objects that solved to
/// `others_db` together (`None`: it is the only object), is (`Ok`) or is not (`Err`) also
/// solved in its alternative, in words. The only object is: nothing tells its textures fall
/// short but the alternative itself.
pub fn solve_alternative(object_db: f64, others_db: Option<f64>) -> Result<String, String> {
    let Some(others_db) = others_db else {
        return Ok(format!("its textures solved to {object_db:.2} dB, the only object"));
    };
    let below = others_db - object_db;
    let said = format!(
        "its textures solved to {object_db:.2} dB, {below:.2} dB below the other objects' {others_db:.2}"
    );
    if below >= SOLVE_BELOW_DB {
        Ok(said)
    } else {
        Err(format!("{said} (an alternative is solved from {SOLVE_BELOW_DB} dB below)"))
    }
}

/// Why an alternative that solved to `alt_db` on an object whose textures solved to
/// `textures_db` is (`Ok`) or is not (`Err`) weighed by whole-file encodes, in words.
pub fn weigh_alternative(alt_db: f64, textures_db: f64, alt: &str) -> Result<String, String> {
    let said = format!("as {alt} it solved to {alt_db:.2} dB against {textures_db:.2}");
    if alt_db >= textures_db - KEEP_BELOW_DB {
        Ok(said)
    } else {
        Err(format!("{said} (more than {KEEP_BELOW_DB} dB below)"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_objects_far_below_the_file_are_solved_again() {
        // The Blender scene's mirror ball as textures, and demo1's table top.
        assert!(solve_alternative(16.51, Some(25.35)).is_ok());
        let kept = solve_alternative(32.74, Some(35.23)).unwrap_err();
        assert!(kept.contains("2.49 dB below the other objects' 35.23"), "{kept}");
        assert!(solve_alternative(30.0, None).unwrap().contains("the only object"));
    }

    #[test]
    fn an_alternative_is_weighed_unless_it_solves_clearly_worse() {
        // The mirror ball as layered shells; demo1's vase; teapot-pem's body.
        assert!(weigh_alternative(29.22, 16.51, "shells").is_ok());
        assert!(weigh_alternative(24.46, 24.58, "shells").is_ok());
        let dropped = weigh_alternative(23.57, 26.00, "shells").unwrap_err();
        assert!(dropped.contains("as shells it solved to 23.57 dB against 26.00"), "{dropped}");
    }
}
