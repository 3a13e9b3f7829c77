//! `pis-samples DIR`: regenerates the sample scenes into DIR (normally `samples/`).

use std::path::PathBuf;
use std::process::ExitCode;

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let root = match args.as_slice() {
        [dir] if !dir.starts_with('-') => PathBuf::from(dir),
        _ => {
            eprintln!(
                "usage: pis-samples DIR   (writes DIR/demo1, DIR/demo2, DIR/teapot-pem, DIR/teapot-glossy, DIR/glass, DIR/wild/*)"
            );
            return ExitCode::from(1);
        }
    };
    match pis_samples::generate_all(&root) {
        Ok(()) => {
            for name in pis_samples::SAMPLES {
                println!("wrote {}", root.join(name).display());
            }
            for name in pis_samples::WILD {
                println!("wrote {}", root.join("wild").join(name).display());
            }
            ExitCode::SUCCESS
        }
        Err(err) => {
            eprintln!("pis-samples: {err}");
            ExitCode::from(2)
        }
    }
}
