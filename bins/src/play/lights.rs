//! pis-play's lights for a relightable file (SPEC.md 6.6): `--light AZ,EL,R,G,B` (any
//! number), `--sky FILE` with `--sky-rotation` and `--sky-strength`, parsed and built into
//! the player's [`Lights`]; the window's Lights panel builds its lights with the same
//! functions.
//!
//! A light's direction is given as an azimuth φ, measured from +X towards +Z, and an
//! elevation above the horizon (world +Y up): d = (cos el·cos φ, sin el, cos el·sin φ),
//! pointing from the scene towards the light.

use std::path::{Path, PathBuf};

use glam::Vec3;
use pis_compile::relight::{project_lat_long, rotate_about_pole, MAX_BAND};
use pis_format::relight::LightDirections;
use pis_play::{DirectionalLight, Lights, Player};

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
            direction: direction(self.azimuth_deg, self.elevation_deg),
            radiance: self.radiance,
        }
    }
}

/// The unit direction towards a light at `azimuth_deg` (from +X towards +Z) and
/// `elevation_deg` (above the horizon).
pub fn direction(azimuth_deg: f32, elevation_deg: f32) -> Vec3 {
    let (sin_az, cos_az) = azimuth_deg.to_radians().sin_cos();
    let (sin_el, cos_el) = elevation_deg.to_radians().sin_cos();
    Vec3::new(cos_el * cos_az, sin_el, cos_el * sin_az)
}

/// A direction's azimuth (degrees from +X towards +Z, −180 to 180) and elevation (degrees
/// above the horizon); a direction straight up or down has azimuth 0.
pub fn azimuth_elevation(d: Vec3) -> (f32, f32) {
    let d = d.normalize_or(Vec3::Y);
    let elevation = d.y.clamp(-1.0, 1.0).asin().to_degrees();
    let azimuth = if d.x.hypot(d.z) < 1e-6 { 0.0 } else { d.z.atan2(d.x).to_degrees() };
    (azimuth, elevation)
}

