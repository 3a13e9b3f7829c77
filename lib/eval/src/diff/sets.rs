//! `pis-diff SET_A SET_B`: two ray-traced sets of one scene compared image by image — above
//! all, how far a set's Monte Carlo noise is from a set traced with more samples per pixel:
//! the accuracy a gold standard itself has, which bounds every PSNR measured against it.
//!
//! The points both sets hold (same index and parameter values) are compared: the combined
//! image per point, and per object its surface radiance (diffuse + specular layers, stored
//! divided by coverage) over the pixels both sets cover; display values (sRGB, peak 1).
//!
//! For reflective and refractive objects the second set's layers are also composed as the
//! player's model composes them — diffuse + fresnel · (local + (1 − α_L) · distant) (thesis
//! 5.7, RAYSET.md 5.3) and diffuse + reflection + refraction (the greedy two-path model,
//! thesis 6.2) — and compared with the first set's surface radiance: the ceiling of any file
//! that stores the object in that model, whatever its representation and coding. With a set
//! against itself this is the model's own error at that set's samples.

use std::path::{Path, PathBuf};

use super::noise::{self, judge, ReferenceNoise};
use crate::metrics::SquaredError;
use anyhow::anyhow;
use pis_trace::denoise::DENOISED_KINDS;
use pis_trace::layers::{LayerKind, PointImages, TERM_VALUES};
use pis_trace::set::RaySet;
use serde::Serialize;

use pis_pack::{Exit, Failure};

/// What to compare.
#[derive(Clone, Debug)]
pub struct SetsRequest {
    pub a: PathBuf,
    pub b: PathBuf,
    /// Gate: exit 7 when the whole-image PSNR is below this.
    pub min_psnr: Option<f64>,
    /// Read both sets' raw layers where they hold denoised twins (RAYSET.md 5.4).
    pub raw: bool,
    /// A second trace of `a` from an independent sample stream: measures `a`'s own noise
    /// ([`super::noise`]).
    pub pair: Option<PathBuf>,
}

/// One point of both sets.
#[derive(Clone, Debug, Serialize)]
pub struct PointRow {
    pub index: usize,
    pub point: Vec<f32>,
    pub psnr_db: Option<f64>,
}

/// One object over all compared points.
#[derive(Clone, Debug, Serialize)]
pub struct ObjectRow {
    pub name: String,
    pub psnr_db: Option<f64>,
    /// Pixels both sets cover, summed over points.
    pub pixels: u64,
    /// Reflective and refractive objects: the layered model the player draws, composed from
    /// the second set's layers ([`LayeredModel::formula`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub model: Option<&'static str>,
    /// That composition against the first set's surface radiance, over the same pixels.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub model_psnr_db: Option<f64>,
    /// Lens objects of a ray-tree set: the greedy model's two terms alone (the tree's first
    /// two) against the same surface, so one set gives the ceiling of both models.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub greedy_psnr_db: Option<f64>,
}

/// One kind of radiance layer, every object that has it pooled.
#[derive(Clone, Debug, Serialize)]
pub struct LayerRow {
    /// `diffuse`, `specular`, `local` (its RGB), `distant`, `reflection` or `refraction`.
    pub kind: &'static str,
    /// The layer's values (stored divided by coverage) of B against A's, display values,
    /// over the pixels both sets cover.
    pub psnr_db: Option<f64>,
    pub pixels: u64,
}

/// The layered model of an object's role, as the player composes its layers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LayeredModel {
    /// Reflective: diffuse + fresnel · (local + (1 − α_L) · distant).
    Environment,
    /// Refractive: diffuse + the lens model's terms (2 greedy: reflection + refraction; the
    /// tree's 3 or 4 add refraction_1 and refraction_2).
    Lens { terms: usize },
}

impl LayeredModel {
    /// The greedy model's two terms, where this is a tree of more.
    pub fn greedy_part(self) -> Option<LayeredModel> {
        match self {
            LayeredModel::Lens { terms } if terms > 2 => Some(LayeredModel::Lens { terms: 2 }),
            _ => None,
        }
    }

