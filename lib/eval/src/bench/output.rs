//! The files an evaluation writes into its output folder (CSV, SVG, JSON) and the row it
//! records in docs/benchmarks/bench.md when asked.

use std::path::{Path, PathBuf};

use crate::chart::{write_svg, Chart, Series};
use crate::report::{record_row, write_atomic, Csv, Stamp};
use anyhow::{anyhow, Result};

/// Creates the output folder when missing.
pub fn ensure_dir(dir: &Path) -> Result<()> {
    std::fs::create_dir_all(dir)
        .map_err(|e| anyhow!("cannot create the output folder {}: {e}", dir.display()))
}

/// Writes `NAME.csv` and `NAME.svg` into `dir`; returns their paths.
pub fn write_chart(
    dir: &Path,
    name: &str,
    csv: &Csv,
    chart: &Chart,
    series: &[Series],
) -> Result<(PathBuf, PathBuf)> {
    let (c, s) = (dir.join(format!("{name}.csv")), dir.join(format!("{name}.svg")));
    write_atomic(&c, csv.text().as_bytes())?;
    write_svg(&s, chart, series)?;
    Ok((c, s))
}

/// The benchmark notebook's page of pis-bench runs, docs/benchmarks/bench.md, in the source
/// tree this binary was built from.
pub fn notebook_page() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../docs/benchmarks/bench.md")
}

/// Records one run under "pis-bench runs" in docs/benchmarks/bench.md: keyed by evaluation
/// and scene, stamped with the machine and the exact command.
pub fn record(eval: &str, stamp: &Stamp, summary: &str) -> Result<()> {
    let head = "| evaluation · scene | summary | machine | command |\n|---|---|---|---|";
    let key = format!("{eval} · {}", stamp.scene);
    let row = format!(
        "| {key} | {summary} | {} | `{}` |",
        stamp.machine,
        stamp.command.replace('|', "\\|")
    );
    record_row(&notebook_page(), "pis-bench runs", head, &key, &row)
}
