//! The documentation says what the tools do: README.md and docs/TOOLS.md. README.md is a
//! newcomer's first page: under 8 KB, the main job and the test command on its first screen,
//! a small picture of the pipeline, every tool linked to its section of docs/TOOLS.md, and
//! every `cargo run` command it shows runs as written. docs/TOOLS.md documents every flag each
//! tool's `--help` prints, and no flag a tool no longer has.
//!
//! The flags convention of docs/TOOLS.md: each tool's `## pis-X` section (for a tool with
//! subcommands, each subcommand's `### pis-X SUB` subsection) holds tables whose header's first cell is
//! `flag`; the first cell of every row names the flag (`--ratio`, or `-o`, `--output`). Those
//! cells are what is checked against `--help`, both ways.
//!
//! The benchmarks: docs/BENCHMARKS.md is a one-page summary (under 15 KB) whose rows link to
//! the notebook's sections in docs/benchmarks/; every relative link of those pages reaches a
//! file and, with `#anchor`, one of its headings; and every table generated from a committed
//! `pis-bench --json` report (docs/benchmarks/results/) is that report's rendering.

use std::collections::BTreeSet;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// The tools, in the order of docs/TOOLS.md.
const TOOLS: [&str; 7] =
    ["pis-trace", "pis-pack", "pis-play", "pis-inspect", "pis-diff", "pis-reencode", "pis-bench"];

/// README's one-command tour and its test command (the one .ci/run runs).
const MAIN_JOB: &str = "cargo run --release --bin pis-play -- samples/demo1/scene.toml";
const TEST_COMMAND: &str = "cargo test --release --workspace";

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn read(rel: &str) -> String {
    std::fs::read_to_string(repo().join(rel)).unwrap_or_else(|e| panic!("{rel}: {e}"))
}

fn in_ci() -> bool {
    std::env::var("CI").is_ok_and(|v| v == "true")
}

/// The built binary of a tool.
fn bin(tool: &str) -> &'static str {
    match tool {
        "pis-trace" => env!("CARGO_BIN_EXE_pis-trace"),
        "pis-pack" => env!("CARGO_BIN_EXE_pis-pack"),
        "pis-play" => env!("CARGO_BIN_EXE_pis-play"),
        "pis-inspect" => env!("CARGO_BIN_EXE_pis-inspect"),
        "pis-diff" => env!("CARGO_BIN_EXE_pis-diff"),
        "pis-reencode" => env!("CARGO_BIN_EXE_pis-reencode"),
        "pis-bench" => env!("CARGO_BIN_EXE_pis-bench"),
        other => panic!("README runs {other}, which is not one of the tools {TOOLS:?}"),
    }
}

/// README's command lines: 4-space-indented code lines, without the indent.
fn readme_code_lines(readme: &str) -> Vec<&str> {
    readme.lines().filter_map(|l| l.strip_prefix("    ")).map(str::trim_end).collect()
}

#[test]
fn readme_is_under_8_kb_with_both_commands_in_its_first_screen() {
    let readme = read("README.md");
    assert!(readme.len() < 8192, "README.md is {} bytes: a newcomer's page stays under 8192 (the reference belongs in docs/TOOLS.md)", readme.len());
    let first_screen: Vec<&str> = readme.lines().take(40).collect();
    for command in [MAIN_JOB, TEST_COMMAND] {
        assert!(
            first_screen.iter().any(|l| l.strip_prefix("    ") == Some(command)),
            "README.md's first 40 lines show `{command}` as a 4-space-indented command line"
        );
    }
    // .ci/run takes the first `^    cargo test` line of README.md and requires exactly this.
    let ci = readme
        .lines()
        .find(|l| l.starts_with("    cargo test"))
        .expect("README.md shows a test command");
    assert_eq!(ci.trim(), TEST_COMMAND, "the test command .ci/run reads from README.md");
}