    /// The model an object's layers carry, if any.
    pub fn of(layers: &[String]) -> Option<LayeredModel> {
        let has = |k: LayerKind| layers.iter().any(|l| l == k.name());
        if has(LayerKind::Fresnel) && has(LayerKind::Local) && has(LayerKind::Distant) {
            Some(LayeredModel::Environment)
        } else if has(LayerKind::Reflection) && has(LayerKind::Refraction) {
            Some(LayeredModel::Lens { terms: TERM_VALUES.iter().take_while(|&&k| has(k)).count() })
        } else {
            None
        }
    }

    pub fn formula(self) -> &'static str {
        match self {
            LayeredModel::Environment => "diffuse + fresnel * (local + (1 - alpha) * distant)",
            LayeredModel::Lens { terms: 2 } => "diffuse + reflection + refraction",
            LayeredModel::Lens { terms: 3 } => "diffuse + reflection + refraction + refraction_1",
            LayeredModel::Lens { .. } => {
                "diffuse + reflection + refraction + refraction_1 + refraction_2"
            }
        }
    }

    /// Channel `c` of the composition at every pixel (None when a layer is missing).
    pub fn compose(self, im: &PointImages, object: &str, c: &str) -> Option<Vec<f32>> {
        let get = |k: LayerKind, c: &str| im.object_layer(object, k).and_then(|l| l.channel(c));
        let d = get(LayerKind::Diffuse, c)?;
        match self {
            LayeredModel::Environment => {
                let (f, l, a, t) = (
                    get(LayerKind::Fresnel, c)?,
                    get(LayerKind::Local, c)?,
                    get(LayerKind::Local, "A")?,
                    get(LayerKind::Distant, c)?,
                );
                let n = d.len().min(f.len()).min(l.len()).min(a.len()).min(t.len());
                Some((0..n).map(|k| d[k] + f[k] * (l[k] + (1.0 - a[k]) * t[k])).collect())
            }
            LayeredModel::Lens { terms } => {
                let mut sum = d.to_vec();
                for &kind in &TERM_VALUES[..terms.min(TERM_VALUES.len())] {
                    let t = get(kind, c)?;
                    sum.truncate(t.len());
                    sum.iter_mut().zip(t).for_each(|(s, v)| *s += v);
                }
                Some(sum)
            }
        }
    }
}

/// The report.
#[derive(Clone, Debug, Serialize)]
pub struct SetsReport {
    pub a: String,
    pub b: String,
    pub resolution: [u32; 2],
    pub spp: [u32; 2],
    /// Points compared (both sets hold them), of the points each set holds.
    pub points_compared: usize,
    pub points: [usize; 2],
    /// Combined images, every compared point.
    pub psnr_db: Option<f64>,
    pub max_error: f64,
    pub objects: Vec<ObjectRow>,
    /// Per kind of radiance layer, every object pooled (the kinds some object has).
    pub layers_by_kind: Vec<LayerRow>,
    pub per_point: Vec<PointRow>,
    pub min_psnr_db: Option<f64>,
    pub passed: bool,
    /// Which layers of each set were read: `denoised` (the set's denoised twins), `raw`
    /// (asked for, or a set without twins).
    pub layers: [&'static str; 2],
    /// With a reference pair: the first set's own noise beside each figure.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reference_noise: Option<ReferenceNoise>,
}

impl SetsReport {
    /// The PSNR on the object `name` (`None`: no such object, or an exact match).
    pub fn object_psnr(&self, name: &str) -> Option<f64> {
        self.objects.iter().find(|o| o.name == name).and_then(|o| o.psnr_db)
    }

    /// The PSNR over every object's covered pixels pooled (the objects' MSEs weighted by
    /// their pixels).
    pub fn pooled_objects_psnr(&self) -> Option<f64> {
        let pixels: u64 = self.objects.iter().map(|o| o.pixels).sum();
        let sum: f64 = self.objects.iter().map(|o| noise::mse(o.psnr_db) * o.pixels as f64).sum();
        noise::psnr(sum / pixels.max(1) as f64)
    }

