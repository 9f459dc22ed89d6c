//! Writes large deterministic STEP and IGES files for throughput measurements.
//!
//! ```text
//! cargo run --release --example gen_large -- --step /tmp/big.step --iges /tmp/big.igs [--mb 100] [--iges-mb 80]
//! ```
//! The STEP file is about `--mb` MB (default 100), the IGES file `--iges-mb` MB (default 80).
//! The entity mix is described in `benches/common/gen.rs`. The files are not committed.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic, missing_docs)]

#[path = "../benches/common/gen.rs"]
mod generator;

use nurbsx::exchange::Format;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut step = None;
    let mut iges = None;
    let mut mb = 100.0_f64;
    let mut iges_mb = 80.0_f64;
    let mut it = args.iter();
    while let Some(a) = it.next() {
        match a.as_str() {
            "--step" => step = it.next().cloned(),
            "--iges" => iges = it.next().cloned(),
            "--mb" => mb = it.next().and_then(|s| s.parse().ok()).expect("--mb N"),
            "--iges-mb" => iges_mb = it.next().and_then(|s| s.parse().ok()).expect("--iges-mb N"),
            other => panic!(
                "unknown argument {other}; usage: --step FILE --iges FILE [--mb N] [--iges-mb N]"
            ),
        }
    }
    if step.is_none() && iges.is_none() {
        eprintln!("usage: gen_large --step FILE --iges FILE [--mb 100] [--iges-mb 80]");
        std::process::exit(2);
    }
    for (path, format, size) in [(step, Format::Step, mb), (iges, Format::Iges, iges_mb)] {
        let Some(path) = path else { continue };
        let (text, doc) = generator::file_of_size(format, (size * 1e6) as usize);
        std::fs::write(&path, &text).expect("write output file");
        println!(
            "{path}: {} bytes, {} entities",
            text.len(),
            doc.entities.len()
        );
    }
}
