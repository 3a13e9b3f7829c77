//! One skeleton for every tool: documented exit codes, errors printed once as
//! `tool: message`, machine output on stdout, everything else on stderr.

use std::process::ExitCode;

pub use pis_pack::{Exit, Failure};

/// The help text's table of exit codes.
pub const EXIT_CODES_HELP: &str = "Exit codes: 0 ok, 1 bad arguments, 2 I/O error, 3 invalid file, 4 runtime error, 5 not supported";

/// Parses arguments with clap, mapping usage errors to exit code 1 (help and version to 0).
pub fn parse<T: clap::Parser>() -> Result<T, ExitCode> {
    T::try_parse().map_err(|e| {
        let _ = e.print();
        if e.use_stderr() {
            Exit::Usage.into()
        } else {
            Exit::Ok.into()
        }
    })
}

/// Runs a tool's body and turns its result into an exit code, printing a failure once.
pub fn finish(tool: &str, result: Result<Exit, Failure>) -> ExitCode {
    match result {
        Ok(code) => code.into(),
        Err(f) => {
            eprintln!("{tool}: {}", message(&f.error));
            f.exit.into()
        }
    }
}

/// The error and its causes, each cause only when its text is not already in the message
/// (a file error names its path and reason once).
pub fn message(err: &anyhow::Error) -> String {
    let mut out = String::new();
    for cause in err.chain() {
        let text = cause.to_string();
        if !out.contains(&text) {
            if !out.is_empty() {
                out.push_str(": ");
            }
            out.push_str(&text);
        }
    }
    out
}

/// `--depth-steps N` (pis-play, pis-bench reflective): depth shells' march steps, 1 to 64.
pub fn parse_depth_steps(s: &str) -> Result<u32, String> {
    let steps = s.parse::<u32>().ok();
    pis_play::check_depth_steps(steps)?;
    steps.ok_or_else(|| format!("--depth-steps {s:?}: expected a whole number"))
}

/// `--shading-seed` and `--reference-seed`: what seeds the tracer's shading.
pub fn parse_shading_seed(s: &str) -> Result<pis_trace::ShadingSeed, String> {
    pis_trace::ShadingSeed::from_name(s)
        .ok_or_else(|| format!("unknown shading seed {s:?} (cell or sample)"))
}

/// `--shading-cells`: `auto` (`None`) or a count of cells across the scene's diagonal.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShadingCells(pub Option<u32>);

/// `--shading-cells`' parser.
pub fn parse_shading_cells(s: &str) -> Result<ShadingCells, String> {
    match s {
        "auto" => Ok(ShadingCells(None)),
        _ => match s.parse::<u32>() {
            Ok(n) if n >= 1 => Ok(ShadingCells(Some(n))),
            _ => Err(format!("{s:?} is neither auto nor a count of cells (1 or more)")),
        },
    }
}

/// A clap parser for one of `all`, by the names `name` gives them: `--help` lists the names
/// and a name not among them is refused with the list, so that the library's names are the
/// only spelling of a mode.
pub fn one_of<T>(
    all: &'static [T],
    name: fn(T) -> &'static str,
) -> impl clap::builder::TypedValueParser<Value = T>
where
    T: Copy + Send + Sync + 'static,
{
    use clap::builder::TypedValueParser;
    clap::builder::PossibleValuesParser::new(all.iter().map(|&v| name(v))).map(move |s| {
        let found = all.iter().copied().find(|&v| name(v) == s);
        found.expect("the parser takes only the listed names")
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shading_cells_are_auto_or_a_count() {
        assert_eq!(parse_shading_cells("auto"), Ok(ShadingCells(None)));
        assert_eq!(parse_shading_cells("4096"), Ok(ShadingCells(Some(4096))));
        assert!(parse_shading_cells("0").unwrap_err().contains("\"0\""));
        assert!(parse_shading_cells("fine").is_err());
    }
}