#[test]
fn readme_shows_the_pipeline_picture_and_links_every_tool_to_its_section() {
    let readme = read("README.md");
    assert!(readme.contains("](docs/pipeline.png)"), "README.md shows docs/pipeline.png");
    let png = std::fs::read(repo().join("docs/pipeline.png")).expect("docs/pipeline.png");
    assert!(png.starts_with(b"\x89PNG\r\n\x1a\n"), "docs/pipeline.png is a PNG");
    assert!(
        png.len() < 100 * 1024,
        "docs/pipeline.png is {} bytes: keep it under 100 KB",
        png.len()
    );
    let tools_md = read("docs/TOOLS.md");
    for tool in TOOLS {
        let link = format!("](docs/TOOLS.md#{tool})");
        assert!(
            readme.contains(&link),
            "README.md's tool table links {tool} to its section ({link})"
        );
        assert!(
            section(&tools_md, "## ", tool).is_some(),
            "docs/TOOLS.md has a `## {tool}` section for README's link"
        );
    }
}

// ---------------------------------------------------------------------------------------------
// docs/TOOLS.md against --help

/// Runs `tool [sub] --help` and returns its long flags, `--help` and `--version` left out.
fn help_flags(tool: &str, sub: Option<&str>) -> BTreeSet<String> {
    let text = help(tool, sub);
    let mut flags = BTreeSet::new();
    for line in text.lines() {
        // Option lines are indented by 2 (`  -o, --output <OUTPUT>`) or 6 (`      --ratio <RATIO>`)
        // spaces; their descriptions, in the long format, by 10.
        let trimmed = line.trim_start();
        if line.len() - trimmed.len() > 6 || !trimmed.starts_with('-') {
            continue;
        }
        let long =
            trimmed.split(|c: char| c.is_whitespace() || c == ',').find(|t| t.starts_with("--"));
        if let Some(long) = long {
            let name = long.split(['<', '=', '[']).next().unwrap();
            if name != "--help" && name != "--version" {
                flags.insert(name.to_string());
            }
        }
    }
    flags
}

fn help(tool: &str, sub: Option<&str>) -> String {
    let mut cmd = Command::new(bin(tool));
    cmd.args(sub).arg("--help");
    let out = cmd.output().unwrap_or_else(|e| panic!("{tool} --help runs: {e}"));
    assert!(
        out.status.success(),
        "{tool} {} --help: {}",
        sub.unwrap_or(""),
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).expect("--help is UTF-8")
}

/// A tool's subcommands, from the `Commands:` list of its --help (`help` left out); none
/// when it lists no commands.
fn subcommands(tool: &str) -> Vec<String> {
    let text = help(tool, None);
    let Some((_, list)) = text.split_once("Commands:\n") else { return Vec::new() };
    list.lines()
        .take_while(|l| !l.trim().is_empty())
        .filter_map(|l| l.split_whitespace().next())
        .filter(|s| *s != "help")
        .map(String::from)
        .collect()
}

/// The text of the section headed exactly `{level}{name}` (`## pis-pack`), up to the next
/// heading of the same or a higher level.
fn section<'a>(md: &'a str, level: &str, name: &str) -> Option<&'a str> {
    let heading = format!("{level}{name}");
    let depth = level.trim_end().len();
    let mut offset = 0;
    let mut from = None;
    for line in md.split_inclusive('\n') {
        let hashes = line.chars().take_while(|&c| c == '#').count();
        if let Some(from) = from {
            if hashes > 0 && hashes <= depth && line[hashes..].starts_with(' ') {
                return Some(&md[from..offset]);
            }
        } else if line.trim_end() == heading {
            from = Some(offset + line.len());
        }
        offset += line.len();
    }
    from.map(|from| &md[from..])
}

/// The flags a section's flags tables name: every `--word` in the first cell of a row of a
/// table whose header's first cell is `flag`. A row whose first cell names no flag fails here.
fn table_flags(text: &str, what: &str) -> BTreeSet<String> {
    let mut flags = BTreeSet::new();
    let mut in_table = false;
    for line in text.lines() {
        let line = line.trim();
        if !line.starts_with('|') {
            in_table = false;
            continue;
        }
        let first = line.split('|').nth(1).unwrap_or("").trim();
        if !in_table {
            in_table = first == "flag";
            continue;
        }
        if first.chars().all(|c| c == '-' || c == ':') {
            continue; // the header's separator row
        }
        let names: Vec<&str> = first
            .split(|c: char| c.is_whitespace() || c == ',' || c == '`')
            .filter(|t| t.starts_with("--"))
            .collect();
        assert!(
            !names.is_empty(),
            "{what}: the flags table row {line:?} names no --flag in its first cell"
        );
        flags.extend(names.into_iter().map(String::from));
    }
    flags
}

