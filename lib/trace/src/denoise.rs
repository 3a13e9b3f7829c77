//! Denoised layers (RAYSET.md 5.4): every radiance layer the inference reads, and the
//! combined image, denoised with Open Image Denoise guided by the albedo and normal at the
//! first non-specular hit.
//!
//! **Segmented layers.** An object's layer is divided by its coverage; it is denoised
//! premultiplied (layer × coverage), where every pixel the object does not cover is 0, so the
//! filter sees the object's own radiance fading to black at its silhouette and nothing of
//! the objects beside it. The result is cleared where the coverage is 0 and divided by the
//! coverage again. Only the rectangle the object covers (and a margin) is filtered.
//!
//! **Never worse.** A denoised layer must not be further from the converged image than the
//! raw one. The render keeps its even and odd samples apart: two independent half images A
//! and B, each from its own rotation of the sample sequence. Per layer and object, over the
//! pixels both halves cover, as the layer is read (divided by coverage), each difference
//! taken as what it changes of the object's surface on display (sRGB, clipped at white: the
//! surface radiance, diffuse + specular, with the layer's value swapped; `local` and
//! `distant` enter times their Fresnel modulation), so that each layer's error counts as much
//! as it moves what is seen:
//!
//! ```text
//! raw      = ½|A − B|²                       (a half's variance)
//! denoised = |D(A) − B|² − ½|A − B|²         (B is unbiased and independent of D(A))
//! ```
//!
//! (the combined image the same way over every pixel, on its own display values), both at
//! half the samples, standing for the layers at all of them (measured on corpus
//! box-textured and tests/clean.rs's room: a logo's diffuse layer kept raw, matte walls
//! denoised; docs/benchmarks/clean-sets.md).
//!
//! A layer whose `denoised` is above `raw` (fine texture the filter blurs, thin
//! features) keeps no twin at that point, and the point's set.json entry lists it.

use crate::error::TraceError;
use crate::layers::{object_layer_name, LayerImage, LayerKind, PointImages, TermPart};
use crate::oidn::{DenoiseImage, Oidn};
use crate::settings::TraceSettings;
use pis_codec::display::display;
use pis_scene::lens_tree::MAX_TERMS;
use pis_scene::ObjectRole;
use serde::{Deserialize, Serialize};

/// The layers denoised per object: the radiance layers. Coverage, Fresnel, the lens
/// terms' modulations and confidences are coefficients, not radiance, and stay raw.
pub const DENOISED_KINDS: [LayerKind; 8] = [
    LayerKind::Diffuse,
    LayerKind::Specular,
    LayerKind::Local,
    LayerKind::Distant,
    LayerKind::Reflection,
    LayerKind::Refraction,
    LayerKind::Internal(1, TermPart::Value),
    LayerKind::Internal(2, TermPart::Value),
];

/// Prefix of a denoised layer's name: `denoised.combined`, `denoised.object.vase.diffuse`.
pub const DENOISED_PREFIX: &str = "denoised.";

/// Pixels of margin around an object's covered rectangle that the filter also sees.
const MARGIN: u32 = 8;

/// What denoising a point reads besides its images.
#[derive(Clone, Debug)]
pub struct DenoiseInput {
    /// `guide.albedo`, `guide.normal`.
    pub guides: [LayerImage; 2],
    /// The point's images from its even and from its odd camera samples.
    pub halves: [PointImages; 2],
}

/// What denoising did at one point (set.json `points[].denoise`).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PointDenoise {
    /// The layers that have a denoised twin (`combined`, `object.vase.diffuse`).
    pub layers: Vec<String>,
    /// Layers kept raw (`object.vase.diffuse`): denoising was estimated to move them further
    /// from the converged image.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub kept_raw: Vec<String>,
}

/// The denoised layers of one point and what was decided.
#[derive(Clone, Debug, Default)]
pub struct DenoisedPoint {
    /// `denoised.<layer>` images, to be written beside the raw ones.
    pub images: Vec<LayerImage>,
    pub summary: PointDenoise,
}

