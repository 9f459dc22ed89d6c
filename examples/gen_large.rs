//! Writes large deterministic STEP and IGES files for throughput measurements.
//!
//! ```text
//! cargo run --release --example gen_large -- --step /tmp/big.step --iges /tmp/big.igs [--mb 100] [--iges-mb 80]
//! cargo run --release --example gen_large -- --analytic-step /tmp/brep.step [--mb 100]
//! cargo run --release --example gen_large -- --brep-step /tmp/nurbs_brep.step [--mb 100]
//! ```
//! The STEP file is about `--mb` MB (default 100), the IGES file `--iges-mb` MB (default 80).
//! The entity mix is described in `benches/common/gen.rs`. The files are not committed.
//!
//! `--analytic-step` writes a STEP file of analytic B-rep geometry instead: copies of
//! `samples/freecad/analytic/filleted_box_with_hole.step` (FreeCAD's export of a box with
//! fillets and a hole: planes, cylinders, spheres, lines, circles, B-spline pcurves, the
//! topology, as Open CASCADE writes them), each copy's instance ids shifted past the
//! previous copy's, until the file is about `--mb` MB.
//!
//! `--brep-step` does the same with `samples/freecad/brep_filleted_box_nurbs.step` (the
//! filleted box with B-spline faces: B_SPLINE_SURFACE_WITH_KNOTS faces bounded by
//! B_SPLINE_CURVE_WITH_KNOTS edges, every vertex, edge, loop, face, shell and the solid),
//! the file for the whole-part read of B-spline faces.
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
    let mut analytic = None;
    let mut brep = None;
    let mut it = args.iter();
    while let Some(a) = it.next() {
        match a.as_str() {
            "--step" => step = it.next().cloned(),
            "--iges" => iges = it.next().cloned(),
            "--analytic-step" => analytic = it.next().cloned(),
            "--brep-step" => brep = it.next().cloned(),
            "--mb" => mb = it.next().and_then(|s| s.parse().ok()).expect("--mb N"),
            "--iges-mb" => iges_mb = it.next().and_then(|s| s.parse().ok()).expect("--iges-mb N"),
            other => panic!(
                "unknown argument {other}; usage: --step FILE --iges FILE [--mb N] [--iges-mb N], or --analytic-step FILE / --brep-step FILE [--mb N]"
            ),
        }
    }
    for (path, sample) in [
        (&analytic, "analytic/filleted_box_with_hole.step"),
        (&brep, "brep_filleted_box_nurbs.step"),
    ] {
        let Some(path) = path else { continue };
        let (text, copies) = copies_of(sample, (mb * 1e6) as usize);
        std::fs::write(path, &text).expect("write output file");
        println!("{path}: {} bytes, {copies} copies of {sample}", text.len());
    }
    if step.is_none() && iges.is_none() {
        if analytic.is_some() || brep.is_some() {
            return;
        }
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

/// Copies of the DATA section of `samples/freecad/{sample}` with shifted ids, in one STEP
/// file of about `size` bytes; returns the text and the number of copies.
fn copies_of(sample: &str, size: usize) -> (String, usize) {
    let sample = std::fs::read_to_string(format!(
        "{}/samples/freecad/{sample}",
        env!("CARGO_MANIFEST_DIR")
    ))
    .expect("the sample file");
    let start = sample.find("DATA;").expect("DATA;") + "DATA;".len();
    let end = sample.rfind("ENDSEC;").expect("ENDSEC;");
    let (header, data) = (&sample[..start], &sample[start..end]);
    // The largest id, so that copy k shifts every `#n` by k * (max + 1).
    let ids = |text: &str| -> Vec<(usize, usize, u64)> {
        let b = text.as_bytes();
        let mut out = Vec::new();
        let mut i = 0;
        while i < b.len() {
            if b[i] == b'#' {
                let j = i + 1 + b[i + 1..].iter().take_while(|c| c.is_ascii_digit()).count();
                if j > i + 1 {
                    out.push((i + 1, j, text[i + 1..j].parse().unwrap()));
                }
                i = j;
            } else {
                i += 1;
            }
        }
        out
    };
    let found = ids(data);
    let step = found.iter().map(|x| x.2).max().unwrap_or(0) + 1;
    let mut text = String::with_capacity(size + data.len() + 64);
    text.push_str(header);
    text.push('\n');
    let mut copies = 0;
    while text.len() < size || copies == 0 {
        let shift = copies as u64 * step;
        let mut last = 0;
        for &(a, b, n) in &found {
            text.push_str(&data[last..a]);
            text.push_str(&(n + shift).to_string());
            last = b;
        }
        text.push_str(&data[last..]);
        copies += 1;
    }
    text.push_str("ENDSEC;\nEND-ISO-10303-21;\n");
    (text, copies)
}