/// Every place of docs/TOOLS.md whose flags tables are checked: (what, the section's text,
/// the flags its --help prints).
fn scopes(tools_md: &str) -> Vec<(String, &str, BTreeSet<String>)> {
    let mut positions = Vec::new();
    let mut scopes = Vec::new();
    for tool in TOOLS {
        let text = section(tools_md, "## ", tool)
            .unwrap_or_else(|| panic!("docs/TOOLS.md has no `## {tool}` section"));
        positions.push((tools_md.find(&format!("\n## {tool}\n")).unwrap_or(0), tool));
        // A tool with subcommands documents each in a `### TOOL SUB` subsection.
        let subs = subcommands(tool);
        assert!(tool != "pis-bench" || !subs.is_empty(), "pis-bench --help lists subcommands");
        let mut all = help_flags(tool, None);
        for sub in subs {
            let name = format!("{tool} {sub}");
            let text = section(text, "### ", &name).unwrap_or_else(|| {
                panic!("docs/TOOLS.md has no `### {name}` subsection under `## {tool}`")
            });
            let flags = help_flags(tool, Some(&sub));
            all.extend(flags.iter().cloned());
            scopes.push((name, text, flags));
        }
        // The section as a whole documents only flags the tool or some subcommand has.
        scopes.push((tool.to_string(), text, all));
    }
    positions.sort();
    let order: Vec<&str> = positions.iter().map(|p| p.1).collect();
    assert_eq!(order, TOOLS, "docs/TOOLS.md's tool sections, in order");
    scopes
}

#[test]
fn every_flag_of_every_tool_is_documented_in_tools_md() {
    let tools_md = read("docs/TOOLS.md");
    let mut missing = Vec::new();
    for (what, text, flags) in scopes(&tools_md) {
        assert!(!flags.is_empty(), "{what} --help: no flags parsed; has its format changed?");
        let documented = table_flags(text, &what);
        for flag in flags.difference(&documented) {
            missing.push(format!(
                "{what}: {flag} (printed by --help) has no row in the flags table of its section"
            ));
        }
    }
    assert!(missing.is_empty(), "docs/TOOLS.md misses flags:\n  {}", missing.join("\n  "));
}

#[test]
fn tools_md_documents_only_flags_the_tools_have() {
    let tools_md = read("docs/TOOLS.md");
    let mut gone = Vec::new();
    for (what, text, flags) in scopes(&tools_md) {
        for flag in table_flags(text, &what).difference(&flags) {
            gone.push(format!("{what}: {flag} is in the flags table but not in --help"));
        }
    }
    assert!(
        gone.is_empty(),
        "docs/TOOLS.md documents flags the tools do not have:\n  {}",
        gone.join("\n  ")
    );
}

// ---------------------------------------------------------------------------------------------
// README's commands, run as written

/// Copies `from` into `to`, every `.pis-cache` folder (traces and packs of earlier runs) left
/// out, so the commands start from what a fresh checkout holds.
fn copy_tree(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap_or_else(|e| panic!("{}: {e}", to.display()));
    for e in std::fs::read_dir(from)
        .unwrap_or_else(|e| panic!("{}: {e}", from.display()))
        .map(Result::unwrap)
    {
        let (src, dst) = (e.path(), to.join(e.file_name()));
        let kind = e.file_type().expect("file type");
        if kind.is_dir() {
            if e.file_name() != ".pis-cache" && e.file_name() != "target" {
                copy_tree(&src, &dst);
            }
        } else if kind.is_file() {
            std::fs::copy(&src, &dst).unwrap_or_else(|e| panic!("copy {}: {e}", src.display()));
        }
    }
}

