//! The decoding threads' own work: every level image of a file read and decoded from its
//! codestream, on one thread, as the player's workers do it (`pis_play::decode_level`).
//! Prints the time per pass and a checksum of the decoded values, so that a change to the
//! decoder can be timed and shown to decode the same values.
//! Run: cargo bench -p pis-play --bench decode -- FILE.pis [PASSES]

use std::path::Path;
use std::time::Instant;

use pis_format::texture::LevelLayout;
use pis_format::PisReader;
use pis_play::decode::{decode_level, LevelJob};

fn jobs(reader: &PisReader) -> Vec<LevelJob> {
    let c = reader.container();
    let mut out = Vec::new();
    for (o, object) in c.objects.iter().enumerate() {
        for (l, layer) in object.layers.iter().enumerate() {
            for (b, block) in layer.blocks.iter().enumerate() {
                let planes = LevelLayout::of(layer, block).planes();
                for (lv, level) in block.levels.iter().enumerate() {
                    for &stream in &level.images {
                        let at = (o, l, b, lv);
                        out.push(LevelJob { stream, planes: planes.clone(), at });
                    }
                }
            }
        }
    }
    out
}

fn main() {
    let mut args = std::env::args().skip(1).filter(|a| a != "--bench");
    let Some(file) = args.next() else {
        eprintln!("usage: cargo bench -p pis-play --bench decode -- FILE.pis [PASSES]");
        return;
    };
    let passes: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(5);
    let reader = match PisReader::open(Path::new(&file)) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("{file}: {e}");
            std::process::exit(1);
        }
    };
    let jobs = jobs(&reader);
    let bytes: u64 = jobs.iter().map(|j| j.stream.length as u64).sum();
    println!("{file}: {} level images, {bytes} bytes of codestreams", jobs.len());
    for pass in 0..passes {
        let start = Instant::now();
        let mut sum = 0u64;
        let mut values = 0usize;
        for job in &jobs {
            let v = decode_level(&reader, job).expect("decodes");
            values += v.len();
            for x in &v {
                sum = sum.rotate_left(5) ^ x.to_bits() as u64;
            }
        }
        let ms = start.elapsed().as_secs_f64() * 1e3;
        println!("pass {pass}: {ms:.1} ms, {values} values, checksum {sum:016x}");
    }
}
