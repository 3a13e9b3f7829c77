//! The texture filter a file's textures were solved for (SPEC.md 6.6): the `filter` and
//! `anisotropy` provenance settings, which players read to draw the textures as the writer
//! measured them.

use crate::model::Provenance;

/// The setting naming the filter: `nearest`, `bilinear`, `trilinear` or `anisotropic`.
pub const FILTER_SETTING: &str = "filter";
/// The setting holding the anisotropy clamp of `anisotropic` (decimal 1 to 16).
pub const ANISOTROPY_SETTING: &str = "anisotropy";
/// The prefix of the settings naming one object's filter; the object's name follows.
pub const OBJECT_FILTER_PREFIX: &str = "filter.";
/// The largest anisotropy clamp (WebGPU and Vulkan samplers: 16).
pub const MAX_ANISOTROPY: u8 = 16;

/// The texture filter of a file.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum FileFilter {
    Nearest,
    Bilinear,
    /// Also what a file without a `filter` setting is drawn with.
    #[default]
    Trilinear,
    /// Trilinear lookups along the footprint's major axis, at most this many (1..=16).
    Anisotropic(u8),
}

impl FileFilter {
    /// The `filter` setting's value.
    pub fn name(self) -> &'static str {
        match self {
            FileFilter::Nearest => "nearest",
            FileFilter::Bilinear => "bilinear",
            FileFilter::Trilinear => "trilinear",
            FileFilter::Anisotropic(_) => "anisotropic",
        }
    }

    /// The settings recording this filter (the anisotropy only for `anisotropic`).
    pub fn settings(self) -> Vec<(String, String)> {
        let mut s = vec![(FILTER_SETTING.to_string(), self.name().to_string())];
        if let FileFilter::Anisotropic(n) = self {
            s.push((ANISOTROPY_SETTING.to_string(), n.to_string()));
        }
        s
    }

    /// The filter the provenance settings record (rule 9001): trilinear without a `filter`
    /// setting; an error naming what is wrong for an unknown name, or an `anisotropic`
    /// filter without an anisotropy of 1 to 16.
    pub fn of(p: Option<&Provenance>) -> Result<FileFilter, String> {
        match p.and_then(|p| p.setting(FILTER_SETTING)) {
            None => Ok(FileFilter::Trilinear),
            Some(name) => FileFilter::named(name, p.and_then(|p| p.setting(ANISOTROPY_SETTING))),
        }
    }

    /// The filter of the setting value `name`, with the `anisotropy` setting's value.
    fn named(name: &str, anisotropy: Option<&str>) -> Result<FileFilter, String> {
        match name {
            "trilinear" => Ok(FileFilter::Trilinear),
            "nearest" => Ok(FileFilter::Nearest),
            "bilinear" => Ok(FileFilter::Bilinear),
            "anisotropic" => match anisotropy.map(|v| v.parse::<u8>()) {
                Some(Ok(n)) if (1..=MAX_ANISOTROPY).contains(&n) => Ok(FileFilter::Anisotropic(n)),
                Some(_) => Err(format!(
                    "{ANISOTROPY_SETTING} {:?} is not an integer from 1 to {MAX_ANISOTROPY}",
                    anisotropy.unwrap_or("")
                )),
                None => {
                    Err(format!("filter \"anisotropic\" without an {ANISOTROPY_SETTING} setting"))
                }
            },
            other => Err(format!(
                "unknown filter {other:?} (nearest, bilinear, trilinear or anisotropic)"
            )),
        }
    }

    /// The setting recording that object `object`'s textures were solved for this filter
    /// rather than the file's (`filter.<object name>`; an anisotropic one takes the file's
    /// `anisotropy`).
    pub fn object_setting(self, object: &str) -> (String, String) {
        (format!("{OBJECT_FILTER_PREFIX}{object}"), self.name().to_string())
    }

    /// Per object (`objects`: their names in file order), the filter its textures are drawn
    /// with (rule 9001): its `filter.<name>` setting, else the file's filter. An error names
    /// a setting that names no object, or whose value the file's `filter` could not take.
    pub fn per_object(p: Option<&Provenance>, objects: &[&str]) -> Result<Vec<FileFilter>, String> {
        let mut out = vec![FileFilter::of(p)?; objects.len()];
        let Some(p) = p else { return Ok(out) };
        for (k, v) in &p.settings {
            let Some(name) = k.strip_prefix(OBJECT_FILTER_PREFIX) else { continue };
            let o = objects
                .iter()
                .position(|&o| o == name)
                .ok_or_else(|| format!("{k}: no object is named {name:?}"))?;
            out[o] = FileFilter::named(v, p.setting(ANISOTROPY_SETTING))
                .map_err(|e| format!("{k}: {e}"))?;
        }
        Ok(out)
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// Provenance with just these settings (also for the display filter's tests).
    pub(crate) fn prov(settings: &[(&str, &str)]) -> Provenance {
        Provenance {
            tool: "t".into(),
            source: "s".into(),
            raw_image_bytes: 0,
            settings: settings.iter().map(|(k, v)| (k.to_string(), v.to_string())).collect(),
        }
    }

    #[test]
    fn settings_round_trip() {
        for f in [
            FileFilter::Nearest,
            FileFilter::Bilinear,
            FileFilter::Trilinear,
            FileFilter::Anisotropic(1),
            FileFilter::Anisotropic(16),
        ] {
            let s = f.settings();
            let p = prov(&s.iter().map(|(k, v)| (k.as_str(), v.as_str())).collect::<Vec<_>>());
            assert_eq!(FileFilter::of(Some(&p)), Ok(f));
        }
        assert_eq!(FileFilter::of(None), Ok(FileFilter::Trilinear));
        assert_eq!(FileFilter::of(Some(&prov(&[("codec", "raw")]))), Ok(FileFilter::Trilinear));
    }

    #[test]
    fn bad_settings_are_refused() {
        for bad in [
            vec![("filter", "cubic")],
            vec![("filter", "Trilinear")],
            vec![("filter", "anisotropic")],
            vec![("filter", "anisotropic"), ("anisotropy", "0")],
            vec![("filter", "anisotropic"), ("anisotropy", "17")],
            vec![("filter", "anisotropic"), ("anisotropy", "4.5")],
        ] {
            assert!(FileFilter::of(Some(&prov(&bad))).is_err(), "{bad:?}");
        }
    }

    #[test]
    fn an_object_may_have_a_filter_of_its_own() {
        let objects = ["Box", "Floor"];
        let (k, v) = FileFilter::Bilinear.object_setting("Box");
        let p = prov(&[(k.as_str(), v.as_str())]);
        assert_eq!(
            FileFilter::per_object(Some(&p), &objects),
            Ok(vec![FileFilter::Bilinear, FileFilter::Trilinear])
        );
        assert_eq!(FileFilter::per_object(None, &objects), Ok(vec![FileFilter::Trilinear; 2]));
        let p = prov(&[("filter", "bilinear"), ("filter.Floor", "trilinear")]);
        assert_eq!(
            FileFilter::per_object(Some(&p), &objects),
            Ok(vec![FileFilter::Bilinear, FileFilter::Trilinear])
        );
        for (bad, says) in [
            (vec![("filter.Lamp", "bilinear")], "no object"),
            (vec![("filter.Box", "cubic")], "unknown filter"),
            (vec![("filter.Box", "anisotropic")], "anisotropy"),
            (vec![("filter", "cubic")], "unknown filter"),
        ] {
            let e = FileFilter::per_object(Some(&prov(&bad)), &objects).unwrap_err();
            assert!(e.contains(says), "{bad:?}: {e}");
        }
        let p = prov(&[("filter.Box", "anisotropic"), ("anisotropy", "8")]);
        assert_eq!(
            FileFilter::per_object(Some(&p), &objects).unwrap()[0],
            FileFilter::Anisotropic(8)
        );
    }
}
