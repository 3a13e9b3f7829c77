//! A set traced point by point, by one process or by several (RAYSET.md 9): each point's
//! entry of `set.json` is recorded in `shards/` once its files are written, and `set.json`
//! is assembled from the records when every point has one. The records are what an
//! interrupted trace resumes from and what shards of one trace, run as separate processes
//! on separate machines sharing the directory, meet in.

use super::atomic::write_atomic;
use super::meta::{PointMeta, SetMeta};
use super::SET_JSON;
use crate::error::TraceError;
use serde::{Deserialize, Serialize};
use std::fs;
use std::path::{Path, PathBuf};

/// The folder of a set directory that holds the records of a trace in progress.
pub const SHARDS_DIR: &str = "shards";
/// The trace the records belong to, inside [`SHARDS_DIR`].
const SHARD_META: &str = "meta.json";

/// One of `count` shards of a trace: the points whose linear index is `index` modulo
/// `count` (interleaved, so that every shard gets points from all over the space).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct Shard {
    pub index: usize,
    pub count: usize,
}

impl Shard {
    /// The whole space, one process.
    pub const WHOLE: Shard = Shard { index: 0, count: 1 };

    /// Whether point `point` is this shard's.
    pub fn has(self, point: usize) -> bool {
        point % self.count == self.index
    }

    /// The points of this shard among the first `points`.
    pub fn points(self, points: usize) -> impl Iterator<Item = usize> {
        (self.index..points).step_by(self.count)
    }
}

impl std::str::FromStr for Shard {
    type Err = String;

    /// `I/N`: shard I (counted from 0) of N.
    fn from_str(s: &str) -> Result<Shard, String> {
        let (i, n) = s
            .split_once('/')
            .ok_or_else(|| format!("expected I/N (shard I of N, from 0), got {s:?}"))?;
        let index: usize = i.trim().parse().map_err(|_| format!("bad shard index in {s:?}"))?;
        let count: usize = n.trim().parse().map_err(|_| format!("bad shard count in {s:?}"))?;
        if count == 0 || index >= count {
            return Err(format!(
                "shard {s:?}: the index counts from 0 and must be below the count"
            ));
        }
        Ok(Shard { index, count })
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

/// `shards/meta.json`: the set's `set.json` without points, and how many points it is to
/// have. Every process of a trace writes the same.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
struct ShardMeta {
    points: usize,
    set: SetMeta,
}

/// How a process takes up the records of a set directory.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Begin {
    /// Forget any records there: a trace from scratch by one process.
    Fresh,
    /// Join the records of the same trace (the same scene, settings and point count), or
    /// start them; records of another trace are an error.
    Join,
}

/// The records of a trace in progress in a set directory.
pub struct Records {
    set_dir: PathBuf,
    dir: PathBuf,
}

fn read_json<T: for<'de> Deserialize<'de>>(path: &Path) -> Result<T, TraceError> {
    let bytes = fs::read(path).map_err(|e| TraceError::io(path, e))?;
    serde_json::from_slice(&bytes)
        .map_err(|e| TraceError::InvalidSet { path: path.to_path_buf(), message: e.to_string() })
}

pub(super) fn encode<T: Serialize>(value: &T, path: &Path) -> Result<Vec<u8>, TraceError> {
    serde_json::to_vec_pretty(value)
        .map_err(|e| TraceError::InvalidInput(format!("cannot encode {}: {e}", path.display())))
}

impl Records {
    /// The records of the trace `meta` (points left empty) of `points` points in the set
    /// directory `set_dir`, taken up as `begin` says.
    pub fn begin(
        set_dir: &Path,
        meta: &SetMeta,
        points: usize,
        begin: Begin,
    ) -> Result<Records, TraceError> {
        let dir = set_dir.join(SHARDS_DIR);
        let path = dir.join(SHARD_META);
        let want = ShardMeta { points, set: SetMeta { points: Vec::new(), ..meta.clone() } };
        if begin == Begin::Fresh && dir.exists() {
            fs::remove_dir_all(&dir).map_err(|e| TraceError::io(&dir, e))?;
        }
        if begin == Begin::Join && path.exists() {
            let have: ShardMeta = read_json(&path)?;
            if have != want {
                let what = if have.points != want.points {
                    format!("{} points, this one {}", have.points, want.points)
                } else if have.set.scene != want.set.scene {
                    format!("scene {:?}, this one {:?}", have.set.scene, want.set.scene)
                } else {
                    "other settings (resolution, samples, preset or renderer)".to_string()
                };
                return Err(TraceError::InvalidSet {
                    path,
                    message: format!("the directory holds points of another trace ({what}): trace into another directory, or remove {} to start over", dir.display()),
                });
            }
        }
        fs::create_dir_all(&dir).map_err(|e| TraceError::io(&dir, e))?;
        // A set.json there describes a set this trace is rewriting.
        let stale = set_dir.join(SET_JSON);
        if stale.exists() {
            fs::remove_file(&stale).map_err(|e| TraceError::io(&stale, e))?;
        }
        write_atomic(&path, &encode(&want, &path)?)?;
        Ok(Records { set_dir: set_dir.to_path_buf(), dir })
    }