/// Per layer the sums behind the decision, squared display errors over its object's pixels,
/// from the halves A and B (each from half the samples) and the halves denoised, D(A), D(B).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Estimate {
    /// ½|A − B|²: a half's variance σ².
    half_noise: f64,
    /// |D(A) − B|²: the denoised half's error (its bias b² and its residual variance v) plus
    /// B's variance.
    denoised_half: f64,
    /// ½|D(A) − D(B)|²: the residual variance v the denoiser leaves in a half (the bias,
    /// what the filter does to the same signal, is common to both).
    denoised_noise: f64,
}

impl Estimate {
    /// The raw layer's error at all the samples: half a half's variance.
    fn raw(&self) -> f64 {
        self.half_noise / 2.0
    }

    /// The denoised layer's error at all the samples: half the residual variance, and the
    /// bias over √2. The filter's bias falls with the noise it is given by between 1 (a
    /// texture's blur, which more samples do not take away) and 2 (the artefacts of a noisy
    /// input); √2 is the geometric middle. (Taken as falling by 2, as the variance does,
    /// demo1's textured table top and the glass scene's thin columns were denoised and read
    /// 0.7 and 0.4 dB further from a 512-spp trace than raw; taken as 1, a floor that
    /// denoising brings 4.5 dB nearer, at 2 samples a half, was kept raw.)
    fn denoised(&self) -> f64 {
        let bias = (self.denoised_half - self.half_noise - self.denoised_noise).max(0.0);
        bias * std::f64::consts::FRAC_1_SQRT_2 + self.denoised_noise / 2.0
    }
}

/// A rectangle of pixels `[x0, x1) × [y0, y1)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Window {
    x0: u32,
    y0: u32,
    x1: u32,
    y1: u32,
}

impl Window {
    fn width(&self) -> u32 {
        self.x1 - self.x0
    }
    fn height(&self) -> u32 {
        self.y1 - self.y0
    }
    /// Image indices of the window's pixels, row by row.
    fn pixels(self, image_width: u32) -> impl Iterator<Item = usize> {
        (self.y0..self.y1)
            .flat_map(move |y| (self.x0..self.x1).map(move |x| (y * image_width + x) as usize))
    }
}

/// The covered rectangle of a coverage plane, grown by [`MARGIN`]; `None` when nothing is
/// covered.
fn covered_window(coverage: &[f32], width: u32, height: u32) -> Option<Window> {
    let (mut x0, mut y0, mut x1, mut y1) = (u32::MAX, u32::MAX, 0, 0);
    for (i, _) in coverage.iter().enumerate().filter(|(_, &c)| c > 0.0) {
        let (x, y) = ((i as u32) % width, (i as u32) / width);
        (x0, y0, x1, y1) = (x0.min(x), y0.min(y), x1.max(x + 1), y1.max(y + 1));
    }
    (x1 > 0).then(|| Window {
        x0: x0.saturating_sub(MARGIN),
        y0: y0.saturating_sub(MARGIN),
        x1: (x1 + MARGIN).min(width),
        y1: (y1 + MARGIN).min(height),
    })
}

/// The RGB of `layer` in `window`, interleaved, each pixel times `weight` (1 without).
fn interleave(layer: &LayerImage, window: Window, weight: Option<&[f32]>) -> Vec<f32> {
    let mut out = Vec::with_capacity(window.width() as usize * window.height() as usize * 3);
    for i in window.pixels(layer.width) {
        let w = weight.map_or(1.0, |p| p[i]);
        out.extend(layer.planes.iter().take(3).map(|p| p[i] * w));
    }
    out
}

/// The point's guides cut to one window, interleaved once for every layer filtered there.
struct WindowGuides {
    window: Window,
    albedo: Vec<f32>,
    normal: Vec<f32>,
}

impl WindowGuides {
    fn new(guides: &[LayerImage; 2], window: Window) -> WindowGuides {
        let [albedo, normal] = guides.each_ref().map(|g| interleave(g, window, None));
        WindowGuides { window, albedo, normal }
    }
}

/// Denoises the RGB of `layer` (times `weight`) in the guides' window.
fn filter(
    oidn: &Oidn,
    layer: &LayerImage,
    weight: Option<&[f32]>,
    guides: &WindowGuides,
) -> Result<Vec<f32>, TraceError> {
    let window = guides.window;
    let color = interleave(layer, window, weight);
    oidn.denoise(&DenoiseImage {
        width: window.width(),
        height: window.height(),
        color: &color,
        albedo: Some(&guides.albedo),
        normal: Some(&guides.normal),
        hdr: true,
        clean_aux: false,
    })
    .map_err(|e| TraceError::Denoise(e.to_string()))
}

