//! The parameter space: scene.toml `[[dimension]]` tables resolved against the glTF.

use std::path::Path;

use glam::Vec3;

use crate::gltf_load::GltfScene;
use crate::light_direction::{arc_directions, light_directions, Cover};
use crate::manifest::{CoverSpec, DimensionSpec, DriverSpec, KindSpec};
use crate::model::{Dimension, Driver, ParameterSpace};
use crate::{DimensionKind, LightKind, SceneError};

/// `n` sample values from `a` to `b`: inclusive of `b`, or for a periodic dimension
/// (a closed loop) stopping one step short of it.
pub fn sample_values(a: f32, b: f32, n: u32, periodic: bool) -> Vec<f32> {
    match n {
        0 => vec![],
        1 => vec![a],
        _ => {
            let steps = if periodic { n } else { n - 1 } as f32;
            (0..n).map(|i| a + (b - a) * i as f32 / steps).collect()
        }
    }
}

fn kind_of(k: KindSpec) -> DimensionKind {
    match k {
        KindSpec::View => DimensionKind::View,
        KindSpec::Light => DimensionKind::Light,
        KindSpec::ObjectMotion => DimensionKind::ObjectMotion,
        KindSpec::Time => DimensionKind::Time,
        KindSpec::Other => DimensionKind::Other,
    }
}

/// Builds the parameter space; `path` is scene.toml (for errors).
pub(crate) fn build_space(
    specs: &[DimensionSpec],
    g: &GltfScene,
    path: &Path,
) -> Result<ParameterSpace, SceneError> {
    let mut dims = Vec::with_capacity(specs.len());
    let mut orbits = 0;
    for (index, d) in specs.iter().enumerate() {
        let at = At { path, index, d };
        check_keys(&at, &specs[..index])?;
        let periodic = d.periodic.unwrap_or(false);
        let resolved = match d.driver {
            DriverSpec::Orbit => {
                orbits += 1;
                if orbits > 1 {
                    return Err(
                        at.invalid("driver", "only one orbit dimension may move the camera")
                    );
                }
                orbit(&at)?
            }
            DriverSpec::Animation => animation(&at, g)?,
            DriverSpec::LightPath => light_path(&at, g)?,
            DriverSpec::LightDirection => light_direction(&at, g)?,
        };
        let Resolved { kind, unit, range: ([a, b], range_key), driver } = resolved;
        if d.samples > 1 && b <= a {
            return Err(at.invalid(
                range_key,
                format!("[{a}, {b}] must increase for {} samples", d.samples),
            ));
        }
        dims.push(Dimension {
            name: d.name.clone(),
            kind,
            periodic,
            unit: unit.to_owned(),
            values: sample_values(a, b, d.samples, periodic),
            driver,
        });
    }
    if dims.is_empty() {
        dims.push(still());
    }
    Ok(ParameterSpace { dims })
}

/// The one dimension of a scene without `[[dimension]]`: `point`, one sample, nothing moves.
fn still() -> Dimension {
    Dimension {
        name: "point".to_owned(),
        kind: DimensionKind::Other,
        periodic: false,
        unit: String::new(),
        values: vec![0.0],
        driver: Driver::Still,
    }
}

/// One `[[dimension]]` table where its errors point: scene.toml and the table's index.
struct At<'a> {
    path: &'a Path,
    index: usize,
    d: &'a DimensionSpec,
}

impl At<'_> {
    fn field(&self, key: &str) -> String {
        format!("dimension[{}].{key}", self.index)
    }

    fn invalid(&self, key: &str, message: impl Into<String>) -> SceneError {
        SceneError::invalid(self.path, self.field(key), message)
    }

    fn required(&self, key: &str) -> SceneError {
        self.invalid(key, format!("required by driver {:?}", self.d.driver))
    }

    /// The kind of a driver that always has `expected`; an explicit other kind is an error.
    fn fixed_kind(&self, expected: KindSpec) -> Result<DimensionKind, SceneError> {
        match self.d.kind {
            Some(k) if k != expected => Err(self.invalid(
                "kind",
                format!("driver {:?} always has kind {:?}", self.d.driver, expected),
            )),
            _ => Ok(kind_of(expected)),
        }
    }
}