    fn point_path(&self, index: usize) -> PathBuf {
        self.dir.join(format!("point_{index:05}.json"))
    }

    /// Records `point`, whose files are written.
    pub fn record(&self, point: &PointMeta) -> Result<(), TraceError> {
        let path = self.point_path(point.index);
        write_atomic(&path, &encode(point, &path)?)
    }

    /// The record of point `index`, when it has one and its files are there.
    pub fn done(&self, index: usize) -> Option<PointMeta> {
        let path = self.point_path(index);
        let point: PointMeta = read_json(&path).ok()?;
        let files = std::iter::once(&point.image).chain(point.rays.as_ref());
        (point.index == index && files.into_iter().all(|f| self.set_dir.join(f).is_file()))
            .then_some(point)
    }
}

/// What [`merge_set`] did.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MergeReport {
    /// Points in set.json.
    pub points: usize,
    /// The set was complete already: nothing was written.
    pub already_complete: bool,
    /// Bytes of set.json written.
    pub bytes: u64,
}

/// Assembles `set.json` in the set directory `set_dir` from the records of its trace and
/// removes them: the set is complete. An error names the points not traced yet. A set
/// that is complete already (set.json and no records) is left as it is; several processes
/// may merge at once (each writes the same bytes, and one that finds the records removed
/// under it by another's merge finds the set complete).
pub fn merge_set(set_dir: &Path) -> Result<MergeReport, TraceError> {
    merge_records(set_dir).or_else(|e| {
        // A merge writes set.json, then removes the records, and a trace removes set.json
        // before it records a point: a set.json there now, after records went missing under
        // this merge, is another process's merge of the same records.
        match read_json::<SetMeta>(&set_dir.join(SET_JSON)) {
            Ok(meta) => {
                Ok(MergeReport { points: meta.points.len(), already_complete: true, bytes: 0 })
            }
            Err(_) => Err(e),
        }
    })
}

fn merge_records(set_dir: &Path) -> Result<MergeReport, TraceError> {
    let dir = set_dir.join(SHARDS_DIR);
    let meta_path = dir.join(SHARD_META);
    let set_json = set_dir.join(SET_JSON);
    if !meta_path.exists() {
        if set_json.is_file() {
            let meta: SetMeta = read_json(&set_json)?;
            return Ok(MergeReport { points: meta.points.len(), already_complete: true, bytes: 0 });
        }
        return Err(TraceError::InvalidSet {
            path: set_dir.to_path_buf(),
            message: format!("not a ray-traced set: neither {SET_JSON} nor the records of a trace ({SHARDS_DIR}/{SHARD_META})"),
        });
    }
    let shard_meta: ShardMeta = read_json(&meta_path)?;
    let records = Records { set_dir: set_dir.to_path_buf(), dir: dir.clone() };
    let mut points = Vec::with_capacity(shard_meta.points.min(1 << 20));
    let mut missing = Vec::new();
    for index in 0..shard_meta.points {
        match records.done(index) {
            Some(p) => points.push(p),
            None => missing.push(index),
        }
    }
    if !missing.is_empty() {
        let list: Vec<String> = missing.iter().take(12).map(usize::to_string).collect();
        let more = if missing.len() > 12 {
            format!(" and {} more", missing.len() - 12)
        } else {
            String::new()
        };
        return Err(TraceError::InvalidSet {
            path: set_dir.to_path_buf(),
            message: format!(
                "{} of {} points are not traced yet (points {}{more}; shard I of N traces the points whose index modulo N is I): run their shards (with --resume) and merge again",
                missing.len(),
                shard_meta.points,
                list.join(", ")
            ),
        });
    }
    let meta = SetMeta { points, ..shard_meta.set };
    let json = encode(&meta, &set_json)?;
    write_atomic(&set_json, &json)?;
    match fs::remove_dir_all(&dir) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => return Err(TraceError::io(&dir, e)),
        _ => {}
    }
    Ok(MergeReport { points: meta.points.len(), already_complete: false, bytes: json.len() as u64 })
}

/// Whether `set_dir` holds the complete set of the trace `meta` (points left empty) of
/// `points` points: its set.json, and no records of a trace in progress.
pub fn is_complete(set_dir: &Path, meta: &SetMeta, points: usize) -> bool {
    if set_dir.join(SHARDS_DIR).exists() {
        return false;
    }
    let Ok(have) = read_json::<SetMeta>(&set_dir.join(SET_JSON)) else { return false };
    have.points.len() == points
        && have.points.iter().enumerate().all(|(i, p)| p.index == i)
        && SetMeta { points: Vec::new(), ..have } == SetMeta { points: Vec::new(), ..meta.clone() }
}