/// The light directions of the player's file where it is relightable: where it has layers of
/// coefficients over them (SPEC.md 7.1), not only the directions a set was traced over.
pub fn relightable(player: &Player) -> Option<&LightDirections> {
    let c = player.reader().container();
    let coefficients = c.objects.iter().flat_map(|o| &o.layers).any(|l| l.basis != 0);
    player.light_directions().filter(|_| coefficients)
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

/// The largest sky image projected as it is (the projection's time grows with the texels: a
/// few seconds at this size). A larger one is averaged down to this size first
/// ([`reduce_lat_long`]): its power is kept, and a small bright source moves by at most half
/// a texel (0.18°), where the basis's finest band varies over some 20°.
pub const SKY_PROJECTED_SIZE: (usize, usize) = (1024, 512);

/// Reads an equirectangular `.exr` or `.hdr` sky and projects it into the player's basis
/// (every band the player holds), unturned; the error names the file.
pub fn load_sky(path: &Path) -> Result<Vec<[f64; 3]>, String> {
    let (w, h, texels) =
        pis_scene::read_environment_image(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let rgb: Vec<f32> = texels.iter().flatten().copied().collect();
    let (w, h, rgb) = reduce_lat_long(w as usize, h as usize, &rgb, SKY_PROJECTED_SIZE);
    Ok(project_lat_long(w, h, &rgb, 0.0, MAX_BAND))
}

/// Each output cell's source cells and their weights along one axis: the overlap of the
/// cells' spans, measured by `measure` (the weights of an output cell sum to 1).
fn overlaps(n: usize, m: usize, measure: impl Fn(f64, f64) -> f64) -> Vec<Vec<(usize, f64)>> {
    (0..m)
        .map(|j| {
            let (a, b) = (j as f64 / m as f64, (j + 1) as f64 / m as f64);
            let first = ((a * n as f64).floor() as usize).min(n - 1);
            let last = ((b * n as f64).ceil() as usize).clamp(first + 1, n);
            let whole = measure(a, b);
            (first..last)
                .filter_map(|k| {
                    let lo = a.max(k as f64 / n as f64);
                    let hi = b.min((k + 1) as f64 / n as f64);
                    (hi > lo && whole > 0.0).then(|| (k, measure(lo, hi) / whole))
                })
                .collect()
        })
        .collect()
}

/// A `width × height` lat-long RGB image (rows from the top) averaged down to at most
/// `max` (width, height): each new texel is the mean radiance over its solid angle (columns
/// by azimuth, rows by cos θ), so the image's power and its coefficients up to bands far
/// coarser than a texel are kept. An image within `max` is returned as it is.
pub fn reduce_lat_long(
    width: usize,
    height: usize,
    rgb: &[f32],
    max: (usize, usize),
) -> (usize, usize, Vec<f32>) {
    let (w, h) = (width.min(max.0.max(1)), height.min(max.1.max(1)));
    if (w, h) == (width, height) || width == 0 || height == 0 {
        return (width, height, rgb.to_vec());
    }
    let cols = overlaps(width, w, |a, b| b - a);
    let polar = |t: f64| (std::f64::consts::PI * t).cos();
    let rows = overlaps(height, h, |a, b| polar(a) - polar(b));
    let mut out = vec![0.0f32; w * h * 3];
    for (i, row) in rows.iter().enumerate() {
        for (j, col) in cols.iter().enumerate() {
            let mut sum = [0.0f64; 3];
            for &(k, wk) in row {
                for &(l, wl) in col {
                    let texel = &rgb[(k * width + l) * 3..][..3];
                    for ch in 0..3 {
                        sum[ch] += wk * wl * texel[ch] as f64;
                    }
                }
            }
            for ch in 0..3 {
                out[(i * w + j) * 3 + ch] = sum[ch] as f32;
            }
        }
    }
    (w, h, out)
}

/// A projected sky (as [`load_sky`] gives it) turned `rotation_deg` about +Y by the
/// right-hand rule (scene.toml's `[environment] rotation_deg`: 90 moves the image centre from
/// +X to −Z) and scaled by `strength`.
pub fn sky_coefficients(projected: &[[f64; 3]], rotation_deg: f32, strength: f32) -> Vec<[f64; 3]> {
    let turned = if rotation_deg == 0.0 {
        projected.to_vec()
    } else {
        rotate_about_pole(projected, rotation_deg.to_radians())
    };
    turned.into_iter().map(|c| c.map(|v| v * strength as f64)).collect()
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
    fn azimuth_runs_from_x_towards_z_and_elevation_from_the_horizon() {
        assert!(close(direction(0.0, 0.0), Vec3::X));
        assert!(close(direction(90.0, 0.0), Vec3::Z));
        assert!(close(direction(180.0, 0.0), Vec3::NEG_X));
        assert!(close(direction(-90.0, 0.0), Vec3::NEG_Z));
        assert!(close(direction(123.0, 90.0), Vec3::Y));
        let d = direction(40.0, 50.0);
        assert!((d.length() - 1.0).abs() < 1e-6 && (d.y - 50f32.to_radians().sin()).abs() < 1e-6);
        let (az, el) = azimuth_elevation(d);
        assert!((az - 40.0).abs() < 1e-4 && (el - 50.0).abs() < 1e-4, "{az} {el}");
        let (az, el) = azimuth_elevation(direction(-120.0, -30.0));
        assert!((az + 120.0).abs() < 1e-4 && (el + 30.0).abs() < 1e-4, "{az} {el}");
        assert_eq!(azimuth_elevation(Vec3::Y), (0.0, 90.0));
        let light = parse_light("90,0,1,2,3").unwrap().light();
        assert!(close(light.direction, Vec3::Z) && light.radiance == [1.0, 2.0, 3.0]);
    }

    /// A small sky with structure in several bands.
    fn projected() -> Vec<[f64; 3]> {
        let (w, h) = (32, 16);
        let mut rgb = vec![0.1f32; w * h * 3];
        rgb[(4 * w + 5) * 3] = 5.0;
        rgb[(6 * w + 20) * 3 + 1] = 3.0;
        project_lat_long(w, h, &rgb, 0.0, 4)
    }

    #[test]
    fn sky_strength_scales_the_coefficients() {
        let s = projected();
        assert_eq!(sky_coefficients(&s, 0.0, 1.0), s);
        let doubled = sky_coefficients(&s, 0.0, 2.5);
        for (a, b) in doubled.iter().zip(&s) {
            for ch in 0..3 {
                assert!((a[ch] - 2.5 * b[ch]).abs() <= 1e-12 * b[ch].abs().max(1.0));
            }
        }
        assert!(sky_coefficients(&s, 30.0, 0.0).iter().flatten().all(|v| *v == 0.0));
    }

    #[test]
    fn sky_rotation_turns_the_projection_about_the_pole() {
        let s = projected();
        let (w, h) = (32, 16);
        let mut rgb = vec![0.1f32; w * h * 3];
        rgb[(4 * w + 5) * 3] = 5.0;
        rgb[(6 * w + 20) * 3 + 1] = 3.0;
        for deg in [90.0f32, -35.0] {
            let turned = sky_coefficients(&s, deg, 2.0);
            let direct = project_lat_long(w, h, &rgb, deg.to_radians(), 4);
            for (a, b) in turned.iter().zip(&direct) {
                for ch in 0..3 {
                    assert!((a[ch] - 2.0 * b[ch]).abs() < 4e-3, "{deg}°: {a:?} against {b:?}");
                }
            }
        }
    }

    #[test]
    fn a_large_sky_is_averaged_down_keeping_its_projection() {
        let (w, h) = (300, 150);
        let rgb: Vec<f32> = (0..w * h * 3)
            .map(|i| {
                let (row, col) = (i / 3 / w, i / 3 % w);
                let sun =
                    if (40..44).contains(&row) && (70..73).contains(&col) { 400.0 } else { 0.0 };
                0.2 + 0.5 * ((col as f32 / 9.0).sin() * (row as f32 / 7.0).cos()).abs() + sun
            })
            .collect();
        let (rw, rh, reduced) = reduce_lat_long(w, h, &rgb, (128, 64));
        assert_eq!((rw, rh, reduced.len()), (128, 64, 128 * 64 * 3));
        let full = project_lat_long(w, h, &rgb, 0.0, 8);
        let small = project_lat_long(rw, rh, &reduced, 0.0, 8);
        let scale = full.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
        assert!((full[0][0] - small[0][0]).abs() < 1e-4 * full[0][0], "the power is kept");
        for (c, (a, b)) in full.iter().zip(&small).enumerate() {
            for ch in 0..3 {
                assert!(
                    (a[ch] - b[ch]).abs() < 0.01 * scale,
                    "coefficient {c}: {a:?} against {b:?}"
                );
            }
        }
        // A uniform sky stays uniform; an image within the size is kept as it is.
        let (_, _, flat) = reduce_lat_long(90, 45, &vec![2.0; 90 * 45 * 3], (32, 16));
        assert!(flat.iter().all(|v| (v - 2.0).abs() < 1e-5));
        assert_eq!(reduce_lat_long(4, 2, &[1.0; 24], (8, 4)), (4, 2, vec![1.0; 24]));
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
        assert!(close(lights.directional[0].direction, direction(40.0, 50.0)));
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
