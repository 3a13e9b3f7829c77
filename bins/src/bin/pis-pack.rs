//! pis-pack: a ray-traced set (or a scene.toml, traced first) to a `.pis` container.
//!
//! Exit codes: 0 ok, 1 bad arguments, 2 I/O, 3 invalid input, 4 runtime error, 5 unsupported
//! (`--matrix probe` without a GPU adapter).

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Parser;
use pis::cli::{self, Exit, Failure};
use pis::pack_args::PackOptions;
use pis_pack::{
    merge_fragments, pack_request, print_report, solve_shard, PackReport, Shard, StderrProgress,
};

/// Infer, compress and write the parameterized textures of a ray-traced set.
///
/// The work can be split over processes or machines that share a folder: `pis-pack solve
/// --shard I/N` solves every N-th object into a fragment file, and `pis-pack merge` reads
/// the fragments and writes the file, the same bytes as one `pis-pack` run.
#[derive(Parser, Debug)]
#[command(name = "pis-pack", version, about, after_help = cli::EXIT_CODES_HELP, args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    /// A ray-traced set directory, or a scene.toml to trace first (into .pis-cache beside it).
    #[arg(required = true)]
    input: Option<PathBuf>,
    /// The container to write (atomically; nothing is left on error).
    #[arg(short, long, required = true)]
    output: Option<PathBuf>,
    /// The set's scene.toml (default: the scene.toml set.json records, else SET_DIR/scene.toml).
    #[arg(long)]
    scene: Option<PathBuf>,
    #[command(flatten)]
    pack: PackOptions,
    /// Print the closing report as JSON on stdout.
    #[arg(long)]
    json: bool,
}

#[derive(clap::Subcommand, Debug)]
enum Command {
    /// Solve the textures of shard I of N of the objects (every N-th object that covers a
    /// pixel, in scene order, from the I-th) into a fragment file in the folder --fragments.
    /// Give the same pack options as the merge.
    Solve {
        #[command(flatten)]
        set: SetArgs,
        /// This process's shard: I/N, I counted from 0.
        #[arg(long, value_name = "I/N")]
        shard: Shard,
        /// The folder of the fragment files, shared by the shards and the merge (created if
        /// missing).
        #[arg(long, value_name = "DIR")]
        fragments: PathBuf,
        /// Keep this shard's fragment when it is there already (a re-run after an
        /// interruption does only what is missing).
        #[arg(long)]
        resume: bool,
    },
    /// Pack the set with the solves read from the fragment files in --fragments (a solve no
    /// fragment holds is solved here) and write the container: the same bytes as one
    /// `pis-pack` run with the same options.
    Merge {
        #[command(flatten)]
        set: SetArgs,
        /// The folder of the solve shards' fragment files.
        #[arg(long, value_name = "DIR")]
        fragments: PathBuf,
        /// The container to write (atomically; nothing is left on error).
        #[arg(short, long)]
        output: PathBuf,
    },
}

/// What `solve` and `merge` read and how: the set, its scene, the pack's options, the
/// report's form.
#[derive(clap::Args, Debug)]
struct SetArgs {
    /// The ray-traced set directory (or scene.toml).
    input: PathBuf,
    /// The set's scene.toml (default: the scene.toml set.json records).
    #[arg(long)]
    scene: Option<PathBuf>,
    #[command(flatten)]
    pack: PackOptions,
    /// Print the report as JSON on stdout.
    #[arg(long)]
    json: bool,
}

fn json_out<T: serde::Serialize>(value: &T) -> Result<(), Failure> {
    let s = serde_json::to_string_pretty(value).map_err(|e| Failure::new(Exit::Runtime, e))?;
    println!("{s}");
    Ok(())
}

fn finish_pack(report: &PackReport, json: bool) -> Result<Exit, Failure> {
    print_report(report, &mut std::io::stderr()).map_err(|e| Failure::new(Exit::Io, e))?;
    if json {
        json_out(report)?;
    }
    Ok(Exit::Ok)
}

fn run(cli: Cli) -> Result<Exit, Failure> {
    match cli.command {
        Some(Command::Solve {
            set: SetArgs { input, scene, pack, json },
            shard,
            fragments,
            resume,
        }) => {
            let req = pack.request(input, scene, PathBuf::new())?;
            let r = solve_shard(&req, shard, &fragments, resume, &StderrProgress)?;
            if r.resumed {
                eprintln!(
                    "pis-pack: shard {}: {} is there already (--resume): nothing to do",
                    r.shard, r.fragment
                );
            } else {
                eprintln!("pis-pack: shard {}: {} objects solved ({}), {} solutions, {} bytes to {}, {:.1} s", r.shard, r.objects.len(), r.objects.join(", "), r.solutions, r.bytes, r.fragment, r.seconds);
            }
            if json {
                json_out(&r)?;
            }
            Ok(Exit::Ok)
        }
        Some(Command::Merge { set: SetArgs { input, scene, pack, json }, fragments, output }) => {
            let req = pack.request(input, scene, output)?;
            finish_pack(&merge_fragments(&req, &fragments, &StderrProgress)?, json)
        }
        None => {
            let (Some(input), Some(output)) = (cli.input, cli.output) else {
                return Err(Failure::new(
                    Exit::Usage,
                    anyhow::anyhow!("give INPUT and -o OUTPUT, or a subcommand (solve, merge)"),
                ));
            };
            let req = cli.pack.request(input, cli.scene, output)?;
            finish_pack(&pack_request(&req, &StderrProgress)?, cli.json)
        }
    }
}

fn main() -> ExitCode {
    match cli::parse::<Cli>() {
        Ok(c) => cli::finish("pis-pack", run(c)),
        Err(code) => code,
    }
}