/// Whether every one of the trace's points in `set_dir` is recorded.
pub fn all_recorded(set_dir: &Path) -> Result<bool, TraceError> {
    let dir = set_dir.join(SHARDS_DIR);
    let shard_meta: ShardMeta = read_json(&dir.join(SHARD_META))?;
    let records = Records { set_dir: set_dir.to_path_buf(), dir };
    Ok((0..shard_meta.points).all(|i| records.done(i).is_some()))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A set's metadata of `points` points, as set.json holds it.
    fn meta(points: usize) -> SetMeta {
        let m = vec![0.0f32; 16];
        let point = |i: usize| {
            serde_json::json!({
                "index": i, "samples": [i], "values": [i as f32], "image": format!("point_{i:05}.exr"), "rays": null,
                "camera": {"world_from_camera": m, "camera_from_world": m, "projection": m, "yfov": 0.7, "znear": 0.1, "zfar": null},
                "lights": [], "objects": []
            })
        };
        serde_json::from_value(serde_json::json!({
            "format": "pis-rayset", "version": 1, "scene": "s", "resolution": [4, 3], "spp": 1,
            "filter": {"sigma_px": 0.5, "radius_px": 1.5},
            "space": [{"name": "view", "kind": "view", "driver": "orbit", "periodic": false, "unit": "deg", "values": (0..points).map(|i| i as f32).collect::<Vec<_>>()}],
            "objects": [], "points": (0..points).map(point).collect::<Vec<_>>()
        }))
        .expect("a set.json")
    }

    #[test]
    fn processes_merging_at_once_all_find_the_set_complete() {
        for round in 0..8 {
            let dir = tempfile::tempdir().unwrap();
            let full = meta(6);
            let records = Records::begin(dir.path(), &full, 6, Begin::Join).unwrap();
            for p in &full.points {
                std::fs::write(dir.path().join(&p.image), b"exr").unwrap();
                records.record(p).unwrap();
            }
            let merges: Vec<_> = (0..4)
                .map(|_| {
                    let d = dir.path().to_path_buf();
                    std::thread::spawn(move || merge_set(&d))
                })
                .collect();
            for m in merges {
                let r = m.join().unwrap().unwrap_or_else(|e| panic!("round {round}: {e}"));
                assert_eq!(r.points, 6);
            }
            let written: SetMeta = read_json(&dir.path().join(SET_JSON)).unwrap();
            assert_eq!(written, full, "set.json holds the records in index order");
            assert!(!dir.path().join(SHARDS_DIR).exists());
        }
    }

    #[test]
    fn a_merge_names_the_points_not_traced_and_a_join_refuses_another_trace() {
        let dir = tempfile::tempdir().unwrap();
        let full = meta(5);
        let records = Records::begin(dir.path(), &full, 5, Begin::Join).unwrap();
        for p in full.points.iter().filter(|p| p.index != 1 && p.index != 4) {
            std::fs::write(dir.path().join(&p.image), b"exr").unwrap();
            records.record(p).unwrap();
        }
        // A record whose image is gone is not done.
        std::fs::remove_file(dir.path().join(&full.points[2].image)).unwrap();
        let e = merge_set(dir.path()).unwrap_err().to_string();
        assert!(e.contains("3 of 5 points are not traced yet (points 1, 2, 4;"), "{e}");
        let other = SetMeta { spp: 2, ..full.clone() };
        let e = Records::begin(dir.path(), &other, 5, Begin::Join)
            .err()
            .expect("another trace is refused")
            .to_string();
        assert!(e.contains("another trace"), "{e}");
        assert!(
            Records::begin(dir.path(), &full, 6, Begin::Join).is_err(),
            "another point count is another trace"
        );
        assert!(
            Records::begin(dir.path(), &other, 5, Begin::Fresh).is_ok(),
            "a fresh trace starts over"
        );
        assert!(merge_set(dir.path()).is_err(), "the fresh trace has recorded nothing");
    }

    #[test]
    fn a_shard_parses_from_i_of_n_and_takes_every_nth_point() {
        let s: Shard = "1/3".parse().unwrap();
        assert_eq!(s, Shard { index: 1, count: 3 });
        assert_eq!(s.points(8).collect::<Vec<_>>(), vec![1, 4, 7]);
        assert!(s.has(4) && !s.has(5));
        assert_eq!(s.to_string(), "1/3");
        for bad in ["3/3", "1/0", "1", "a/2", "-1/2"] {
            assert!(bad.parse::<Shard>().is_err(), "{bad}");
        }
        let all: Vec<usize> = (0..3)
            .flat_map(|i| Shard { index: i, count: 3 }.points(8))
            .collect::<std::collections::BTreeSet<_>>()
            .into_iter()
            .collect();
        assert_eq!(all, (0..8).collect::<Vec<_>>(), "the shards cover every point once");
    }
}
