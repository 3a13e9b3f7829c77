//! pis-play's lights for a relightable file (SPEC.md 6.6): `--light AZ,EL,R,G,B` (any
//! number), `--sky FILE` with `--sky-rotation` and `--sky-strength`, parsed and built into
//! the player's [`Lights`]; the window's Lights panel builds its lights with the same
//! functions.
//!
//! A light's direction is given as an azimuth φ, measured from +X towards +Z, and an
//! elevation above the horizon (world +Y up): d = (cos el·cos φ, sin el, cos el·sin φ),
//! pointing from the scene towards the light.

use std::path::{Path, PathBuf};

use pis_compile::relight::{direction_at, load_sky, sky_coefficients};
use pis_play::{DirectionalLight, Lights};

use crate::cli::{Exit, Failure};

/// One `--light`: where it comes from and its colour × intensity.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightSpec {
    /// Degrees from +X towards +Z.
    pub azimuth_deg: f32,
    /// Degrees above the horizon, −90 to 90.
    pub elevation_deg: f32,
    /// Linear RGB colour × intensity, in the units of the file's traced light (E₀).
    pub radiance: [f32; 3],
}

impl LightSpec {
    /// The player's light.
    pub fn light(&self) -> DirectionalLight {
        DirectionalLight {
            direction: direction_at(self.azimuth_deg, self.elevation_deg),
            radiance: self.radiance,
        }
    }
}

/// `--light`'s parser: `AZ,EL,R,G,B`, degrees then linear colour × intensity.
pub fn parse_light(s: &str) -> Result<LightSpec, String> {
    let expected = || {
        format!(
            "expected AZ,EL,R,G,B: azimuth and elevation in degrees (elevation −90 to 90), then \
             the linear colour × intensity (each 0 or more), e.g. 40,50,2.5,1.9,1.2; got {s:?}"
        )
    };
    let v: Vec<f32> = s
        .split(',')
        .map(|p| p.trim().parse::<f32>().ok().filter(|x| x.is_finite()))
        .collect::<Option<_>>()
        .ok_or_else(expected)?;
    match v.as_slice() {
        &[az, el, r, g, b] if (-90.0..=90.0).contains(&el) && r >= 0.0 && g >= 0.0 && b >= 0.0 => {
            Ok(LightSpec { azimuth_deg: az, elevation_deg: el, radiance: [r, g, b] })
        }
        _ => Err(expected()),
    }
}

/// `--sky-rotation`'s parser: finite degrees.
pub fn parse_degrees(s: &str) -> Result<f32, String> {
    s.trim()
        .parse::<f32>()
        .ok()
        .filter(|x| x.is_finite())
        .ok_or_else(|| format!("expected an angle in degrees, got {s:?}"))
}

/// `--sky-strength`'s parser: a factor, 0 or more.
pub fn parse_strength(s: &str) -> Result<f32, String> {
    s.trim()
        .parse::<f32>()
        .ok()
        .filter(|x| x.is_finite() && *x >= 0.0)
        .ok_or_else(|| format!("expected a factor, 0 or more, got {s:?}"))
}

/// The lights of the command line.
#[derive(clap::Args, Debug, Clone, Default, PartialEq)]
pub struct LightArgs {
    /// Relight the file (one with relightable layers) with a directional light: azimuth
    /// (degrees from +X towards +Z), elevation (degrees above the horizon, +Y up), and its
    /// linear colour × intensity in the units of the file's traced light; repeat for more
    /// lights. The frames (and the window's start) show exactly the lights and sky given
    /// instead of the file's own light.
    #[arg(
        long = "light",
        value_name = "AZ,EL,R,G,B",
        value_parser = parse_light,
        allow_hyphen_values = true,
        conflicts_with = "compare"
    )]
    pub lights: Vec<LightSpec>,
    /// Relight the file with a sky: an equirectangular .exr or .hdr radiance image (as
    /// scene.toml's [environment] image), alone or with --light.
    #[arg(long, value_name = "FILE", conflicts_with = "compare")]
    pub sky: Option<PathBuf>,
    /// Turn the --sky image about +Y by the right-hand rule, as scene.toml's [environment]
    /// rotation_deg (90 moves the image centre from +X to −Z).
    #[arg(long, value_name = "DEG", default_value_t = 0.0, requires = "sky", allow_hyphen_values = true, value_parser = parse_degrees)]
    pub sky_rotation: f32,
    /// Scale the --sky image's radiance by this factor.
    #[arg(long, value_name = "X", default_value_t = 1.0, requires = "sky", value_parser = parse_strength)]
    pub sky_strength: f32,
}

impl LightArgs {
    /// Whether any light or a sky is given.
    pub fn given(&self) -> bool {
        !self.lights.is_empty() || self.sky.is_some()
    }

