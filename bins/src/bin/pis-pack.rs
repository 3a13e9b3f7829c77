//! pis-pack: a ray-traced set (or a scene.toml, traced first) to a `.pis` container.
//!
//! Exit codes: 0 ok, 1 bad arguments, 2 I/O, 3 invalid input, 4 runtime error, 5 unsupported
//! (`--matrix probe` without a GPU adapter).

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Parser;
use pis::cli::{self, Exit, Failure};
use pis_pack::{pack_request, print_report, StderrProgress};
use pis::pack_args::PackOptions;

/// Infer, compress and write the parameterized textures of a ray-traced set.
#[derive(Parser, Debug)]
#[command(name = "pis-pack", version, about, after_help = cli::EXIT_CODES_HELP)]
struct Cli {
    /// A ray-traced set directory, or a scene.toml to trace first (into .pis-cache beside it).
    input: PathBuf,
    /// The container to write (atomically; nothing is left on error).
    #[arg(short, long)]
    output: PathBuf,
    /// The set's scene.toml (default: the scene.toml set.json records, else SET_DIR/scene.toml).
    #[arg(long)]
    scene: Option<PathBuf>,
    #[command(flatten)]
    pack: PackOptions,
    /// Print the closing report as JSON on stdout.
    #[arg(long)]
    json: bool,
}

fn run(cli: Cli) -> Result<Exit, Failure> {
    let req = cli.pack.request(cli.input, cli.scene, cli.output)?;
    let report = pack_request(&req, &StderrProgress)?;
    print_report(&report, &mut std::io::stderr()).map_err(|e| Failure::new(Exit::Io, e))?;
    if cli.json {
        let s = serde_json::to_string_pretty(&report).map_err(|e| Failure::new(Exit::Runtime, e))?;
        println!("{s}");
    }
    Ok(Exit::Ok)
}

fn main() -> ExitCode {
    match cli::parse::<Cli>() {
        Ok(c) => cli::finish("pis-pack", run(c)),
        Err(code) => code,
    }
}