/// A driver resolved against the glTF: the dimension's kind, unit, range with the key it
/// came from, and what it moves.
struct Resolved {
    kind: DimensionKind,
    unit: &'static str,
    range: ([f32; 2], &'static str),
    driver: Driver,
}

/// At least one sample, a name not used by an `earlier` dimension, and only the keys of
/// its driver.
fn check_keys(at: &At, earlier: &[DimensionSpec]) -> Result<(), SceneError> {
    let d = at.d;
    if d.samples == 0 {
        return Err(SceneError::ZeroSamples {
            path: at.path.to_owned(),
            field: at.field("samples"),
            dimension: d.name.clone(),
        });
    }
    if earlier.iter().any(|e| e.name == d.name) {
        return Err(at.invalid("name", format!("dimension name `{}` is used twice", d.name)));
    }
    // Keys each driver may use; any other driver-specific key is an error.
    let present: [(&str, bool); 13] = [
        ("target", d.target.is_some()),
        ("radius", d.radius.is_some()),
        ("elevation_deg", d.elevation_deg.is_some()),
        ("azimuth_deg", d.azimuth_deg.is_some()),
        ("animation", d.animation.is_some()),
        ("time", d.time.is_some()),
        ("light", d.light.is_some()),
        ("path", d.path.is_some()),
        ("range", d.range.is_some()),
        ("directions", d.directions.is_some()),
        ("up", d.up.is_some()),
        ("center", d.center.is_some()),
        ("distance", d.distance.is_some()),
    ];
    let allowed: &[&str] = match d.driver {
        DriverSpec::Orbit => &["target", "radius", "elevation_deg", "azimuth_deg"],
        DriverSpec::Animation => &["animation", "time"],
        DriverSpec::LightPath => &["light", "path", "range"],
        DriverSpec::LightDirection => {
            &["light", "directions", "up", "center", "distance", "elevation_deg", "azimuth_deg"]
        }
    };
    if let Some((key, _)) = present.iter().find(|(k, p)| *p && !allowed.contains(k)) {
        return Err(at.invalid(key, format!("key not used by driver {:?}", d.driver)));
    }
    Ok(())
}

/// The camera on a circle about `target` (azimuth in degrees).
fn orbit(at: &At) -> Result<Resolved, SceneError> {
    let d = at.d;
    let target = Vec3::from(d.target.ok_or_else(|| at.required("target"))?);
    let radius = d.radius.ok_or_else(|| at.required("radius"))?;
    if radius <= 0.0 {
        return Err(at.invalid("radius", format!("must be > 0, found {radius}")));
    }
    let elevation_deg = d.elevation_deg.unwrap_or(0.0);
    let range = d.azimuth_deg.ok_or_else(|| at.required("azimuth_deg"))?;
    Ok(Resolved {
        kind: at.fixed_kind(KindSpec::View)?,
        unit: "deg",
        range: (range, "azimuth_deg"),
        driver: Driver::Orbit { target, radius, elevation_deg },
    })
}

/// A glTF animation sampled in time (seconds; its whole time range by default).
fn animation(at: &At, g: &GltfScene) -> Result<Resolved, SceneError> {
    let d = at.d;
    let name = d.animation.as_deref().ok_or_else(|| at.required("animation"))?;
    if let Some((f, why)) = g.unsupported_animations.get(name) {
        return Err(SceneError::unsupported(
            at.path,
            f.clone(),
            format!("animation `{name}`: {why}"),
        ));
    }
    let Some(anim) = g.rig.animations.iter().find(|a| a.name == name) else {
        let known = g.rig.animations.iter().map(|a| a.name.as_str());
        return Err(SceneError::unknown(at.path, at.field("animation"), "animation", name, known));
    };
    let (t0, t1) = anim.time_range();
    let range = d.time.unwrap_or([t0, t1]);
    Ok(Resolved {
        kind: kind_of(d.kind.unwrap_or(KindSpec::Time)),
        unit: "s",
        range: (range, "time"),
        driver: Driver::Animation { animation: name.to_owned() },
    })
}

/// The light named by `light`, or the error naming the lights there are.
fn named_light<'a>(at: &At<'a>, g: &GltfScene) -> Result<(&'a str, LightKind), SceneError> {
    let name = at.d.light.as_deref().ok_or_else(|| at.required("light"))?;
    match g.rig.lights.iter().find(|l| l.name == name || g.rig.nodes[l.node].name == name) {
        Some(l) => Ok((name, l.kind)),
        None => {
            let known = g.rig.lights.iter().map(|l| l.name.as_str());
            Err(SceneError::unknown(at.path, at.field("light"), "light", name, known))
        }
    }
}