/// Runs `program args` in `dir` without a display (pis-play draws headless), stdout and stderr
/// read as they come; killed after `limit` (a hang fails the test).
fn run_in(dir: &Path, program: &str, args: &[&str], limit: Duration) -> Output {
    let mut child = Command::new(program)
        .args(args)
        .current_dir(dir)
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap_or_else(|e| panic!("{program} runs: {e}"));
    let drain = |mut r: Box<dyn Read + Send>| {
        std::thread::spawn(move || {
            let mut buf = Vec::new();
            let _ = r.read_to_end(&mut buf);
            buf
        })
    };
    let stdout = drain(Box::new(child.stdout.take().unwrap()));
    let stderr = drain(Box::new(child.stderr.take().unwrap()));
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().expect("wait") {
            break status;
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            panic!("{program} {args:?} hung for {} s", limit.as_secs());
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    Output { status, stdout: stdout.join().unwrap(), stderr: stderr.join().unwrap() }
}

/// Every `cargo run --release --bin TOOL -- ARGS` line of README.md is run as the built TOOL
/// with exactly ARGS, in README order, in a folder holding a copy of samples/ (the commands
/// use relative paths and write demo1-set and demo1.pis there): each exits 0. The samples'
/// scene.toml files are CI-sized (160×120, 4 spp), so this is the size README's commands run
/// at. Left out: the chart command `pis-bench -- all --preset ci`, which
/// tests/bench.rs `readme_chart_command_runs_at_its_smallest_preset` takes from README.md and
/// runs. A command that finds no GPU adapter is skipped with a message, and fails in CI.
#[test]
fn readme_commands_run_as_written() {
    let readme = read("README.md");
    let commands: Vec<(&str, Vec<&str>)> = readme_code_lines(&readme)
        .into_iter()
        .filter_map(|l| l.strip_prefix("cargo run --release --bin "))
        .map(|rest| {
            let (tool, args) = rest.split_once(" -- ").unwrap_or((rest, ""));
            (tool.trim(), args.split_whitespace().collect())
        })
        .collect();
    assert!(
        commands.iter().any(|(tool, _)| *tool == "pis-play"),
        "README.md shows pis-play commands"
    );
    let dir = tempfile::tempdir().expect("temporary directory");
    copy_tree(&repo().join("samples"), &dir.path().join("samples"));
    for (tool, args) in &commands {
        let shown = format!("cargo run --release --bin {tool} -- {}", args.join(" "));
        if *tool == "pis-bench" && args.first() == Some(&"all") {
            eprintln!(
                "`{shown}`: run by tests/bench.rs readme_chart_command_runs_at_its_smallest_preset"
            );
            continue;
        }
        eprintln!("README's `{shown}`");
        let out = run_in(dir.path(), bin(tool), args, Duration::from_secs(1200));
        let err = String::from_utf8_lossy(&out.stderr);
        if !out.status.success() && err.contains("no GPU adapter") {
            assert!(!in_ci(), "README's `{shown}`: {err}");
            eprintln!("README's `{shown}`: skipped: {err}");
            continue;
        }
        assert!(out.status.success(), "README's `{shown}` exits {:?}:\n{err}", out.status.code());
    }
    assert!(
        dir.path().join("demo1.pis").is_file(),
        "README's step-by-step commands write demo1.pis"
    );
}

/// The benchmark summary's limit: one page a reader takes in, the notebook holds the rest.
const SUMMARY_LIMIT: usize = 15 * 1024;
/// The lines around a block of the notebook rendered from a committed `pis-bench --json`
/// report: a line `<!-- generated from results/NAME.json: do not edit -->`, the table, a line
/// [`GENERATED_END`].
const GENERATED_START: &str = "<!-- generated from ";
const GENERATED_END: &str = "<!-- end generated -->";

/// docs/BENCHMARKS.md and every page of docs/benchmarks/, as paths relative to the repository.
fn benchmark_pages() -> Vec<String> {
    let mut pages = vec!["docs/BENCHMARKS.md".to_string()];
    let dir = repo().join("docs/benchmarks");
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".md"))
        .collect();
    names.sort();
    pages.extend(names.into_iter().map(|n| format!("docs/benchmarks/{n}")));
    pages
}

/// Lines outside fenced code blocks.
fn prose_lines(md: &str) -> Vec<&str> {
    let mut fenced = false;
    md.lines()
        .filter(|l| {
            if l.trim_start().starts_with("```") {
                fenced = !fenced;
                return false;
            }
            !fenced
        })
        .collect()
}

