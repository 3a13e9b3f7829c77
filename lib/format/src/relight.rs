//! Relightable files (SPEC.md 6.6 and 7.1, since 1.6): the light directions of a `light`
//! dimension, recorded as provenance settings, and the layers that hold spherical-harmonic
//! coefficients of an object's radiance over them.
//!
//! `light_directions.DIM` holds the unit direction, from the scene towards the light, of
//! every sample of dimension DIM (`x,y,z;x,y,z;…`, in sample order), and
//! `light_radiance.DIM` the radiance the set was traced with (`r,g,b`): a directional light's
//! illuminance times its colour. A layer whose `basis` is c + 1 holds coefficient c: at the
//! light direction ω its texel shows Σ_c Y_c(ω)·x_c (the real spherical harmonics of
//! section 9), under a light of the recorded radiance.

use crate::model::{DimensionKind, Layer, Mapping, Object, ParameterSpace, Provenance};

/// The key prefix of a dimension's directions; the dimension's name follows.
pub const DIRECTIONS_PREFIX: &str = "light_directions.";
/// The key prefix of a dimension's traced radiance; the dimension's name follows.
pub const RADIANCE_PREFIX: &str = "light_radiance.";
/// The most coefficients a layer may hold: bands 0 to 8.
pub const MAX_COEFFICIENTS: u8 = 81;

/// A light dimension's directions and the radiance its samples were traced with.
#[derive(Clone, Debug, PartialEq)]
pub struct LightDirections {
    /// The dimension's index in the parameter space.
    pub dim: usize,
    pub radiance: [f32; 3],
    pub directions: Vec<[f32; 3]>,
}

/// The two settings that record `l` on dimension `name`.
pub fn light_settings(name: &str, l: &LightDirections) -> [(String, String); 2] {
    let dirs: Vec<String> =
        l.directions.iter().map(|d| format!("{},{},{}", d[0], d[1], d[2])).collect();
    let [r, g, b] = l.radiance;
    [
        (format!("{DIRECTIONS_PREFIX}{name}"), dirs.join(";")),
        (format!("{RADIANCE_PREFIX}{name}"), format!("{r},{g},{b}")),
    ]
}

/// Three comma-separated decimal numbers.
fn triple(v: &str) -> Option<[f32; 3]> {
    let parts: Vec<f32> =
        v.split(',').map(|s| s.trim().parse::<f32>().ok()).collect::<Option<_>>()?;
    <[f32; 3]>::try_from(parts).ok()
}

/// The file's light directions (at most one dimension has them) — rule 9006: an error
/// naming what is wrong where a setting names no dimension of kind `light`, holds another
/// count of directions than the dimension's samples, a direction that is not unit within
/// 10⁻³, or a radiance that is not three finite numbers greater than 0; where one of the two
/// settings lacks the other; or where two dimensions have them.
pub fn light_directions(
    p: Option<&Provenance>,
    space: &ParameterSpace,
) -> Result<Option<LightDirections>, String> {
    let Some(p) = p else { return Ok(None) };
    let mut found: Option<LightDirections> = None;
    for (k, v) in &p.settings {
        let Some(name) = k.strip_prefix(DIRECTIONS_PREFIX) else { continue };
        let (dim, d) = space
            .dims
            .iter()
            .enumerate()
            .find(|(_, d)| d.name == name)
            .ok_or_else(|| format!("{k}: no dimension is named {name:?}"))?;
        if d.kind != DimensionKind::Light {
            return Err(format!("{k}: dimension {name:?} is of kind {}", d.kind.name()));
        }
        let directions: Vec<[f32; 3]> = v
            .split(';')
            .map(triple)
            .collect::<Option<_>>()
            .ok_or_else(|| format!("{k}: not a list of x,y,z directions separated by ';'"))?;
        if directions.len() != d.values.len() {
            return Err(format!(
                "{k}: {} directions, the dimension has {} samples",
                directions.len(),
                d.values.len()
            ));
        }
        if let Some(i) = directions.iter().position(|w| {
            let n = (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]).sqrt();
            n.is_nan() || (n - 1.0).abs() > 1e-3
        }) {
            return Err(format!("{k}: direction {i} is not a unit vector"));
        }
        let rk = format!("{RADIANCE_PREFIX}{name}");
        let radiance =
            p.setting(&rk).ok_or_else(|| format!("{k}: no {rk} beside it")).and_then(|v| {
                triple(v)
                    .filter(|c| c.iter().all(|x| x.is_finite() && *x > 0.0))
                    .ok_or_else(|| format!("{rk} {v:?} is not three numbers greater than 0"))
            })?;
        if found.is_some() {
            return Err(format!("{k}: a second dimension with light directions"));
        }
        found = Some(LightDirections { dim, radiance, directions });
    }
    if let Some((k, _)) = p.settings.iter().find(|(k, _)| {
        k.strip_prefix(RADIANCE_PREFIX)
            .is_some_and(|n| found.as_ref().is_none_or(|f| space.dims[f.dim].name != n))
    }) {
        return Err(format!("{k}: no light directions beside it"));
    }
    Ok(found)
}