/// How one layer's value moves what is seen of its object, per pixel and channel of a window:
/// the surface radiance as read (diffuse + specular, divided by coverage), the layer's own
/// value in it and the weight it enters with (the Fresnel modulation for the incident
/// `local` and `distant` layers, the latter also times 1 − local alpha; 1 for the others).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct SurfaceTerm {
    surface: f32,
    layer: f32,
    weight: f32,
}

/// The [`SurfaceTerm`]s of `object`'s layer `kind` in `window`, pixel by pixel, RGB.
fn surface_terms(
    images: &PointImages,
    object: &str,
    kind: LayerKind,
    window: Window,
) -> Vec<SurfaceTerm> {
    let layer = |k| images.object_layer(object, k);
    let (diffuse, specular, own) =
        (layer(LayerKind::Diffuse), layer(LayerKind::Specular), layer(kind));
    let (fresnel, local) = (layer(LayerKind::Fresnel), layer(LayerKind::Local));
    let value = |l: Option<&LayerImage>, c: usize, i: usize| l.map_or(0.0, |l| l.planes[c][i]);
    let weight = |c: usize, i: usize| match kind {
        LayerKind::Local => value(fresnel, c, i),
        LayerKind::Distant => value(fresnel, c, i) * (1.0 - value(local, 3, i)),
        _ => 1.0,
    };
    window
        .pixels(images.width)
        .flat_map(|i| (0..3).map(move |c| (i, c)))
        .map(|(i, c)| SurfaceTerm {
            surface: value(diffuse, c, i) + value(specular, c, i),
            layer: value(own, c, i),
            weight: weight(c, i),
        })
        .collect()
}

/// The [`SurfaceTerm`]s of an image seen as it is (the combined image): each value its own
/// surface, with weight 1.
fn displayed_terms(layer: &LayerImage) -> Vec<SurfaceTerm> {
    (0..layer.width as usize * layer.height as usize)
        .flat_map(|i| (0..3).map(move |c| (i, c)))
        .map(|(i, c)| {
            let v = layer.planes[c][i];
            SurfaceTerm { surface: v, layer: v, weight: 1.0 }
        })
        .collect()
}

/// Squared display difference (sRGB, peak 1, clipped) between the surface with the layer at
/// `a` and with it at `b`, summed over one pixel's RGB.
fn display_error(a: &[f32], b: &[f32], terms: &[SurfaceTerm]) -> f64 {
    let seen = |v: f32, t: &SurfaceTerm| display(t.surface + t.weight * (v - t.layer));
    a.iter().zip(b).zip(terms).map(|((&x, &y), t)| (seen(x, t) - seen(y, t)).powi(2)).sum()
}

/// The plane of the coverage layer `name` in `images`: `None` without a name, `Some(None)`
/// when the layer is missing.
fn coverage_plane<'a>(images: &'a PointImages, name: Option<&str>) -> Option<Option<&'a [f32]>> {
    name.map(|c| images.layer(c).map(|l| l.planes[0].as_slice()))
}

