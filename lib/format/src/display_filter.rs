//! The display filter of the ray-traced set a file was made from (SPEC.md 6.6): the
//! `display_filter`, `display_filter_sigma_px` and `display_filter_radius_px` provenance
//! settings. The gold standard's pixels are that filter's weighted means of sub-pixel
//! samples (RAYSET.md section 4), so a player that keeps several samples per pixel resolves
//! them with it to mix silhouettes as the gold standard does.

use crate::model::Provenance;

/// The setting naming the filter: `gaussian`.
pub const DISPLAY_FILTER_SETTING: &str = "display_filter";
/// The Gaussian's standard deviation in display pixels (decimal text, finite, > 0).
pub const DISPLAY_FILTER_SIGMA_SETTING: &str = "display_filter_sigma_px";
/// The truncation radius in display pixels (decimal text, finite, > 0).
pub const DISPLAY_FILTER_RADIUS_SETTING: &str = "display_filter_radius_px";
/// The largest σ and R a file may record, in pixels: a filter wider than this is not a
/// display filter (and no player's neighbourhood reaches that far).
pub const MAX_DISPLAY_FILTER_PX: f32 = 64.0;

/// A truncated, radially symmetric Gaussian centred on the pixel centre:
/// w(d) = exp(−|d|² / 2σ²) for |d| ≤ R, 0 beyond (RAYSET.md section 4).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DisplayFilter {
    pub sigma_px: f32,
    pub radius_px: f32,
}

impl DisplayFilter {
    /// Checks σ and R: finite, positive, at most [`MAX_DISPLAY_FILTER_PX`].
    pub fn new(sigma_px: f32, radius_px: f32) -> Result<DisplayFilter, String> {
        let ok = |v: f32| v.is_finite() && v > 0.0 && v <= MAX_DISPLAY_FILTER_PX;
        if !ok(sigma_px) {
            return Err(format!("{DISPLAY_FILTER_SIGMA_SETTING} {sigma_px} is not a number of pixels in (0, {MAX_DISPLAY_FILTER_PX}]"));
        }
        if !ok(radius_px) {
            return Err(format!("{DISPLAY_FILTER_RADIUS_SETTING} {radius_px} is not a number of pixels in (0, {MAX_DISPLAY_FILTER_PX}]"));
        }
        Ok(DisplayFilter { sigma_px, radius_px })
    }

    /// The settings recording this filter.
    pub fn settings(self) -> Vec<(String, String)> {
        vec![
            (DISPLAY_FILTER_SETTING.to_string(), "gaussian".to_string()),
            (DISPLAY_FILTER_SIGMA_SETTING.to_string(), self.sigma_px.to_string()),
            (DISPLAY_FILTER_RADIUS_SETTING.to_string(), self.radius_px.to_string()),
        ]
    }

    /// The display filter the provenance settings record (rule 9002): none without a
    /// `display_filter` setting; an error naming what is wrong for an unknown filter, a
    /// missing or malformed σ or R, or σ or R without `display_filter`.
    pub fn of(p: Option<&Provenance>) -> Result<Option<DisplayFilter>, String> {
        let get = |k: &str| p.and_then(|p| p.setting(k));
        let number = |k: &str| -> Result<f32, String> {
            let v = get(k).ok_or_else(|| {
                format!("{DISPLAY_FILTER_SETTING} \"gaussian\" without a {k} setting")
            })?;
            v.trim().parse::<f32>().map_err(|_| format!("{k} {v:?} is not a decimal number"))
        };
        match get(DISPLAY_FILTER_SETTING) {
            None => match [DISPLAY_FILTER_SIGMA_SETTING, DISPLAY_FILTER_RADIUS_SETTING]
                .into_iter()
                .find(|k| get(k).is_some())
            {
                Some(k) => Err(format!("{k} without a {DISPLAY_FILTER_SETTING} setting")),
                None => Ok(None),
            },
            Some("gaussian") => DisplayFilter::new(
                number(DISPLAY_FILTER_SIGMA_SETTING)?,
                number(DISPLAY_FILTER_RADIUS_SETTING)?,
            )
            .map(Some),
            Some(other) => Err(format!("unknown {DISPLAY_FILTER_SETTING} {other:?} (gaussian)")),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::filter::tests::prov;

    #[test]
    fn settings_round_trip() {
        for f in [
            DisplayFilter { sigma_px: 0.5, radius_px: 1.5 },
            DisplayFilter { sigma_px: 0.3333, radius_px: 2.0 },
        ] {
            let s = f.settings();
            let p = prov(&s.iter().map(|(k, v)| (k.as_str(), v.as_str())).collect::<Vec<_>>());
            assert_eq!(DisplayFilter::of(Some(&p)), Ok(Some(f)));
        }
        assert_eq!(DisplayFilter::of(None), Ok(None));
        assert_eq!(DisplayFilter::of(Some(&prov(&[("filter", "trilinear")]))), Ok(None));
    }

    #[test]
    fn malformed_settings_are_refused() {
        let g = ("display_filter", "gaussian");
        for bad in [
            vec![("display_filter", "box")],
            vec![
                ("display_filter", "Gaussian"),
                ("display_filter_sigma_px", "0.5"),
                ("display_filter_radius_px", "1.5"),
            ],
            vec![g],
            vec![g, ("display_filter_sigma_px", "0.5")],
            vec![g, ("display_filter_radius_px", "1.5")],
            vec![g, ("display_filter_sigma_px", "half"), ("display_filter_radius_px", "1.5")],
            vec![g, ("display_filter_sigma_px", "0"), ("display_filter_radius_px", "1.5")],
            vec![g, ("display_filter_sigma_px", "-0.5"), ("display_filter_radius_px", "1.5")],
            vec![g, ("display_filter_sigma_px", "NaN"), ("display_filter_radius_px", "1.5")],
            vec![g, ("display_filter_sigma_px", "0.5"), ("display_filter_radius_px", "inf")],
            vec![g, ("display_filter_sigma_px", "0.5"), ("display_filter_radius_px", "1e9")],
            vec![("display_filter_sigma_px", "0.5")],
        ] {
            let e = DisplayFilter::of(Some(&prov(&bad))).expect_err(&format!("{bad:?}"));
            assert!(e.contains("display_filter"), "{bad:?}: {e}");
        }
    }
}
