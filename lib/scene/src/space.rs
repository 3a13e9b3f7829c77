//! The parameter space: scene.toml `[[dimension]]` tables resolved against the glTF.

use std::path::Path;

use glam::Vec3;

use crate::gltf_load::GltfScene;
use crate::manifest::{DimensionSpec, DriverSpec, KindSpec};
use crate::model::{Dimension, Driver, ParameterSpace};
use crate::{DimensionKind, SceneError};

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
    for (i, d) in specs.iter().enumerate() {
        let field = |key: &str| format!("dimension[{i}].{key}");
        if d.samples == 0 {
            return Err(SceneError::ZeroSamples {
                path: path.to_owned(),
                field: field("samples"),
                dimension: d.name.clone(),
            });
        }
        if specs[..i].iter().any(|e| e.name == d.name) {
            return Err(SceneError::invalid(
                path,
                field("name"),
                format!("dimension name `{}` is used twice", d.name),
            ));
        }
        // Keys each driver may use; any other driver-specific key is an error.
        let present: [(&str, bool); 9] = [
            ("target", d.target.is_some()),
            ("radius", d.radius.is_some()),
            ("elevation_deg", d.elevation_deg.is_some()),
            ("azimuth_deg", d.azimuth_deg.is_some()),
            ("animation", d.animation.is_some()),
            ("time", d.time.is_some()),
            ("light", d.light.is_some()),
            ("path", d.path.is_some()),
            ("range", d.range.is_some()),
        ];
        let allowed: &[&str] = match d.driver {
            DriverSpec::Orbit => &["target", "radius", "elevation_deg", "azimuth_deg"],
            DriverSpec::Animation => &["animation", "time"],
            DriverSpec::LightPath => &["light", "path", "range"],
        };
        if let Some((key, _)) = present.iter().find(|(k, p)| *p && !allowed.contains(k)) {
            return Err(SceneError::invalid(
                path,
                field(key),
                format!("key not used by driver {:?}", d.driver),
            ));
        }
        let required = |key: &str| {
            SceneError::invalid(path, field(key), format!("required by driver {:?}", d.driver))
        };
        let periodic = d.periodic.unwrap_or(false);
        let check_kind = |expected: KindSpec| match d.kind {
            Some(k) if k != expected => Err(SceneError::invalid(
                path,
                field("kind"),
                format!("driver {:?} always has kind {:?}", d.driver, expected),
            )),
            _ => Ok(kind_of(expected)),
        };
        let (kind, unit, range, driver) = match d.driver {
            DriverSpec::Orbit => {
                orbits += 1;
                if orbits > 1 {
                    return Err(SceneError::invalid(
                        path,
                        field("driver"),
                        "only one orbit dimension may move the camera",
                    ));
                }
                let target = Vec3::from(d.target.ok_or_else(|| required("target"))?);
                let radius = d.radius.ok_or_else(|| required("radius"))?;
                if radius <= 0.0 {
                    return Err(SceneError::invalid(
                        path,
                        field("radius"),
                        format!("must be > 0, found {radius}"),
                    ));
                }
                let elevation_deg = d.elevation_deg.unwrap_or(0.0);
                let range = d.azimuth_deg.ok_or_else(|| required("azimuth_deg"))?;
                (
                    check_kind(KindSpec::View)?,
                    "deg",
                    (range, "azimuth_deg"),
                    Driver::Orbit { target, radius, elevation_deg },
                )
            }
            DriverSpec::Animation => {
                let name = d.animation.as_deref().ok_or_else(|| required("animation"))?;
                if let Some((f, why)) = g.unsupported_animations.get(name) {
                    return Err(SceneError::unsupported(
                        path,
                        f.clone(),
                        format!("animation `{name}`: {why}"),
                    ));
                }
                let Some(anim) = g.rig.animations.iter().find(|a| a.name == name) else {
                    let known = g.rig.animations.iter().map(|a| a.name.as_str());
                    return Err(SceneError::unknown(
                        path,
                        field("animation"),
                        "animation",
                        name,
                        known,
                    ));
                };
                let (t0, t1) = anim.time_range();
                let range = d.time.unwrap_or([t0, t1]);
                let kind = kind_of(d.kind.unwrap_or(KindSpec::Time));
                (kind, "s", (range, "time"), Driver::Animation { animation: name.to_owned() })
            }
            DriverSpec::LightPath => {
                let name = d.light.as_deref().ok_or_else(|| required("light"))?;
                if !g.rig.lights.iter().any(|l| l.name == name || g.rig.nodes[l.node].name == name)
                {
                    let known = g.rig.lights.iter().map(|l| l.name.as_str());
                    return Err(SceneError::unknown(path, field("light"), "light", name, known));
                }
                let pts: Vec<Vec3> = d
                    .path
                    .as_ref()
                    .ok_or_else(|| required("path"))?
                    .iter()
                    .map(|&p| Vec3::from(p))
                    .collect();
                if pts.is_empty() {
                    return Err(SceneError::invalid(
                        path,
                        field("path"),
                        "needs at least one point",
                    ));
                }
                let range = d.range.unwrap_or([0.0, 1.0]);
                (
                    check_kind(KindSpec::Light)?,
                    "",
                    (range, "range"),
                    Driver::LightPath { light: name.to_owned(), path: pts },
                )
            }
        };
        let ([a, b], range_key) = range;
        if d.samples > 1 && b <= a {
            return Err(SceneError::invalid(
                path,
                field(range_key),
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
    Ok(ParameterSpace { dims })
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