/// GitHub's anchor of a heading: lower case, every character but letters, digits, `-`, `_`
/// and spaces dropped, spaces turned into `-`.
fn slug(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter(|c| c.is_alphanumeric() || matches!(c, '-' | '_' | ' '))
        .map(|c| if c == ' ' { '-' } else { c })
        .collect()
}

/// The anchors of a page's headings; a repeated one gets `-1`, `-2`, … as on GitHub.
fn anchors(md: &str) -> BTreeSet<String> {
    let mut seen = BTreeSet::new();
    for line in prose_lines(md) {
        let hashes = line.chars().take_while(|&c| c == '#').count();
        let Some(text) = line.get(hashes..).and_then(|t| t.strip_prefix(' ')) else { continue };
        if hashes == 0 || hashes > 6 {
            continue;
        }
        let base = slug(text);
        let mut anchor = base.clone();
        let mut n = 0;
        while seen.contains(&anchor) {
            n += 1;
            anchor = format!("{base}-{n}");
        }
        seen.insert(anchor);
    }
    seen
}

/// The targets of a page's inline links `[text](target)`, outside fenced code.
fn link_targets(md: &str) -> Vec<String> {
    let mut targets = Vec::new();
    for line in prose_lines(md) {
        let mut rest = line;
        while let Some(i) = rest.find("](") {
            rest = &rest[i + 2..];
            let Some(end) = rest.find(')') else { break };
            targets.push(rest[..end].trim().to_string());
            rest = &rest[end..];
        }
    }
    targets
}

#[test]
fn benchmark_summary_is_one_page() {
    let md = read("docs/BENCHMARKS.md");
    assert!(
        md.len() < SUMMARY_LIMIT,
        "docs/BENCHMARKS.md is {} bytes: the summary stays under {SUMMARY_LIMIT} (measurements belong in docs/benchmarks/)",
        md.len()
    );
}

/// Every relative link of the summary and the notebook names a file that exists and, with
/// `#anchor`, a heading of that file.
#[test]
fn benchmark_links_resolve_to_files_and_headings() {
    let mut broken = Vec::new();
    for page in benchmark_pages() {
        let md = read(&page);
        let dir = Path::new(&page).parent().expect("a folder").to_path_buf();
        for target in link_targets(&md) {
            if target.contains("://") || target.starts_with("mailto:") {
                continue;
            }
            let (file, anchor) = target.split_once('#').unwrap_or((&target, ""));
            let rel = if file.is_empty() { PathBuf::from(&page) } else { dir.join(file) };
            let path = repo().join(&rel);
            if !path.exists() {
                broken.push(format!("{page}: ({target}): no file {}", rel.display()));
            } else if !anchor.is_empty() {
                let text = std::fs::read_to_string(&path).unwrap_or_default();
                if !anchors(&text).contains(anchor) {
                    broken.push(format!("{page}: ({target}): no heading #{anchor}"));
                }
            }
        }
    }
    assert!(broken.is_empty(), "{} broken link(s):\n{}", broken.len(), broken.join("\n"));
}