/// The raw and denoised errors of layer `name` (filtered premultiplied by the coverage layer
/// `coverage` where it has one, compared divided by it), accumulated over the covered pixels
/// of the guides' window (`mask`).
fn estimate(
    oidn: &Oidn,
    input: &DenoiseInput,
    (name, coverage): (&str, Option<&str>),
    (guides, mask, terms): (&WindowGuides, &[bool], &[SurfaceTerm]),
) -> Result<Estimate, TraceError> {
    let mut est = Estimate::default();
    let [ha, hb] = &input.halves;
    let (Some(la), Some(lb)) = (ha.layer(name), hb.layer(name)) else { return Ok(est) };
    let (ca, cb) = match (coverage_plane(ha, coverage), coverage_plane(hb, coverage)) {
        (Some(Some(ca)), Some(Some(cb))) => (Some(ca), Some(cb)),
        (None, None) => (None, None),
        _ => return Ok(est),
    };
    // Compared as the layers are read, divided by coverage, where both halves cover.
    let window = guides.window;
    let (a, b) = (interleave(la, window, None), interleave(lb, window, None));
    let (da, db) = (filter(oidn, la, ca, guides)?, filter(oidn, lb, cb, guides)?);
    for (k, i) in window.pixels(la.width).enumerate().filter(|&(k, _)| mask[k]) {
        let (wa, wb) = (ca.map_or(1.0, |c| c[i]), cb.map_or(1.0, |c| c[i]));
        if wa <= 0.0 || wb <= 0.0 {
            continue;
        }
        let px = k * 3..k * 3 + 3;
        let dak: [f32; 3] = std::array::from_fn(|c| da[k * 3 + c].max(0.0) / wa);
        let dbk: [f32; 3] = std::array::from_fn(|c| db[k * 3 + c].max(0.0) / wb);
        let t = &terms[px.clone()];
        est.half_noise += display_error(&a[px.clone()], &b[px.clone()], t) / 2.0;
        est.denoised_half += display_error(&dak, &b[px.clone()], t);
        est.denoised_noise += display_error(&dak, &dbk, t) / 2.0;
    }
    Ok(est)
}

/// A denoised image named `denoised.<layer.name>`: the filtered values in `window` divided by
/// `coverage` (cleared where it is 0), the raw values elsewhere outside the window.
fn denoised_image(
    layer: &LayerImage,
    filtered: &[f32],
    window: Window,
    coverage: Option<&[f32]>,
) -> LayerImage {
    let mut out = LayerImage::new(
        format!("{DENOISED_PREFIX}{}", layer.name),
        &["R", "G", "B"],
        layer.width,
        layer.height,
    );
    for c in 0..3 {
        out.planes[c].clone_from(&layer.planes[c]);
    }
    for (k, i) in window.pixels(layer.width).enumerate() {
        let cov = coverage.map_or(1.0, |p| p[i]);
        for c in 0..3 {
            out.planes[c][i] = if cov > 0.0 { filtered[k * 3 + c].max(0.0) / cov } else { 0.0 };
        }
    }
    out
}

/// Denoises one point's combined image and its objects' radiance layers (`objects`: each
/// object's channel name and role, in scene order).
pub fn denoise_point(
    oidn: &Oidn,
    images: &PointImages,
    input: &DenoiseInput,
    objects: &[(String, ObjectRole)],
) -> Result<DenoisedPoint, TraceError> {
    let (w, h) = (images.width, images.height);
    let mut out = DenoisedPoint::default();
    let whole = Window { x0: 0, y0: 0, x1: w, y1: h };
    if let Some(combined) = images.layer("combined") {
        let guides = WindowGuides::new(&input.guides, whole);
        let mask = vec![true; w as usize * h as usize];
        let terms = displayed_terms(combined);
        let est = estimate(oidn, input, ("combined", None), (&guides, &mask, &terms))?;
        if est.denoised() <= est.raw() {
            let filtered = filter(oidn, combined, None, &guides)?;
            out.images.push(denoised_image(combined, &filtered, whole, None));
            out.summary.layers.push(combined.name.clone());
        } else {
            out.summary.kept_raw.push(combined.name.clone());
        }
    }
    for (name, role) in objects {
        let coverage_name = object_layer_name(name, LayerKind::Coverage);
        let Some(coverage) = images.layer(&coverage_name).map(|l| &l.planes[0]) else { continue };
        let Some(window) = covered_window(coverage, w, h) else { continue };
        let mask: Vec<bool> = window.pixels(w).map(|i| coverage[i] > 0.0).collect();
        let guides = WindowGuides::new(&input.guides, window);
        for kind in
            DENOISED_KINDS.into_iter().filter(|k| LayerKind::for_role(*role, MAX_TERMS).contains(k))
        {
            let layer_name = object_layer_name(name, kind);
            let Some(layer) = images.layer(&layer_name) else { continue };
            if layer.planes.iter().take(3).all(|p| p.iter().all(|&v| v == 0.0)) {
                continue;
            }
            let terms = surface_terms(images, name, kind, window);
            let at = (&guides, mask.as_slice(), terms.as_slice());
            let est = estimate(oidn, input, (&layer_name, Some(&coverage_name)), at)?;
            if est.denoised() <= est.raw() {
                let filtered = filter(oidn, layer, Some(coverage), &guides)?;
                out.images.push(denoised_image(layer, &filtered, window, Some(coverage)));
                out.summary.layers.push(layer_name);
            } else {
                out.summary.kept_raw.push(layer_name);
            }
        }
    }
    Ok(out)
}

