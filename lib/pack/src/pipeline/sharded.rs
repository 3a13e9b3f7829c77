//! A pack split over processes or machines sharing a folder (docs/CLUSTER.md): solve
//! shards each run the inference of every N-th object and write the solutions they
//! computed to a fragment file ([`crate::solutions`]); the merge packs the set with every
//! solve read from the fragments, writing the file a single process writes.

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::time::Instant;

use super::{begin, infer_layers, pack_request, PackReport, PackRequest, Progress, Shard, Stages};
use crate::error::{Exit, Failure};
use crate::pipeline::report::FragmentsReport;

/// What a solve shard did ([`solve_shard`]).
#[derive(Clone, Debug, serde::Serialize)]
pub struct SolveReport {
    /// `I/N`.
    pub shard: String,
    /// The fragment file.
    pub fragment: String,
    /// The objects this shard solved (for `--representation auto`, both ways).
    pub objects: Vec<String>,
    /// Solutions in the fragment.
    pub solutions: usize,
    pub bytes: u64,
    /// The fragment was there already (`resume`): nothing was done.
    pub resumed: bool,
    pub seconds: f64,
    /// Milliseconds per stage.
    pub stage_ms: BTreeMap<String, f64>,
}

/// The fragment file of shard `shard` in the folder `fragments`.
pub fn fragment_path(fragments: &std::path::Path, shard: Shard) -> PathBuf {
    fragments.join(format!(
        "solve-{:04}-of-{:04}.{}",
        shard.index,
        shard.count,
        crate::solutions::FRAGMENT_EXTENSION
    ))
}

/// The solve of a pack split over processes: runs `req`'s inference for the objects of
/// `shard` (the objects that cover a pixel, in scene order, every N-th from the I-th) and
/// writes the solutions to a fragment file in the folder `fragments` (atomically); with
/// `resume`, a fragment that is there already is kept and nothing is done.
/// [`merge_fragments`] then writes the file.
pub fn solve_shard(
    req: &PackRequest,
    shard: Shard,
    fragments: &std::path::Path,
    resume: bool,
    progress: &dyn Progress,
) -> Result<SolveReport, Failure> {
    let start = Instant::now();
    std::fs::create_dir_all(fragments)
        .map_err(|e| Failure::new(Exit::Io, anyhow::anyhow!("{}: {e}", fragments.display())))?;
    let path = fragment_path(fragments, shard);
    let mut report = SolveReport {
        shard: shard.to_string(),
        fragment: path.display().to_string(),
        objects: Vec::new(),
        solutions: 0,
        bytes: 0,
        resumed: false,
        seconds: 0.0,
        stage_ms: BTreeMap::new(),
    };
    if resume && path.is_file() {
        report.resumed = true;
        report.bytes = std::fs::metadata(&path).map(|m| m.len()).unwrap_or(0);
        return Ok(report);
    }
    let store = std::sync::Arc::new(crate::solutions::Solutions::recording());
    let mut req = req.clone();
    req.solver = crate::solutions::Solver::with(store.clone());
    req.shard = Some(shard);
    // A streamed solve keeps its scratch file beside its fragment.
    req.output = path.clone();
    let mut stages = Stages::new(progress);
    let (set, plan, mut matrices) = begin(&req, &mut stages)?;
    let inferred = infer_layers::infer_all(&set, &req, &plan, &mut matrices, &mut stages)
        .map_err(|e| Failure::new(Exit::Runtime, e))?;
    report.objects = inferred.models.iter().map(|m| m.name.clone()).collect();
    report.solutions = store.len();
    report.bytes = store.write_fragment(&path).map_err(|e| Failure::new(Exit::Io, e))?;
    stages.done(
        "fragment",
        &format!(
            "{} solutions of {} objects ({} bytes) to {}",
            report.solutions,
            report.objects.len(),
            report.bytes,
            path.display()
        ),
    );
    report.stage_ms = stages.ms.into_iter().collect();
    report.seconds = start.elapsed().as_secs_f64();
    Ok(report)
}

/// The fragment files in the folder `fragments`, in name order.
pub fn fragment_files(fragments: &std::path::Path) -> Result<Vec<PathBuf>, Failure> {
    let read = std::fs::read_dir(fragments)
        .map_err(|e| Failure::new(Exit::Io, anyhow::anyhow!("{}: {e}", fragments.display())))?;
    let mut files: Vec<PathBuf> = read
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.extension().is_some_and(|x| x == crate::solutions::FRAGMENT_EXTENSION) && p.is_file()
        })
        .collect();
    files.sort();
    Ok(files)
}

/// The merge of a pack split over processes: packs `req` as [`pack_request`] does, every
/// solve the fragments in the folder `fragments` hold read from them instead of solved
/// (a solve none holds is solved here). The file is the one a single process writes.
pub fn merge_fragments(
    req: &PackRequest,
    fragments: &std::path::Path,
    progress: &dyn Progress,
) -> Result<PackReport, Failure> {
    let t = Instant::now();
    let files = fragment_files(fragments)?;
    if files.is_empty() {
        return Err(Failure::new(Exit::Invalid, anyhow::anyhow!("no solve fragments (*.{}) in {}: run `pis-pack solve --shard I/N --fragments {}` first", crate::solutions::FRAGMENT_EXTENSION, fragments.display(), fragments.display())));
    }
    let store = std::sync::Arc::new(crate::solutions::Solutions::default());
    let mut held = 0;
    for f in &files {
        held += store.read_fragment(f).map_err(|e| Failure::new(Exit::Invalid, e))?;
    }
    let read_ms = t.elapsed().as_secs_f64() * 1e3;
    progress.stage(
        "fragments",
        read_ms,
        &format!("{held} solutions from {} fragment files in {}", files.len(), fragments.display()),
    );
    let mut req = req.clone();
    req.solver = crate::solutions::Solver::with(store.clone());
    let mut report = pack_request(&req, progress)?;
    let (read, solved) = store.counts();
    if solved > 0 {
        progress.note(&format!("{solved} of {} solves were in no fragment and were solved here: the shards ran with other settings, on another set, or some shard is missing", read + solved));
    }
    report.stage_ms.insert("fragments".to_string(), read_ms);
    report.fragments = Some(FragmentsReport { files: files.len(), solutions: held, read, solved });
    Ok(report)
}