    /// The flag that asked for relighting, for messages.
    fn flag(&self) -> &'static str {
        if self.lights.is_empty() {
            "--sky"
        } else {
            "--light"
        }
    }

    /// Refuses the lights for `file` when it is not relightable.
    pub fn check(&self, file: &Path, relightable: bool) -> Result<(), Failure> {
        if !self.given() || relightable {
            return Ok(());
        }
        Err(Failure::new(
            Exit::Usage,
            anyhow::anyhow!(
                "{}: {} has no relightable layers (layers of coefficients over light \
                 directions, SPEC.md 7.1), so it plays only under its own light; a set traced over \
                 light directions packs into one with pis-pack --relight on (the default)",
                self.flag(),
                file.display()
            ),
        ))
    }

    /// The `--sky` image projected into the player's basis, unturned (none without `--sky`).
    pub fn read_sky(&self) -> Result<Option<Vec<[f64; 3]>>, Failure> {
        let Some(path) = &self.sky else { return Ok(None) };
        let exit = if path.is_file() { Exit::Invalid } else { Exit::Io };
        load_sky(path).map(Some).map_err(|m| Failure::new(exit, anyhow::anyhow!("--sky {m}")))
    }

    /// The lights given, for `file` (relightable or not): none where none are given, an
    /// error where the file cannot be relit or the sky cannot be read.
    pub fn relight(&self, file: &Path, relightable: bool) -> Result<Option<Lights>, Failure> {
        self.check(file, relightable)?;
        if !self.given() {
            return Ok(None);
        }
        let sky = self.read_sky()?;
        Ok(Some(self.lights_with(sky.as_deref())))
    }

    /// The lights given, with the `--sky` image's projection `sky` (unturned, as
    /// [`load_sky`] gives it).
    pub fn lights_with(&self, sky: Option<&[[f64; 3]]>) -> Lights {
        Lights {
            directional: self.lights.iter().map(LightSpec::light).collect(),
            sky: sky.map(|s| sky_coefficients(s, self.sky_rotation, self.sky_strength)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;
    use pis_compile::relight::project_lat_long;

    fn close(a: Vec3, b: Vec3) -> bool {
        (a - b).length() < 1e-6
    }

    #[test]
    fn a_light_spec_parses_and_bad_ones_say_what_was_expected() {
        assert_eq!(
            parse_light("40,50,2.5,1.9,1.2"),
            Ok(LightSpec { azimuth_deg: 40.0, elevation_deg: 50.0, radiance: [2.5, 1.9, 1.2] })
        );
        assert_eq!(parse_light(" -120, 30,0.7,0.9,1.5").unwrap().azimuth_deg, -120.0);
        for bad in ["", "40,50,2.5,1.9", "40,50,2.5,1.9,1.2,1", "a,50,1,1,1", "0,91,1,1,1"] {
            let err = parse_light(bad).unwrap_err();
            assert!(err.contains("expected AZ,EL,R,G,B") && err.contains(&format!("{bad:?}")));
        }
        assert!(parse_light("0,45,1,-1,1").is_err(), "a negative colour");
        assert!(parse_light("NaN,45,1,1,1").is_err());
        assert!(parse_light("0,inf,1,1,1").is_err());
        assert_eq!(parse_strength("2"), Ok(2.0));
        assert!(parse_strength("-1").unwrap_err().contains("expected a factor"));
        assert_eq!(parse_degrees("-90"), Ok(-90.0));
        assert!(parse_degrees("east").unwrap_err().contains("degrees"));
    }

    #[test]
    fn a_light_spec_is_a_light_from_its_azimuth_and_elevation() {
        let light = parse_light("90,0,1,2,3").unwrap().light();
        assert!(close(light.direction, Vec3::Z) && light.radiance == [1.0, 2.0, 3.0]);
    }

    /// A small sky with structure in several bands.
    fn projected() -> Vec<[f64; 3]> {
        let (w, h) = (32, 16);
        let mut rgb = vec![0.1f32; w * h * 3];
        rgb[(4 * w + 5) * 3] = 5.0;
        project_lat_long(w, h, &rgb, 0.0, 4)
    }

    #[test]
    fn the_command_line_lights_are_the_lights_and_the_sky_given() {
        let args = LightArgs {
            lights: vec![parse_light("40,50,2.5,1.9,1.2").unwrap()],
            sky: Some(PathBuf::from("sky.exr")),
            sky_rotation: 90.0,
            sky_strength: 0.5,
        };
        let s = projected();
        let lights = args.lights_with(Some(&s));
        assert_eq!(lights.directional.len(), 1);
        assert!(close(lights.directional[0].direction, direction_at(40.0, 50.0)));
        assert_eq!(lights.sky, Some(sky_coefficients(&s, 90.0, 0.5)));
        assert!(LightArgs::default().relight(Path::new("f.pis"), false).unwrap().is_none());
        let err = args.check(Path::new("f.pis"), false).unwrap_err();
        assert_eq!(err.exit, Exit::Usage);
        let m = err.error.to_string();
        assert!(m.starts_with("--light: f.pis") && m.contains("no relightable layers"), "{m}");
        let sky_only = LightArgs { lights: Vec::new(), ..args.clone() };
        assert!(sky_only
            .check(Path::new("f.pis"), false)
            .unwrap_err()
            .error
            .to_string()
            .starts_with("--sky: f.pis"));
        assert!(args.check(Path::new("f.pis"), true).is_ok());
        let missing = sky_only.read_sky().unwrap_err();
        assert_eq!(missing.exit, Exit::Io);
        assert!(missing.error.to_string().contains("sky.exr"));
    }
}
