//! pis-reencode: a container's textures coded again with another codec, rate or gamma.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Parser;
use pis::cli::{self, Exit, Failure};
use pis_codec::CodecId;
use pis_eval::reencode::{print_report, reencode, ReencodeRequest};

/// Code every texture of a .pis file (all parameter samples, all layers) again: from the
/// file's lossless master when it carries one (pis-pack --keep-master: the textures as
/// solved, and pis-pack's allocation weights, so the result is what a direct pack at the new
/// settings gives), else from its decoded level images. New adaptive Laplacian pyramids per
/// parameter block, equal-slope storage allocation over all level images weighted by screen
/// area (as pis-pack), the chosen codec. Geometry, cameras, parameter space and placements are
/// copied; provenance records the re-encoding. The output is written atomically, read back
/// and compared with the input (and, with a master, both with the master).
#[derive(Parser, Debug)]
#[command(
    name = "pis-reencode",
    version,
    after_help = "Exit codes: 0 ok, 1 bad arguments, 2 I/O error, 3 invalid input file, 4 runtime error, 5 not supported"
)]
struct Cli {
    /// The .pis file to re-encode.
    input: PathBuf,
    /// The container to write (atomically; nothing is left on error).
    #[arg(short, long)]
    output: PathBuf,
    /// Level-image codec.
    #[arg(long, default_value = "wavelet", value_parser = pis::cli::one_of(&CodecId::ALL, CodecId::name))]
    codec: CodecId,
    /// Target compression ratio: level-image bytes = raw image bytes / R. Default (lossy
    /// codecs): the input's level-image bytes.
    #[arg(long, conflicts_with = "psnr", allow_hyphen_values = true)]
    ratio: Option<f64>,
    /// Target PSNR in dB of the stored (gamma-compensated) textures, screen-area weighted,
    /// instead of a ratio.
    #[arg(long, allow_hyphen_values = true)]
    psnr: Option<f64>,
    /// Display gamma of the compensation for lossy codecs (default 2.2); lossless and raw
    /// store linear values (gamma 1).
    #[arg(long, allow_hyphen_values = true)]
    gamma: Option<f32>,
    /// Write the lossless master into the output: the input's, or one made from the decoded
    /// textures of an input whose level images are all lossless or raw. Without it the
    /// output carries no master.
    #[arg(long)]
    keep_master: bool,
    /// Parameter-block sizes of the output: N (every dimension) or NxM (one per dimension),
    /// as pis-pack's --block; the block origins are staggered per object again as pis-pack
    /// staggers them. Default: the input's blocks.
    #[arg(long, value_parser = parse_block)]
    block: Option<BlockSizes>,
    /// The allocation's max-MSE constraint (thesis 4.8), as pis-pack's --max-mse-ratio: `off`
    /// or α above 1 (`auto` needs the traced set and means 1.25 here). Default: what the
    /// input's provenance records its writer applied (1.25 where it records nothing).
    #[arg(long, value_name = "off|ALPHA")]
    max_mse_ratio: Option<pis_pack::MaxMse>,
    /// Memory budget in GiB for the decoded textures and the new pyramids: an input that
    /// would take more is refused before decoding (exit 5). Default: 4, or half the memory
    /// available where that is less.
    #[arg(long, value_name = "GB", value_parser = pis_eval::budget::parse_memory)]
    memory: Option<f64>,
    /// Print the report as JSON on stdout.
    #[arg(long)]
    json: bool,
}

/// `--block`: one size, or one per dimension.
#[derive(Clone, Debug)]
struct BlockSizes(Vec<u32>);

fn parse_block(s: &str) -> Result<BlockSizes, String> {
    pis_pack::parse_sizes(s).map(BlockSizes)
}

fn run(cli: Cli) -> Result<Exit, Failure> {
    let target = pis_pack::Target::given(cli.ratio, cli.psnr)
        .map_err(|e| Failure::new(Exit::Usage, anyhow::anyhow!(e)))?;
    let req = ReencodeRequest {
        input: cli.input,
        output: cli.output,
        codec: cli.codec,
        target,
        gamma: cli.gamma,
        keep_master: cli.keep_master,
        block: cli.block.map(|b| b.0),
        max_mse: cli.max_mse_ratio,
        memory: pis_eval::budget::budget_bytes(cli.memory),
    };
    let report = reencode(&req)?;
    print_report(&report, &mut std::io::stderr()).map_err(|e| Failure::new(Exit::Io, e))?;
    if cli.json {
        let s =
            serde_json::to_string_pretty(&report).map_err(|e| Failure::new(Exit::Runtime, e))?;
        println!("{s}");
    }
    Ok(Exit::Ok)
}

fn main() -> ExitCode {
    match cli::parse::<Cli>() {
        Ok(c) => cli::finish("pis-reencode", run(c)),
        Err(code) => code,
    }
}
