//! The representations pis-pack knows, beside the seam they implement
//! ([`super::represent`]): a new representation is its module plus one line here.

use pis_scene::ObjectRole;

use super::hybrid::HybridRendering;
use super::pem::LayeredPem;
use super::represent::Representation;
use super::surface::SurfaceTextures;
use super::RepresentationMode;

/// The representations pis-pack knows, in the order they are tried.
pub const REPRESENTATIONS: &[&dyn Representation] =
    &[&HybridRendering, &LayeredPem, &SurfaceTextures];

/// The representation of an object of `role` under `mode`: the first that applies
/// (environment maps, for reflective and refractive objects, only when `mode` asks for
/// them; the layered representation of reflective objects then makes one or two shells as
/// `mode` says).
pub fn choose(role: ObjectRole, mode: RepresentationMode) -> Option<&'static dyn Representation> {
    let textures_only = matches!(mode, RepresentationMode::Texture | RepresentationMode::Auto);
    REPRESENTATIONS
        .iter()
        .copied()
        .filter(|r| !textures_only || !r.shells())
        .find(|r| r.applies(role))
}

/// The representation also solved for an object of `role` under `mode`, to be chosen
/// between by [`super::choice`]: in `auto`, layered environment maps for a reflective object
/// and hybrid rendering for a refractive one.
pub fn alternative(
    role: ObjectRole,
    mode: RepresentationMode,
) -> Option<&'static dyn Representation> {
    if mode != RepresentationMode::Auto {
        return None;
    }
    REPRESENTATIONS.iter().copied().filter(|r| r.shells()).find(|r| r.applies(role))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_object_role_has_a_representation() {
        for role in [ObjectRole::Diffuse, ObjectRole::Reflective, ObjectRole::Refractive] {
            assert_eq!(
                choose(role, RepresentationMode::Texture).map(|r| r.name()),
                Some("surface textures"),
                "{role:?}"
            );
            let pem = match role {
                ObjectRole::Reflective => "layered environment maps",
                ObjectRole::Refractive => "hybrid rendering",
                ObjectRole::Diffuse => "surface textures",
            };
            assert_eq!(
                choose(role, RepresentationMode::Pem).map(|r| r.name()),
                Some(pem),
                "{role:?}"
            );
        }
    }

    #[test]
    fn auto_weighs_shells_against_textures_for_reflective_and_refractive_objects() {
        let alt = |role, mode| alternative(role, mode).map(|r| r.name());
        assert_eq!(
            alt(ObjectRole::Reflective, RepresentationMode::Auto),
            Some("layered environment maps")
        );
        assert_eq!(alt(ObjectRole::Refractive, RepresentationMode::Auto), Some("hybrid rendering"));
        assert_eq!(alt(ObjectRole::Diffuse, RepresentationMode::Auto), None);
        assert_eq!(alt(ObjectRole::Reflective, RepresentationMode::Pem), None);
    }
}