/// A light turned over the directions of a hemisphere or the sphere; the sample values are
/// the samples' indices. A directional light needs no `center` or `distance`; any other
/// light needs both.
fn light_direction(at: &At, g: &GltfScene) -> Result<Resolved, SceneError> {
    let d = at.d;
    let (name, kind) = named_light(at, g)?;
    let up = Vec3::from(d.up.unwrap_or([0.0, 1.0, 0.0]));
    if !up.is_finite() || up.length() < 1e-6 {
        return Err(at.invalid("up", format!("must be a finite direction, found {up}")));
    }
    let (center, distance) = match (kind, d.center, d.distance) {
        (LightKind::Directional, None, None) => (Vec3::ZERO, 0.0),
        (LightKind::Directional, _, _) => {
            let key = if d.center.is_some() { "center" } else { "distance" };
            return Err(at.invalid(key, format!("light `{name}` is directional: it has no place")));
        }
        (_, Some(c), Some(r)) if r > 0.0 && r.is_finite() => (Vec3::from(c), r),
        (_, Some(_), Some(r)) => {
            return Err(at.invalid("distance", format!("must be > 0, found {r}")));
        }
        (_, None, _) => {
            return Err(at.invalid("center", format!("required: light `{name}` has a place")))
        }
        (_, _, None) => {
            return Err(at.invalid("distance", format!("required: light `{name}` has a place")))
        }
    };
    if d.periodic == Some(true) {
        return Err(at.invalid("periodic", "a set of directions has no loop to close"));
    }
    let cover = d.directions.unwrap_or(CoverSpec::Hemisphere);
    if cover != CoverSpec::Arc {
        for (key, given) in
            [("elevation_deg", d.elevation_deg), ("azimuth_deg", d.azimuth_deg.map(|a| a[0]))]
        {
            if given.is_some() {
                return Err(at.invalid(key, "only an arc (`directions = \"arc\"`) has it"));
            }
        }
    }
    let up = up.normalize();
    let directions = match cover {
        CoverSpec::Hemisphere => light_directions(d.samples, Cover::Hemisphere, up),
        CoverSpec::Sphere => light_directions(d.samples, Cover::Sphere, up),
        CoverSpec::Arc => {
            let azimuth = d.azimuth_deg.ok_or_else(|| at.required("azimuth_deg"))?;
            let elevation = d.elevation_deg.unwrap_or(0.0);
            if !(azimuth.iter().all(|a| a.is_finite()) && elevation.abs() <= 90.0) {
                return Err(at.invalid("elevation_deg", format!("must lie in [-90, 90] with a finite azimuth_deg, found {elevation} and {azimuth:?}")));
            }
            arc_directions(d.samples, elevation, azimuth, up)
        }
    };
    Ok(Resolved {
        kind: at.fixed_kind(KindSpec::Light)?,
        unit: "",
        range: ([0.0, d.samples.saturating_sub(1) as f32], "samples"),
        driver: Driver::LightDirection {
            light: name.to_owned(),
            directions,
            center,
            distance,
            arc: cover == CoverSpec::Arc,
        },
    })
}

/// A light moved along a polyline (the range in normalised arc length, [0, 1] by default).
fn light_path(at: &At, g: &GltfScene) -> Result<Resolved, SceneError> {
    let d = at.d;
    let (name, _) = named_light(at, g)?;
    let pts: Vec<Vec3> = d
        .path
        .as_ref()
        .ok_or_else(|| at.required("path"))?
        .iter()
        .map(|&p| Vec3::from(p))
        .collect();
    if pts.is_empty() {
        return Err(at.invalid("path", "needs at least one point"));
    }
    let range = d.range.unwrap_or([0.0, 1.0]);
    Ok(Resolved {
        kind: at.fixed_kind(KindSpec::Light)?,
        unit: "",
        range: (range, "range"),
        driver: Driver::LightPath { light: name.to_owned(), path: pts },
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_inclusive_and_periodic() {
        assert_eq!(sample_values(0.0, 30.0, 4, false), vec![0.0, 10.0, 20.0, 30.0]);
        assert_eq!(sample_values(0.0, 360.0, 4, true), vec![0.0, 90.0, 180.0, 270.0]);
        assert_eq!(sample_values(5.0, 9.0, 1, false), vec![5.0]);
    }
}