/// A PSNR cell of a `pis-bench rd` report's row: the PSNR, pis-pack's prediction in
/// parentheses, the achieved ratio and the CRF where the report gives them.
/// `x` to `digits` decimals, without the trailing zeros (96.04 → "96", 98.17 → "98.2" at one).
fn rounded(x: f64, digits: usize) -> String {
    let s = format!("{x:.digits$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

fn rd_cell(row: &serde_json::Value) -> String {
    let num = |k: &str| row.get(k).and_then(serde_json::Value::as_f64);
    let mut cell = format!("{:.2}", num("psnr_db").expect("psnr_db"));
    if let Some(p) = num("psnr_db_predicted") {
        cell += &format!(" ({p:.2})");
    }
    if let Some(r) = num("ratio") {
        cell += &format!(" at {}:1", rounded(r, 1));
    }
    if let Some(c) = num("crf") {
        cell += &format!(", CRF {}", rounded(c, 2));
    }
    if row.get("reached").and_then(serde_json::Value::as_bool) == Some(false) {
        cell += ", budget not reached";
    }
    cell
}

/// The markdown table of a `pis-bench rd --json` report: a row per method, a column per
/// target ratio, and the PSNR's scope.
fn rd_table(report: &serde_json::Value) -> String {
    let rows = report["rows"].as_array().expect("rows");
    let mut ratios: Vec<f64> = Vec::new();
    let mut methods: Vec<&str> = Vec::new();
    for r in rows {
        let t = r["target_ratio"].as_f64().expect("target_ratio");
        if !ratios.contains(&t) {
            ratios.push(t);
        }
        let m = r["method"].as_str().expect("method");
        if !methods.contains(&m) {
            methods.push(m);
        }
    }
    ratios.sort_by(f64::total_cmp);
    let mut out = String::from("| method |");
    for t in &ratios {
        out += &format!(" {t}:1 |");
    }
    out += " scope |\n|---|";
    out += &"---|".repeat(ratios.len() + 1);
    for m in methods {
        let of = |t: f64| rows.iter().find(|r| r["method"] == m && r["target_ratio"] == t);
        out += &format!("\n| {m} |");
        for &t in &ratios {
            out += &format!(" {} |", of(t).map_or("—".to_string(), rd_cell));
        }
        let scope = rows.iter().find(|r| r["method"] == m).and_then(|r| r["psnr_scope"].as_str());
        out += match scope {
            Some("whole-image-played") => " played, whole image (predicted, covered pixels) |",
            Some("covered-predicted") => " predicted, covered pixels |",
            Some("whole-image") => " decoded, whole image |",
            _ => " |",
        };
    }
    out
}

/// Every generated block of the notebook is the rendering of the report it names, so that
/// its figures are the committed result file's. `PIS_BLESS=1 cargo test --release -p pis
/// --test docs` rewrites the blocks from the files instead (docs/benchmarks/README.md).
#[test]
fn generated_benchmark_tables_are_current() {
    let bless = std::env::var("PIS_BLESS").is_ok_and(|v| v == "1");
    let mut stale = Vec::new();
    let mut blocks = 0;
    for page in benchmark_pages() {
        let md = read(&page);
        let dir = Path::new(&page).parent().expect("a folder").to_path_buf();
        let mut out = String::new();
        let mut rest = md.as_str();
        while let Some(i) = rest.find(&format!("\n{GENERATED_START}")).map(|i| i + 1) {
            let line_end = i + rest[i..].find('\n').expect("the marker's line ends");
            let marker = &rest[i..line_end];
            let name = marker[GENERATED_START.len()..].split(':').next().expect("a file name");
            let end = rest[line_end..].find(GENERATED_END).map(|j| line_end + j);
            let end = end.unwrap_or_else(|| panic!("{page}: `{marker}` has no `{GENERATED_END}`"));
            let json = read(&dir.join(name).to_string_lossy());
            let report: serde_json::Value =
                serde_json::from_str(&json).unwrap_or_else(|e| panic!("{page}: {name}: {e}"));
            let table = rd_table(&report);
            if rest[line_end + 1..end].trim_end() != table {
                stale.push(format!("{page}: the table from {name}"));
            }
            out += &format!("{}\n{table}\n", &rest[..line_end]);
            rest = &rest[end..];
            blocks += 1;
        }
        out += rest;
        if bless && out != md {
            let tmp = repo().join(format!("{page}.bless"));
            std::fs::write(&tmp, out).expect("write the page");
            std::fs::rename(&tmp, repo().join(&page)).expect("replace the page");
        }
    }
    assert!(blocks > 0, "the notebook holds generated tables");
    assert!(
        bless || stale.is_empty(),
        "generated tables differ from their result files (regenerate: PIS_BLESS=1 cargo test --release -p pis --test docs):\n{}",
        stale.join("\n")
    );
}

#[test]
fn heading_anchors_follow_githubs_rule() {
    assert_eq!(slug("`paper` preset (640×480, 16 spp)"), "paper-preset-640480-16-spp");
    assert_eq!(
        slug("Parameter blocks: which dimensions are staggered (`--stagger auto|always`)"),
        "parameter-blocks-which-dimensions-are-staggered---stagger-autoalways"
    );
    assert_eq!(
        anchors("# A\n```\n# not a heading\n```\n## A\n").into_iter().collect::<Vec<_>>(),
        ["a", "a-1"]
    );
    assert_eq!(link_targets("[x](a.md#b) and [y](../c.md)"), ["a.md#b", "../c.md"]);
}