    pub fn exit(&self) -> Exit {
        if self.passed {
            Exit::Ok
        } else {
            Exit::Different
        }
    }
}

fn finite(p: f64) -> Option<f64> {
    p.is_finite().then_some(p)
}

fn open(p: &Path) -> Result<RaySet, Failure> {
    RaySet::open(p).map_err(|e| {
        Failure::new(
            pis_pack::trace_exit(&e),
            anyhow::Error::new(e).context(format!("opening the ray-traced set {}", p.display())),
        )
    })
}

/// Adds one object's errors at a point to `acc` (A's surface radiance against B's, over
/// the pixels both cover), `macc` (A's against B's composed by B's layered model and, for a
/// tree, by its greedy part) and `kinds` (each radiance layer, [`add_layers`]): the object's
/// channels in A and B are `cha` and `chb`.
fn add_object(
    ia: &PointImages,
    ib: &PointImages,
    (cha, chb): (&str, &str),
    model: Option<LayeredModel>,
    npx: usize,
    (acc, macc): (&mut SquaredError, &mut [SquaredError; 2]),
    kinds: &mut [SquaredError],
) {
    let cov = |im: &PointImages, ch: &str| {
        im.object_layer(ch, LayerKind::Coverage).and_then(|l| l.channel("A")).map(<[f32]>::to_vec)
    };
    let (Some(cova), Some(covb)) = (cov(ia, cha), cov(ib, chb)) else { return };
    let surface = |im: &PointImages, ch: &str, c: &str| -> Vec<f32> {
        let get = |k| im.object_layer(ch, k).and_then(|l| l.channel(c));
        let (d, s) = (get(LayerKind::Diffuse), get(LayerKind::Specular));
        (0..npx)
            .map(|k| {
                d.and_then(|p| p.get(k)).copied().unwrap_or(0.0)
                    + s.and_then(|p| p.get(k)).copied().unwrap_or(0.0)
            })
            .collect()
    };
    let both: Vec<bool> = cova.iter().zip(&covb).map(|(a, b)| *a > 0.0 && *b > 0.0).collect();
    add_layers(ia, ib, (cha, chb), &both, kinds);
    for c in ["R", "G", "B"] {
        let (x, y) = (surface(ia, cha, c), surface(ib, chb, c));
        let composed = [model, model.and_then(LayeredModel::greedy_part)]
            .map(|m| m.and_then(|m| m.compose(ib, chb, c)));
        for k in 0..npx.min(cova.len()).min(covb.len()) {
            if cova[k] > 0.0 && covb[k] > 0.0 {
                acc.add(y[k], x[k]);
                for (composed, macc) in composed.iter().zip(macc.iter_mut()) {
                    if let Some(m) = composed.as_ref().and_then(|m| m.get(k)) {
                        macc.add(*m, x[k]);
                    }
                }
            }
        }
    }
}

/// Adds each radiance layer of one object at a point to `kinds` (indexed as
/// [`DENOISED_KINDS`]): B's values against A's at the pixels `both` marks.
fn add_layers(
    ia: &PointImages,
    ib: &PointImages,
    (cha, chb): (&str, &str),
    both: &[bool],
    kinds: &mut [SquaredError],
) {
    for (kind, acc) in DENOISED_KINDS.iter().zip(kinds.iter_mut()) {
        let (Some(la), Some(lb)) = (ia.object_layer(cha, *kind), ib.object_layer(chb, *kind))
        else {
            continue;
        };
        for c in ["R", "G", "B"] {
            let (Some(x), Some(y)) = (la.channel(c), lb.channel(c)) else { continue };
            for ((x, y), _) in x.iter().zip(y).zip(both).filter(|(_, b)| **b) {
                acc.add(*y, *x);
            }
        }
    }
}

/// Compares the sets of `req`.
pub fn compare_sets(req: &SetsRequest) -> Result<SetsReport, Failure> {
    let (sa, sb) = (open(&req.a)?.with_raw(req.raw), open(&req.b)?.with_raw(req.raw));
    let read = |s: &RaySet| if !s.raw && s.is_denoised() { "denoised" } else { "raw" };
    let layers = [read(&sa), read(&sb)];
    let invalid = |e: anyhow::Error| Failure::new(Exit::Invalid, e);
    if sa.meta.resolution != sb.meta.resolution {
        return Err(invalid(anyhow!(
            "{} is {}x{}, {} is {}x{}: sets of one size compare pixel by pixel",
            req.a.display(),
            sa.meta.resolution[0],
            sa.meta.resolution[1],
            req.b.display(),
            sb.meta.resolution[0],
            sb.meta.resolution[1]
        )));
    }
    let npx = sa.meta.resolution[0] as usize * sa.meta.resolution[1] as usize;
    // Objects of A that B also has, with both channel names.
    let objects: Vec<(String, String, String, Option<LayeredModel>)> = sa
        .meta
        .objects
        .iter()
        .filter_map(|o| {
            sb.meta.objects.iter().find(|p| p.name == o.name).map(|p| {
                (
                    o.name.clone(),
                    o.channel_name.clone(),
                    p.channel_name.clone(),
                    LayeredModel::of(&p.layers),
                )
            })
        })
        .collect();
    let mut total = SquaredError::default();
    let mut per_object = vec![SquaredError::default(); objects.len()];
    let mut per_model = vec![<[SquaredError; 2]>::default(); objects.len()];
    let mut per_kind = vec![SquaredError::default(); DENOISED_KINDS.len()];
    let mut per_point = Vec::new();
    for pa in &sa.meta.points {
        let Some(pb) = sb.meta.points.iter().find(|p| p.index == pa.index) else { continue };
        if pa.values != pb.values {
            return Err(invalid(anyhow!(
                "point {} is {:?} in {} and {:?} in {}: not the same parameter space",
                pa.index,
                pa.values,
                req.a.display(),
                pb.values,
                req.b.display()
            )));
        }
        let read = |s: &RaySet, i: usize, dir: &Path| {
            s.read_point(i).map_err(|e| {
                Failure::new(
                    pis_pack::trace_exit(&e),
                    anyhow::Error::new(e)
                        .context(format!("reading point {i} of {}", dir.display())),
                )
            })
        };
        let (ia, ib) = (read(&sa, pa.index, &req.a)?, read(&sb, pb.index, &req.b)?);
        let mut e = SquaredError::default();
        let (ca, cb) = match (ia.layer("combined"), ib.layer("combined")) {
            (Some(a), Some(b)) => (a, b),
            _ => {
                return Err(invalid(anyhow!(
                    "point {}: a set without its combined image",
                    pa.index
                )))
            }
        };
        for c in ["R", "G", "B"] {
            match (ca.channel(c), cb.channel(c)) {
                (Some(x), Some(y)) if x.len() == npx && y.len() == npx => e.add_slices(y, x),
                _ => {
                    return Err(invalid(anyhow!(
                        "point {}: combined image without a full {c} channel",
                        pa.index
                    )))
                }
            }
        }
        for (((_, cha, chb, model), acc), macc) in
            objects.iter().zip(per_object.iter_mut()).zip(per_model.iter_mut())
        {
            add_object(&ia, &ib, (cha, chb), *model, npx, (acc, macc), &mut per_kind);
        }
        total.merge(&e);
        per_point.push(PointRow {
            index: pa.index,
            point: pa.values.clone(),
            psnr_db: finite(e.psnr()),
        });
    }
    if per_point.is_empty() {
        return Err(invalid(anyhow!(
            "{} and {} hold no point in common",
            req.a.display(),
            req.b.display()
        )));
    }
    let psnr = finite(total.psnr());
    let passed = req.min_psnr.is_none_or(|m| psnr.is_none_or(|p| p >= m));
    let mut report = SetsReport {
        reference_noise: None,
        layers,
        a: req.a.display().to_string(),
        b: req.b.display().to_string(),
        resolution: sa.meta.resolution,
        spp: [sa.meta.spp, sb.meta.spp],
        points_compared: per_point.len(),
        points: [sa.meta.points.len(), sb.meta.points.len()],
        psnr_db: psnr,
        max_error: total.max,
        objects: objects
            .iter()
            .zip(per_object.iter().zip(&per_model))
            .map(|((n, _, _, model), (e, [m, g]))| {
                let model = model.filter(|_| m.count > 0);
                ObjectRow {
                    name: n.clone(),
                    psnr_db: finite(e.psnr()),
                    pixels: e.count / 3,
                    model: model.map(LayeredModel::formula),
                    model_psnr_db: model.and_then(|_| finite(m.psnr())),
                    greedy_psnr_db: (g.count > 0).then(|| finite(g.psnr())).flatten(),
                }
            })
            .collect(),
        layers_by_kind: DENOISED_KINDS
            .iter()
            .zip(&per_kind)
            .filter(|(_, e)| e.count > 0)
            .map(|(k, e)| LayerRow {
                kind: k.name(),
                psnr_db: finite(e.psnr()),
                pixels: e.count / 3,
            })
            .collect(),
        per_point,
        min_psnr_db: req.min_psnr,
        passed,
    };
    if let Some(second) = &req.pair {
        report.reference_noise = Some(reference_noise(&report, &req.a, second, req.raw)?);
    }
    Ok(report)
}

/// Compares the reference `first` with its second trace `second` (their layers read as
/// `raw` asks): the pair's own figures, whole image and per object.
pub fn pair(first: &Path, second: &Path, raw: bool) -> Result<SetsReport, Failure> {
    compare_sets(&SetsRequest {
        a: first.to_path_buf(),
        b: second.to_path_buf(),
        min_psnr: None,
        raw,
        pair: None,
    })
}

/// The first set's own noise, from its second trace, beside the report's figures.
fn reference_noise(
    r: &SetsReport,
    first: &Path,
    second: &Path,
    raw: bool,
) -> Result<ReferenceNoise, Failure> {
    let pair = pair(first, second, raw)?;
    let mut figures = vec![judge("whole image", r.psnr_db, pair.psnr_db)];
    figures.extend(
        r.objects
            .iter()
            .filter(|o| o.pixels > 0)
            .map(|o| judge(&o.name, o.psnr_db, pair.object_psnr(&o.name))),
    );
    figures.extend(r.layers_by_kind.iter().map(|l| {
        let between = pair.layers_by_kind.iter().find(|p| p.kind == l.kind).and_then(|p| p.psnr_db);
        judge(&format!("{} layers", l.kind), l.psnr_db, between)
    }));
    Ok(ReferenceNoise { pair: second.display().to_string(), points: pair.points_compared, figures })
}

/// The readable report.
pub fn render(r: &SetsReport) -> String {
    use std::fmt::Write;
    let db = |v: Option<f64>| v.map_or("inf (identical)".to_string(), |v| format!("{v:.2} dB"));
    let mut s = String::new();
    let _ = writeln!(s, "ray-traced set {} ({} spp, {} layers) against {} ({} spp, {} layers), {}x{}: {} point(s) compared ({} and {} held)",
        r.a, r.spp[0], r.layers[0], r.b, r.spp[1], r.layers[1], r.resolution[0], r.resolution[1], r.points_compared, r.points[0], r.points[1]);
    let _ = writeln!(
        s,
        "  combined images: {} (largest display error {:.4})",
        db(r.psnr_db),
        r.max_error
    );
    for o in &r.objects {
        let _ =
            writeln!(s, "    {:<14} {}  ({} pixels both cover)", o.name, db(o.psnr_db), o.pixels);
        if let Some(m) = o.model {
            let _ = writeln!(
                s,
                "    {:<14} {}  the second set's layers composed as the player's model, {m}",
                "",
                db(o.model_psnr_db)
            );
        }
        if o.greedy_psnr_db.is_some() {
            let _ = writeln!(
                s,
                "    {:<14} {}  its greedy model's terms alone (the tree's first two), diffuse + reflection + refraction",
                "",
                db(o.greedy_psnr_db)
            );
        }
    }
    if !r.layers_by_kind.is_empty() {
        let _ = writeln!(s, "  radiance layers, every object pooled, over the pixels both cover:");
    }
    for l in &r.layers_by_kind {
        let _ = writeln!(s, "    {:<14} {}  ({} pixels)", l.kind, db(l.psnr_db), l.pixels);
    }
    if let Some(n) = &r.reference_noise {
        s.push_str(&noise::render(n));
    }
    if let Some(m) = r.min_psnr_db {
        let _ =
            writeln!(s, "  gate --min-psnr {m}: {}", if r.passed { "passed" } else { "failed" });
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use pis_scene::ObjectRole;
    use pis_trace::layers::{LayerImage, TermPart};

    fn layer(object: &str, kind: LayerKind, channels: &[&str], values: &[f32]) -> LayerImage {
        let mut l = LayerImage::new(format!("object.{object}.{}", kind.name()), channels, 2, 1);
        for p in &mut l.planes {
            p.copy_from_slice(values);
        }
        l
    }

    #[test]
    fn the_model_of_an_object_is_read_from_its_layers() {
        let names = |ks: &[LayerKind]| ks.iter().map(|k| k.name().to_string()).collect::<Vec<_>>();
        assert_eq!(
            LayeredModel::of(&names(LayerKind::for_role(ObjectRole::Reflective, 2))),
            Some(LayeredModel::Environment)
        );
        assert_eq!(
            LayeredModel::of(&names(LayerKind::for_role(ObjectRole::Refractive, 2))),
            Some(LayeredModel::Lens { terms: 2 })
        );
        assert_eq!(
            LayeredModel::of(&names(LayerKind::for_role(ObjectRole::Refractive, 4))),
            Some(LayeredModel::Lens { terms: 4 })
        );
        assert_eq!(LayeredModel::of(&names(LayerKind::for_role(ObjectRole::Diffuse, 2))), None);
    }

    #[test]
    fn layers_compose_as_the_player_composes_them() {
        let rgb = ["R", "G", "B"];
        let im = PointImages {
            width: 2,
            height: 1,
            layers: vec![
                layer("m", LayerKind::Diffuse, &rgb, &[0.1, 0.0]),
                layer("m", LayerKind::Fresnel, &rgb, &[0.5, 1.0]),
                // Premultiplied local layer: α 0.25 at the first pixel, 1 at the second.
                layer("m", LayerKind::Local, &["R", "G", "B", "A"], &[0.25, 1.0]),
                layer("m", LayerKind::Distant, &rgb, &[0.4, 7.0]),
                layer("g", LayerKind::Diffuse, &rgb, &[0.1, 0.2]),
                layer("g", LayerKind::Reflection, &rgb, &[0.3, 0.0]),
                layer("g", LayerKind::Refraction, &rgb, &[0.5, 0.25]),
                layer("g", LayerKind::Internal(1, TermPart::Value), &rgb, &[0.0, 0.5]),
            ],
        };
        // 0.1 + 0.5 · (0.25 + 0.75 · 0.4); the fully covering local layer hides the distant one.
        let m = LayeredModel::Environment.compose(&im, "m", "G").expect("all layers");
        assert!((m[0] - 0.375).abs() < 1e-6 && (m[1] - 1.0).abs() < 1e-6, "{m:?}");
        let two = LayeredModel::Lens { terms: 2 };
        assert_eq!(two.compose(&im, "g", "B").expect("all layers"), vec![0.9, 0.45]);
        let three = LayeredModel::Lens { terms: 3 };
        assert_eq!(three.compose(&im, "g", "B").expect("all layers"), vec![0.9, 0.95]);
        assert!(
            LayeredModel::Lens { terms: 4 }.compose(&im, "g", "B").is_none(),
            "no refraction_2"
        );
        assert!(two.compose(&im, "m", "R").is_none(), "no reflection layer");
    }
}
