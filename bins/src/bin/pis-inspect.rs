//! pis-inspect: look inside a .pis file.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Parser;
use pis::cli::{finish, parse, Exit, Failure, EXIT_CODES_HELP};
use pis_eval::inspect;
use pis_format::{validate_file, PisReader, Severity};

/// Look inside a .pis file: its parameter space, objects, layers, shells, codecs, bytes per
/// kind and compression ratio; validate it against the spec; list its chunks; extract its
/// textures.
#[derive(Parser)]
#[command(name = "pis-inspect", version, after_help = EXIT_CODES_HELP)]
struct Args {
    /// The .pis file.
    file: PathBuf,
    /// Print machine-readable JSON on stdout instead of the report.
    #[arg(long)]
    json: bool,
    /// Check every rule of format-spec/SPEC.md and every checksum, decoding every
    /// codestream. Prints `error-NNNN: ...` lines; exits 3 if the file is invalid.
    #[arg(long)]
    validate: bool,
    /// List the chunks with offset, length and checksum status.
    #[arg(long)]
    chunks: bool,
    /// Write each object's textures and environment-map faces at the parameter point
    /// (--at) as linear EXR and sRGB PNG into DIR.
    #[arg(long, value_name = "DIR")]
    extract: Option<PathBuf>,
    /// Parameter point for --extract: one value per dimension, comma-separated; the nearest
    /// samples are used. Default: the first sample of every dimension.
    #[arg(long, value_name = "V1,V2,...", allow_hyphen_values = true)]
    at: Option<String>,
}

fn main() -> ExitCode {
    let args = match parse::<Args>() {
        Ok(a) => a,
        Err(code) => return code,
    };
    finish("pis-inspect", run(&args))
}

fn run(args: &Args) -> Result<Exit, Failure> {
    if args.validate || args.chunks {
        let v = validate_file(&args.file);
        if args.chunks {
            let rows = inspect::chunk_rows(&v.chunks, &v.chunk_crc_ok);
            if args.json && !args.validate {
                println!(
                    "{}",
                    serde_json::to_string_pretty(&rows)
                        .map_err(|e| Failure::new(Exit::Runtime, e))?
                );
            } else {
                print!("{}", inspect::render_chunks(&rows));
            }
        }
        if args.validate {
            if args.json {
                let issues: Vec<_> = v
                    .issues
                    .iter()
                    .map(|i| {
                        serde_json::json!({
                            "id": i.id,
                            "severity": match i.severity { Severity::Error => "error", Severity::Warning => "warning" },
                            "message": i.summary(),
                            "detail": i.detail,
                            "chunk": i.chunk.as_ref().map(|(t, _)| t.clone()),
                            "chunk_index": i.chunk.as_ref().and_then(|&(_, n)| (n != usize::MAX).then_some(n)),
                            "offset": i.offset,
                        })
                    })
                    .collect();
                let out = serde_json::json!({ "file": args.file.display().to_string(), "valid": v.is_valid(), "issues": issues });
                println!(
                    "{}",
                    serde_json::to_string_pretty(&out)
                        .map_err(|e| Failure::new(Exit::Runtime, e))?
                );
            } else {
                for i in &v.issues {
                    println!("{i}");
                }
                let errors = v.issues.iter().filter(|i| i.severity == Severity::Error).count();
                let warnings = v.issues.len() - errors;
                if v.is_valid() {
                    eprintln!("{}: valid ({warnings} warning(s))", args.file.display());
                } else {
                    eprintln!(
                        "{}: INVALID, {errors} error(s), {warnings} warning(s)",
                        args.file.display()
                    );
                }
            }
            return Ok(if v.is_valid() { Exit::Ok } else { Exit::Invalid });
        }
        if args.extract.is_none() {
            return Ok(Exit::Ok);
        }
    }

    let reader = PisReader::open(&args.file)?;
    if let Some(dir) = &args.extract {
        let point = inspect::parse_point(&reader.container().space, args.at.as_deref())
            .map_err(|e| Failure::new(Exit::Usage, e))?;
        let files = inspect::extract(&reader, &point, dir)?;
        let values: Vec<String> = reader
            .container()
            .space
            .dims
            .iter()
            .zip(&point)
            .map(|(d, &s)| format!("{}={} (sample {s})", d.name, d.values[s as usize]))
            .collect();
        if args.json {
            let out = serde_json::json!({ "point": point, "directory": dir.display().to_string(), "files": files });
            println!(
                "{}",
                serde_json::to_string_pretty(&out).map_err(|e| Failure::new(Exit::Runtime, e))?
            );
        } else {
            eprintln!(
                "extracted {} files at {} into {}",
                files.len(),
                values.join(", "),
                dir.display()
            );
        }
        return Ok(Exit::Ok);
    }
    if args.chunks {
        return Ok(Exit::Ok);
    }
    let summary = inspect::summarize(&reader);
    if args.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&summary).map_err(|e| Failure::new(Exit::Runtime, e))?
        );
    } else {
        print!("{}", inspect::render(&summary));
    }
    Ok(Exit::Ok)
}
