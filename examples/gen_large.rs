//! Writes large deterministic STEP and IGES files for throughput measurements.
//!
//! ```text
//! cargo run --release --example gen_large -- --step /tmp/big.step --iges /tmp/big.igs [--mb 100] [--iges-mb 80]
//! cargo run --release --example gen_large -- --analytic-step /tmp/brep.step [--mb 100] [--without-pcurves]
//! cargo run --release --example gen_large -- --brep-step /tmp/nurbs_brep.step [--mb 100]
//! ```
//! The STEP file is about `--mb` MB (default 100), the IGES file `--iges-mb` MB (default 80).
//! The entity mix is described in `benches/common/gen.rs`. The files are not committed.
//!
//! `--analytic-step` writes a STEP file of analytic B-rep geometry instead: copies of
//! `samples/freecad/analytic/filleted_box_with_hole.step` (FreeCAD's export of a box with
//! fillets and a hole: planes, cylinders, spheres, lines, circles, B-spline pcurves, the
//! topology, as Open CASCADE writes them), each copy's instance ids shifted past the
//! previous copy's, until the file is about `--mb` MB. With `--without-pcurves`, the sample
//! loses its PCURVEs first (every PCURVE instance, and every instance that only they use,
//! directly or through others, is dropped; each SURFACE_CURVE and SEAM_CURVE lists no
//! pcurve): the same B-rep without the 2-D side Open CASCADE writes for each edge on each
//! face, to measure what that side costs a read.
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
    let mut without_pcurves = false;
    let mut it = args.iter();
    while let Some(a) = it.next() {
        match a.as_str() {
            "--step" => step = it.next().cloned(),
            "--iges" => iges = it.next().cloned(),
            "--analytic-step" => analytic = it.next().cloned(),
            "--brep-step" => brep = it.next().cloned(),
            "--without-pcurves" => without_pcurves = true,
            "--mb" => mb = it.next().and_then(|s| s.parse().ok()).expect("--mb N"),
            "--iges-mb" => iges_mb = it.next().and_then(|s| s.parse().ok()).expect("--iges-mb N"),
            other => panic!(
                "unknown argument {other}; usage: --step FILE --iges FILE [--mb N] [--iges-mb N], or --analytic-step FILE / --brep-step FILE [--mb N] [--without-pcurves]"
            ),
        }
    }
    for (path, sample) in [
        (&analytic, "analytic/filleted_box_with_hole.step"),
        (&brep, "brep_filleted_box_nurbs.step"),
    ] {
        let Some(path) = path else { continue };
        let (text, copies) = copies_of(sample, (mb * 1e6) as usize, without_pcurves);
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

/// Copies of the DATA section of `samples/freecad/{sample}` (without its pcurves when
/// `without_pcurves`: [`drop_pcurves`]) with shifted ids, in one STEP file of about `size`
/// bytes; returns the text and the number of copies.
fn copies_of(sample: &str, size: usize, without_pcurves: bool) -> (String, usize) {
    let sample = std::fs::read_to_string(format!(
        "{}/samples/freecad/{sample}",
        env!("CARGO_MANIFEST_DIR")
    ))
    .expect("the sample file");
    let start = sample.find("DATA;").expect("DATA;") + "DATA;".len();
    let end = sample.rfind("ENDSEC;").expect("ENDSEC;");
    let (header, data) = (&sample[..start], &sample[start..end]);
    let stripped;
    let data = if without_pcurves {
        stripped = drop_pcurves(data);
        stripped.as_str()
    } else {
        data
    };
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

/// The DATA section `data` (`#n = ...;` statements, no `;` inside a string, as the samples
/// are) without its PCURVEs: every PCURVE, and every instance that only dropped instances
/// use, is dropped (a complex instance's keyword counts as empty), and the references to
/// dropped instances leave the lists of SURFACE_CURVEs and SEAM_CURVEs.
fn drop_pcurves(data: &str) -> String {
    use std::collections::{HashMap, HashSet};
    let refs = |body: &str| -> Vec<u64> {
        body.split('#')
            .skip(1)
            .filter_map(|s| {
                let n: String = s.chars().take_while(char::is_ascii_digit).collect();
                n.parse().ok()
            })
            .collect()
    };
    let statements: Vec<(u64, &str, &str)> = data
        .split(';')
        .filter_map(|s| {
            let s = s.trim();
            let (id, body) = s.strip_prefix('#')?.split_once('=')?;
            let body = body.trim();
            let keyword = body.split(['(', ' ']).next().unwrap_or("");
            Some((id.trim().parse().ok()?, keyword, body))
        })
        .collect();
    let mut users: HashMap<u64, Vec<u64>> = HashMap::new();
    for &(id, _, body) in &statements {
        for r in refs(body) {
            users.entry(r).or_default().push(id);
        }
    }
    let mut dropped: HashSet<u64> = statements
        .iter()
        .filter(|(_, k, _)| *k == "PCURVE")
        .map(|(id, _, _)| *id)
        .collect();
    loop {
        let more: Vec<u64> = statements
            .iter()
            .filter(|(id, k, _)| {
                !dropped.contains(id)
                    && !matches!(*k, "SURFACE_CURVE" | "SEAM_CURVE")
                    && users
                        .get(id)
                        .is_some_and(|u| u.iter().all(|x| dropped.contains(x)))
            })
            .map(|(id, _, _)| *id)
            .collect();
        if more.is_empty() {
            break;
        }
        dropped.extend(more);
    }
    let mut out = String::with_capacity(data.len());
    out.push('\n');
    for &(id, keyword, body) in &statements {
        if dropped.contains(&id) {
            continue;
        }
        let body = if matches!(keyword, "SURFACE_CURVE" | "SEAM_CURVE") {
            // `KEYWORD('name',#curve,(#p1,#p2),.MASTER.)`: the list keeps what stays.
            let start = body.find(",(").map(|i| i + 2);
            let end = start.and_then(|a| body[a..].find(')').map(|j| a + j));
            match (start, end) {
                (Some(a), Some(b)) => {
                    let kept: Vec<String> = refs(&body[a..b])
                        .into_iter()
                        .filter(|r| !dropped.contains(r))
                        .map(|r| format!("#{r}"))
                        .collect();
                    format!("{}{}{}", &body[..a], kept.join(","), &body[b..])
                }
                _ => body.to_owned(),
            }
        } else {
            body.to_owned()
        };
        out.push_str(&format!("#{id} = {body};\n"));
    }
    out
}