/// The denoiser a render with `settings` denoises with, as set.json and the report name it
/// (`Open Image Denoise 2.5.1`); `None` when it does not denoise.
pub fn denoiser(settings: &TraceSettings) -> Option<String> {
    if !settings.denoise {
        return None;
    }
    let oidn = crate::oidn::shared().ok()?;
    Some(format!("Open Image Denoise {}", oidn.version()))
}

/// Replaces every layer that has a `denoised.` twin in `images` by it (its RGB; a `local`
/// layer keeps its raw A) and drops the twins.
pub fn prefer_denoised(images: &mut PointImages) {
    let (twins, mut layers): (Vec<LayerImage>, Vec<LayerImage>) =
        std::mem::take(&mut images.layers)
            .into_iter()
            .partition(|l| l.name.starts_with(DENOISED_PREFIX));
    for twin in twins {
        let target = &twin.name[DENOISED_PREFIX.len()..];
        let Some(layer) = layers.iter_mut().find(|l| l.name == target) else { continue };
        for (c, plane) in twin.channels.iter().zip(twin.planes) {
            if let Some(k) = layer.channels.iter().position(|x| x == c) {
                layer.planes[k] = plane;
            }
        }
    }
    images.layers = layers;
}

/// Drops every `denoised.` twin from `images` (a set read raw).
pub fn drop_denoised(images: &mut PointImages) {
    images.layers.retain(|l| !l.name.starts_with(DENOISED_PREFIX));
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_covered_window_is_grown_by_the_margin_and_clipped() {
        let (w, h) = (40, 30);
        let mut cov = vec![0.0; (w * h) as usize];
        assert_eq!(covered_window(&cov, w, h), None);
        cov[(12 * w + 20) as usize] = 0.5;
        cov[(14 * w + 3) as usize] = 1.0;
        let win = covered_window(&cov, w, h).expect("covered");
        assert_eq!(win, Window { x0: 0, y0: 4, x1: 29, y1: 23 });
        assert_eq!(win.pixels(w).count(), 29 * 19);
    }

    #[test]
    fn twins_replace_their_layers_and_a_local_layer_keeps_its_alpha() {
        let mut images = PointImages {
            width: 1,
            height: 1,
            layers: vec![
                LayerImage::new("object.t.local".into(), &["R", "G", "B", "A"], 1, 1),
                LayerImage::new("denoised.object.t.local".into(), &["R", "G", "B"], 1, 1),
            ],
        };
        images.layers[0].planes[3][0] = 0.25;
        images.layers[1].planes[1][0] = 2.0;
        let mut raw = images.clone();
        prefer_denoised(&mut images);
        assert_eq!(images.layers.len(), 1);
        assert_eq!(images.layers[0].planes[1][0], 2.0);
        assert_eq!(images.layers[0].planes[3][0], 0.25);
        drop_denoised(&mut raw);
        assert_eq!(raw.layers.len(), 1);
        assert_eq!(raw.layers[0].planes[1][0], 0.0);
    }

    #[test]
    fn a_denoised_image_is_divided_by_coverage_and_cleared_where_nothing_is_covered() {
        let mut layer = LayerImage::new("object.t.diffuse".into(), &["R", "G", "B"], 2, 1);
        layer.planes[0] = vec![7.0, 7.0];
        let window = Window { x0: 0, y0: 0, x1: 2, y1: 1 };
        let filtered = [0.25, 0.0, 0.0, 0.5, 0.0, 0.0];
        let out = denoised_image(&layer, &filtered, window, Some(&[0.5, 0.0]));
        assert_eq!(out.name, "denoised.object.t.diffuse");
        assert_eq!(out.planes[0], [0.5, 0.0]);
    }
}
