//! Exchange throughput (bytes per second): STEP bytes -> model (one and two threads), IGES
//! bytes -> model, model -> STEP text, model -> IGES text, on deterministic generated files
//! (`benches/common/gen.rs`, the same mix as `examples/gen_large.rs`).
//!
//! `cargo bench --bench exchange` uses ~8 MB files so criterion stays quick; set
//! `NURBSX_BENCH_MB=100` for full-size files. For the 100 MB / 80 MB figures and peak memory
//! the README uses `examples/throughput.rs` (see its doc comment). Throughput is in input
//! bytes for reads and output bytes for writes (MB = 10^6 bytes).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic, missing_docs)]

#[path = "common/gen.rs"]
mod generator;

use std::time::Duration;

use criterion::{Criterion, Throughput, black_box};
use nurbsx::exchange::{Format, ImportOptions, read, write};

fn mb() -> f64 {
    std::env::var("NURBSX_BENCH_MB")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(8.0)
}

fn bench_format(c: &mut Criterion, format: Format, name: &str) {
    let (text, doc) = generator::file_of_size(format, (mb() * 1e6) as usize);
    let bytes = text.into_bytes();
    let mut options = ImportOptions::default();
    options.limits.max_input_bytes = usize::MAX;
    // Check once that every entity is resolved, so the timing is of a complete read.
    let read_back = read(&bytes, &options).unwrap();
    assert_eq!(read_back.entities.len(), doc.entities.len());

    let mut g = c.benchmark_group(name);
    g.sample_size(10);
    g.measurement_time(Duration::from_secs(10));
    g.throughput(Throughput::Bytes(bytes.len() as u64));
    let threads: &[usize] = if format == Format::Step {
        &[1, 2]
    } else {
        &[1]
    };
    for &t in threads {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(t)
            .build()
            .unwrap();
        g.bench_function(format!("bytes_to_model/{t}_thread"), |b| {
            b.iter(|| pool.install(|| black_box(read(black_box(&bytes), &options).unwrap())))
        });
    }
    let export = generator::export_options();
    let out_len = write(&read_back, format, &export).unwrap().len();
    g.throughput(Throughput::Bytes(out_len as u64));
    g.bench_function("model_to_text", |b| {
        b.iter(|| black_box(write(black_box(&read_back), format, &export).unwrap()))
    });
    g.finish();
}

fn main() {
    let mut c = Criterion::default().configure_from_args();
    bench_format(&mut c, Format::Step, "step");
    bench_format(&mut c, Format::Iges, "iges");
    c.final_summary();
}
