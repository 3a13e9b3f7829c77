//! Report files: atomic writes, CSV tables, the stamp (machine, scene, command) every figure
//! carries, and rows recorded in docs/benchmarks/bench.md.

use std::path::Path;

use anyhow::{anyhow, Context, Result};

/// Writes `bytes` to `path` through a temporary file beside it and a rename.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let dir = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    let name = path.file_name().ok_or_else(|| anyhow!("{}: not a file path", path.display()))?;
    let tmp = dir.join(format!(".{}.tmp{}", name.to_string_lossy(), std::process::id()));
    std::fs::write(&tmp, bytes).with_context(|| format!("writing {}", tmp.display()))?;
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        anyhow!("renaming {} to {}: {e}", tmp.display(), path.display())
    })
}

/// Where and how a figure was measured.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Stamp {
    pub machine: String,
    pub scene: String,
    pub command: String,
}

impl Stamp {
    /// The stamp of this process: the machine described from /proc/cpuinfo, the command
    /// line as given.
    pub fn here(scene: &str) -> Stamp {
        let args: Vec<String> = std::env::args().collect();
        let prog = args
            .first()
            .map(|a| {
                Path::new(a).file_name().map_or(a.clone(), |f| f.to_string_lossy().into_owned())
            })
            .unwrap_or_default();
        let rest: Vec<String> = args
            .iter()
            .skip(1)
            .map(|a| if a.contains(' ') { format!("'{a}'") } else { a.clone() })
            .collect();
        Stamp {
            machine: machine(),
            scene: scene.to_string(),
            command: format!("{prog} {}", rest.join(" ")).trim().to_string(),
        }
    }

    /// The stamp as chart footer lines.
    pub fn lines(&self) -> Vec<String> {
        vec![
            format!("machine: {}", self.machine),
            format!("scene: {}", self.scene),
            format!("command: {}", self.command),
        ]
    }
}

/// "N vCPU MODEL, MEMORY GiB": what the figures ran on.
pub fn machine() -> String {
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|m| m.trim().to_string())
        })
        .unwrap_or_else(|| std::env::consts::ARCH.to_string());
    let n = std::thread::available_parallelism().map_or(1, |n| n.get());
    let mem = std::fs::read_to_string("/proc/meminfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .next()
                .and_then(|l| l.split_whitespace().nth(1))
                .and_then(|k| k.parse::<f64>().ok())
        })
        .map(|kb| format!(", {:.0} GiB", kb / 1048576.0))
        .unwrap_or_default();
    format!("{n} vCPU {cpu}{mem}")
}

/// A CSV table: a header and rows of fields, quoted where needed.
#[derive(Clone, Debug, Default)]
pub struct Csv {
    pub header: Vec<String>,
    pub rows: Vec<Vec<String>>,
}

fn field(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

impl Csv {
    pub fn new(header: &[&str]) -> Csv {
        Csv { header: header.iter().map(|s| s.to_string()).collect(), rows: vec![] }
    }

    pub fn push(&mut self, row: Vec<String>) {
        self.rows.push(row);
    }

    pub fn text(&self) -> String {
        let mut out = String::new();
        for r in std::iter::once(&self.header).chain(&self.rows) {
            out.push_str(&r.iter().map(|f| field(f)).collect::<Vec<_>>().join(","));
            out.push('\n');
        }
        out
    }
}

/// Puts `row` (a Markdown table row starting `| key |`) under `## heading` of the Markdown
/// file `path`: replaces the row with the same key, or appends it after the section's last
/// table row; creates the section (with `table_head`) at the end of the file when missing.
pub fn record_row(
    path: &Path,
    heading: &str,
    table_head: &str,
    key: &str,
    row: &str,
) -> Result<()> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    let title = format!("## {heading}");
    let start = match lines.iter().position(|l| l.trim_end() == title) {
        Some(i) => i,
        None => {
            if lines.last().is_some_and(|l| !l.is_empty()) {
                lines.push(String::new());
            }
            lines.push(title);
            lines.push(String::new());
            lines.extend(table_head.lines().map(str::to_string));
            lines.len() - table_head.lines().count() - 2
        }
    };
    let end = lines
        .iter()
        .enumerate()
        .skip(start + 1)
        .find(|(_, l)| l.starts_with("## "))
        .map_or(lines.len(), |(i, _)| i);
    let prefix = format!("| {key} |");
    if let Some(i) = (start..end).find(|&i| lines[i].starts_with(&prefix)) {
        lines[i] = row.to_string();
    } else if let Some(i) = (start..end).rev().find(|&i| lines[i].starts_with('|')) {
        lines.insert(i + 1, row.to_string());
    } else {
        lines.insert(end, row.to_string());
    }
    let mut out = lines.join("\n");
    out.push('\n');
    write_atomic(path, out.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_quotes_fields_with_commas() {
        let mut c = Csv::new(&["a", "b"]);
        c.push(vec!["x,y".into(), "z".into()]);
        assert_eq!(c.text(), "a,b\n\"x,y\",z\n");
    }

    #[test]
    fn record_row_creates_then_replaces() {
        let dir = std::env::temp_dir().join(format!("pis-eval-report-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let md = dir.join("B.md");
        std::fs::write(&md, "# B\n\n## other\n\ntext\n").unwrap();
        let head = "| run | value |\n|---|---|";
        record_row(&md, "bench", head, "rd demo1", "| rd demo1 | 1 |").unwrap();
        record_row(&md, "bench", head, "rd demo2", "| rd demo2 | 2 |").unwrap();
        record_row(&md, "bench", head, "rd demo1", "| rd demo1 | 3 |").unwrap();
        let t = std::fs::read_to_string(&md).unwrap();
        assert!(t.contains("## other\n\ntext\n"), "{t}");
        assert!(
            t.contains("| run | value |\n|---|---|\n| rd demo1 | 3 |\n| rd demo2 | 2 |\n"),
            "{t}"
        );
        assert!(!t.contains("| rd demo1 | 1 |"));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
