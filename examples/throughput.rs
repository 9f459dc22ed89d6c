//! Bytes -> model and model -> text throughput on a large file, with peak memory.
//!
//! ```text
//! cargo run --release --example gen_large -- --step /tmp/big.step --iges /tmp/big.igs
//! RAYON_NUM_THREADS=1 cargo run --release --example throughput -- read /tmp/big.step 3
//! RAYON_NUM_THREADS=2 cargo run --release --example throughput -- read /tmp/big.step 3
//! cargo run --release --example throughput -- write /tmp/big.step 3
//! cargo run --release --example throughput -- mem /tmp/big.step
//! ```
//! `read` times `nurbsx::exchange::read` (every B-spline resolved into the NURBS model) N
//! times and prints the first run's, the best and the median MB/s (MB = 10^6 bytes of input);
//! `read-geometry` the same with `geometry_only` (curves and surfaces, no faces, edges or
//! pcurves: the `--geometry-only` reading). `write` reads once
//! and times writing the document back in the same format (MB/s of output text). `mem`
//! reads once in a fresh process and prints the peak resident set (`VmHWM`) relative to the
//! file size; the file bytes themselves are included (they are read into memory first).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic, missing_docs)]

use std::time::Instant;

use nurbsx::exchange::{ExportOptions, ImportOptions, read, write};

fn status_kb(field: &str) -> u64 {
    let s = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    s.lines()
        .find(|l| l.starts_with(field))
        .and_then(|l| l.split_whitespace().nth(1))
        .and_then(|v| v.parse().ok())
        .unwrap_or(0)
}

/// CPU time of the whole process (every thread, `/proc/self/task/*/schedstat`), in seconds.
/// On a shared machine wall time mostly measures waiting for a core; CPU time is what the
/// code costs. Both are printed.
fn cpu_secs() -> f64 {
    let mut ns: u64 = 0;
    if let Ok(dir) = std::fs::read_dir("/proc/self/task") {
        for task in dir.flatten() {
            let s = std::fs::read_to_string(task.path().join("schedstat")).unwrap_or_default();
            ns += s
                .split_whitespace()
                .next()
                .and_then(|v| v.parse::<u64>().ok())
                .unwrap_or(0);
        }
    }
    ns as f64 / 1e9
}

fn report(label: &str, bytes: usize, mut secs: Vec<f64>, mut cpu: Vec<f64>) {
    // The first run is the one a one-shot CLI process sees: every page it allocates is
    // faulted in fresh. Later runs may reuse memory the allocator kept, so they are shown
    // separately.
    let first = secs[0];
    secs.sort_by(f64::total_cmp);
    cpu.sort_by(f64::total_cmp);
    let mb = bytes as f64 / 1e6;
    println!(
        "{label}: {mb:.1} MB, wall first run {:.1} MB/s, best {:.1} MB/s, median {:.1} MB/s; CPU time best {:.1} MB/s, median {:.1} MB/s ({} runs)",
        mb / first,
        mb / secs[0],
        mb / secs[secs.len() / 2],
        mb / cpu[0],
        mb / cpu[cpu.len() / 2],
        secs.len()
    );
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (mode, path) = match (args.first(), args.get(1)) {
        (Some(m), Some(p)) => (m.as_str(), p.as_str()),
        _ => {
            eprintln!("usage: throughput read|read-geometry|write|mem FILE [N]");
            std::process::exit(2);
        }
    };
    let n: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(3);
    let mut options = ImportOptions::default();
    options.limits.max_input_bytes = usize::MAX;
    let base_kb = status_kb("VmRSS:");
    let bytes = std::fs::read(path).expect("read input file");
    if mode == "read-geometry" {
        options.geometry_only = true;
    }
    match mode {
        "read" | "read-geometry" => {
            let mut secs = Vec::new();
            let mut cpu = Vec::new();
            for _ in 0..n {
                let c = cpu_secs();
                let t = Instant::now();
                let doc = read(&bytes, &options).expect("file reads");
                secs.push(t.elapsed().as_secs_f64());
                cpu.push(cpu_secs() - c);
                assert!(!doc.entities.is_empty());
                std::hint::black_box(doc);
            }
            let threads = rayon::current_num_threads();
            report(
                &format!("{mode} {path} ({threads} threads)"),
                bytes.len(),
                secs,
                cpu,
            );
        }
        "write" => {
            let doc = read(&bytes, &options).expect("file reads");
            let export = ExportOptions {
                timestamp: Some("2026-01-01T00:00:00".to_owned()),
                ..Default::default()
            };
            let mut secs = Vec::new();
            let mut cpu = Vec::new();
            let mut len = 0;
            for _ in 0..n {
                let c = cpu_secs();
                let t = Instant::now();
                let text = write(&doc, doc.format, &export).expect("document writes");
                secs.push(t.elapsed().as_secs_f64());
                cpu.push(cpu_secs() - c);
                len = text.len();
            }
            report(
                &format!("write {:?} from {path}", doc.format),
                len,
                secs,
                cpu,
            );
        }
        "mem" => {
            let doc = read(&bytes, &options).expect("file reads");
            let peak_kb = status_kb("VmHWM:");
            let size = bytes.len() as f64;
            println!(
                "mem {path}: {} entities, file {:.1} MB, peak RSS {:.1} MB = {:.2}x file (baseline {:.1} MB before reading; {:.2}x above it)",
                doc.entities.len(),
                size / 1e6,
                peak_kb as f64 * 1024.0 / 1e6,
                peak_kb as f64 * 1024.0 / size,
                base_kb as f64 * 1024.0 / 1e6,
                (peak_kb - base_kb) as f64 * 1024.0 / size,
            );
        }
        other => panic!("unknown mode {other}"),
    }
}