/// Whether layer `l` is a valid coefficient layer by itself (rule 6003): a 3-channel surface
/// layer added to the surface term, of a coefficient below [`MAX_COEFFICIENTS`].
pub fn basis_layer_fits<S>(l: &Layer<S>) -> bool {
    l.mapping == Mapping::Surface
        && l.channels == 3
        && l.combine == crate::model::Combine::Add
        && l.basis <= MAX_COEFFICIENTS
}

/// Rule 6011 over every object: a layer with a basis needs the file's light directions,
/// and does not depend on their dimension. The first violation, described.
pub fn check_basis_layers<S>(
    objects: &[Object<S>],
    lights: Option<&LightDirections>,
) -> Result<(), String> {
    for (oi, o) in objects.iter().enumerate() {
        for (li, l) in o.layers.iter().enumerate().filter(|(_, l)| l.basis != 0) {
            let at = format!("object {oi} '{}' layer {li}", o.name);
            let Some(lights) = lights else {
                return Err(format!(
                    "{at}: coefficient {} and the file records no light directions",
                    l.basis - 1
                ));
            };
            if l.depends_on.contains(lights.dim) {
                return Err(format!("{at}: depends on the light dimension its coefficient spans"));
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::filter::tests::prov;
    use crate::model::Dimension;

    fn space() -> ParameterSpace {
        let dim = |name: &str, kind, n: usize| Dimension {
            name: name.into(),
            unit: String::new(),
            kind,
            periodic: false,
            block_size: 8,
            values: (0..n).map(|i| i as f32).collect(),
        };
        ParameterSpace {
            dims: vec![dim("view", DimensionKind::View, 2), dim("sun", DimensionKind::Light, 2)],
        }
    }

    #[test]
    fn directions_round_trip_through_their_settings() {
        let l = LightDirections {
            dim: 1,
            radiance: [3.0, 2.5, 0.125],
            directions: vec![[0.0, 1.0, 0.0], [0.6, 0.0, 0.8]],
        };
        let settings = light_settings("sun", &l);
        let p = Provenance { settings: settings.to_vec(), ..prov(&[]) };
        assert_eq!(light_directions(Some(&p), &space()), Ok(Some(l)));
        assert_eq!(light_directions(None, &space()), Ok(None));
    }

    #[test]
    fn every_broken_setting_is_named() {
        let ok_r = ("light_radiance.sun", "1,1,1");
        for (settings, says) in [
            (vec![("light_directions.moon", "0,1,0;0,1,0"), ok_r], "no dimension"),
            (
                vec![("light_directions.view", "0,1,0;0,1,0"), ("light_radiance.view", "1,1,1")],
                "kind view",
            ),
            (vec![("light_directions.sun", "0,1,0"), ok_r], "1 directions"),
            (vec![("light_directions.sun", "0,1,0;0,2,0"), ok_r], "direction 1"),
            (vec![("light_directions.sun", "0,1,0;0,1"), ok_r], "x,y,z"),
            (vec![("light_directions.sun", "0,1,0;0,1,0")], "no light_radiance.sun"),
            (
                vec![("light_directions.sun", "0,1,0;0,1,0"), ("light_radiance.sun", "1,0,1")],
                "greater than 0",
            ),
            (vec![ok_r], "no light directions"),
        ] {
            let err = light_directions(Some(&prov(&settings)), &space()).unwrap_err();
            assert!(err.contains(says), "{settings:?}: {err}");
        }
    }
}
