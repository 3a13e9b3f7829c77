//! `pis-diff SET_A SET_B`: two ray-traced sets of one scene compared image by image — above
//! all, how far a set's Monte Carlo noise is from a set traced with more samples per pixel:
//! the accuracy a gold standard itself has, which bounds every PSNR measured against it.
//!
//! The points both sets hold (same index and parameter values) are compared: the combined
//! image per point, and per object its surface radiance (diffuse + specular layers, stored
//! divided by coverage) over the pixels both sets cover; display values (sRGB, peak 1).

use std::path::{Path, PathBuf};

use anyhow::anyhow;
use crate::metrics::SquaredError;
use pis_trace::layers::LayerKind;
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
    pub per_point: Vec<PointRow>,
    pub min_psnr_db: Option<f64>,
    pub passed: bool,
}

impl SetsReport {
    pub fn exit(&self) -> Exit {
        if self.passed { Exit::Ok } else { Exit::Different }
    }
}

fn finite(p: f64) -> Option<f64> {
    p.is_finite().then_some(p)
}

fn open(p: &Path) -> Result<RaySet, Failure> {
    RaySet::open(p).map_err(|e| Failure::new(pis_pack::trace_exit(&e), anyhow::Error::new(e).context(format!("opening the ray-traced set {}", p.display()))))
}

/// Compares the sets of `req`.
pub fn compare_sets(req: &SetsRequest) -> Result<SetsReport, Failure> {
    let (sa, sb) = (open(&req.a)?, open(&req.b)?);
    let invalid = |e: anyhow::Error| Failure::new(Exit::Invalid, e);
    if sa.meta.resolution != sb.meta.resolution {
        return Err(invalid(anyhow!("{} is {}x{}, {} is {}x{}: sets of one size compare pixel by pixel", req.a.display(),
            sa.meta.resolution[0], sa.meta.resolution[1], req.b.display(), sb.meta.resolution[0], sb.meta.resolution[1])));
    }
    let npx = sa.meta.resolution[0] as usize * sa.meta.resolution[1] as usize;
    // Objects of A that B also has, with both channel names.
    let objects: Vec<(String, String, String)> = sa.meta.objects.iter()
        .filter_map(|o| sb.meta.objects.iter().find(|p| p.name == o.name).map(|p| (o.name.clone(), o.channel_name.clone(), p.channel_name.clone())))
        .collect();
    let mut total = SquaredError::default();
    let mut per_object = vec![SquaredError::default(); objects.len()];
    let mut per_point = Vec::new();
    for pa in &sa.meta.points {
        let Some(pb) = sb.meta.points.iter().find(|p| p.index == pa.index) else { continue };
        if pa.values != pb.values {
            return Err(invalid(anyhow!("point {} is {:?} in {} and {:?} in {}: not the same parameter space", pa.index, pa.values, req.a.display(), pb.values, req.b.display())));
        }
        let read = |s: &RaySet, i: usize, dir: &Path| s.read_point(i).map_err(|e| Failure::new(pis_pack::trace_exit(&e), anyhow::Error::new(e).context(format!("reading point {i} of {}", dir.display()))));
        let (ia, ib) = (read(&sa, pa.index, &req.a)?, read(&sb, pb.index, &req.b)?);
        let mut e = SquaredError::default();
        let (ca, cb) = match (ia.layer("combined"), ib.layer("combined")) {
            (Some(a), Some(b)) => (a, b),
            _ => return Err(invalid(anyhow!("point {}: a set without its combined image", pa.index))),
        };
        for c in ["R", "G", "B"] {
            match (ca.channel(c), cb.channel(c)) {
                (Some(x), Some(y)) if x.len() == npx && y.len() == npx => e.add_slices(y, x),
                _ => return Err(invalid(anyhow!("point {}: combined image without a full {c} channel", pa.index))),
            }
        }
        for ((_, cha, chb), acc) in objects.iter().zip(per_object.iter_mut()) {
            let cov = |im: &pis_trace::layers::PointImages, ch: &str| im.object_layer(ch, LayerKind::Coverage).and_then(|l| l.channel("A")).map(<[f32]>::to_vec);
            let (Some(cova), Some(covb)) = (cov(&ia, cha), cov(&ib, chb)) else { continue };
            let surface = |im: &pis_trace::layers::PointImages, ch: &str, c: &str| -> Vec<f32> {
                let get = |k| im.object_layer(ch, k).and_then(|l| l.channel(c));
                let (d, s) = (get(LayerKind::Diffuse), get(LayerKind::Specular));
                (0..npx).map(|k| d.and_then(|p| p.get(k)).copied().unwrap_or(0.0) + s.and_then(|p| p.get(k)).copied().unwrap_or(0.0)).collect()
            };
            for c in ["R", "G", "B"] {
                let (x, y) = (surface(&ia, cha, c), surface(&ib, chb, c));
                for k in 0..npx.min(cova.len()).min(covb.len()) {
                    if cova[k] > 0.0 && covb[k] > 0.0 {
                        acc.add(y[k], x[k]);
                    }
                }
            }
        }
        total.merge(&e);
        per_point.push(PointRow { index: pa.index, point: pa.values.clone(), psnr_db: finite(e.psnr()) });
    }
    if per_point.is_empty() {
        return Err(invalid(anyhow!("{} and {} hold no point in common", req.a.display(), req.b.display())));
    }
    let psnr = finite(total.psnr());
    let passed = req.min_psnr.is_none_or(|m| psnr.is_none_or(|p| p >= m));
    Ok(SetsReport {
        a: req.a.display().to_string(),
        b: req.b.display().to_string(),
        resolution: sa.meta.resolution,
        spp: [sa.meta.spp, sb.meta.spp],
        points_compared: per_point.len(),
        points: [sa.meta.points.len(), sb.meta.points.len()],
        psnr_db: psnr,
        max_error: total.max,
        objects: objects.iter().zip(&per_object).map(|((n, _, _), e)| ObjectRow { name: n.clone(), psnr_db: finite(e.psnr()), pixels: e.count / 3 }).collect(),
        per_point,
        min_psnr_db: req.min_psnr,
        passed,
    })
}

/// The readable report.
pub fn render(r: &SetsReport) -> String {
    use std::fmt::Write;
    let db = |v: Option<f64>| v.map_or("inf (identical)".to_string(), |v| format!("{v:.2} dB"));
    let mut s = String::new();
    let _ = writeln!(s, "ray-traced set {} ({} spp) against {} ({} spp), {}x{}: {} point(s) compared ({} and {} held)",
        r.a, r.spp[0], r.b, r.spp[1], r.resolution[0], r.resolution[1], r.points_compared, r.points[0], r.points[1]);
    let _ = writeln!(s, "  combined images: {} (largest display error {:.4})", db(r.psnr_db), r.max_error);
    for o in &r.objects {
        let _ = writeln!(s, "    {:<14} {}  ({} pixels both cover)", o.name, db(o.psnr_db), o.pixels);
    }
    if let Some(m) = r.min_psnr_db {
        let _ = writeln!(s, "  gate --min-psnr {m}: {}", if r.passed { "passed" } else { "failed" });
    }
    s
}
