//! Manual check against FreeCAD's own readings of the sample corpus (not committed; made by
//! the samples helper with FreeCAD 0.20.2 / OCCT 7.6.3). Run with
//! `NURBSX_FREECAD_SAMPLES=/path/to/samples/freecad cargo test --test iges_freecad_corpus -- --ignored --nocapture`.
//!
//! For every `*.igs` with its `*.igs.json` (FreeCAD's evaluations after `Part.read`), each
//! B-spline curve FreeCAD holds must match one of our curves at the same parameters
//! (OCCT's IGES import segments to `V(0)..V(1)` but keeps the parameterisation), and each
//! surface one of our surfaces, within 1e-6 of the model size.
// Test helpers outside #[test] functions may unwrap and panic too.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::path::Path;

use nurbsx::exchange::{self, ImportOptions};
use nurbsx::nurbs::Geometry;

fn dist(a: [f64; 3], b: &[f64]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

#[test]
#[ignore = "needs the FreeCAD sample corpus (NURBSX_FREECAD_SAMPLES)"]
fn freecad_corpus_matches() {
    let dir = std::env::var("NURBSX_FREECAD_SAMPLES")
        .unwrap_or_else(|_| "/work/wt/samples/samples/freecad".into());
    let mut files: Vec<_> = std::fs::read_dir(Path::new(&dir))
        .expect("corpus directory")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "igs"))
        .collect();
    files.sort();
    let mut failures = 0;
    for path in files {
        let text = std::fs::read_to_string(&path).unwrap();
        let json_path = format!("{}.json", path.display());
        let Ok(json) = std::fs::read_to_string(&json_path) else {
            continue;
        };
        let fc: serde_json::Value = serde_json::from_str(&json).unwrap();
        let options = ImportOptions {
            target_units: Some(nurbsx::exchange::LengthUnit::Mm), // FreeCAD works in mm
            ..ImportOptions::default()
        };
        let doc = match exchange::iges::read(&text, &options) {
            Ok(d) => d,
            Err(e) => {
                println!("{}: READ ERROR {e}", path.display());
                failures += 1;
                continue;
            }
        };
        let codes: Vec<String> = doc
            .diagnostics
            .iter()
            .map(|d| format!("{:?}:{}", d.severity, d.code))
            .collect();
        let mut matched = (0, 0);
        let mut total = (0, 0);
        let mut worst = 0.0f64;
        for c in fc["curves"].as_array().into_iter().flatten() {
            total.0 += 1;
            let evals = c["evaluations"].as_array().unwrap();
            let best = doc
                .entities
                .iter()
                .filter_map(|e| match &e.geometry {
                    Geometry::Curve(ours) => Some(ours),
                    _ => None,
                })
                .map(|ours| {
                    evals.iter().fold(0.0f64, |m, ev| {
                        let t = ev["t"].as_f64().unwrap();
                        let p: Vec<f64> = ev["point"]
                            .as_array()
                            .unwrap()
                            .iter()
                            .map(|x| x.as_f64().unwrap())
                            .collect();
                        match ours.point_at(t) {
                            Ok(q) => m.max(dist(q, &p)),
                            Err(_) => f64::INFINITY,
                        }
                    })
                })
                .fold(f64::INFINITY, f64::min);
            worst = worst.max(best);
            if best < 1e-6 {
                matched.0 += 1;
            }
        }
        for s in fc["surfaces"].as_array().into_iter().flatten() {
            total.1 += 1;
            let evals = s["evaluations"].as_array().unwrap();
            let best = doc
                .entities
                .iter()
                .filter_map(|e| match &e.geometry {
                    Geometry::Surface(ours) => Some(ours),
                    _ => None,
                })
                .map(|ours| {
                    evals.iter().fold(0.0f64, |m, ev| {
                        let u = ev["u"].as_f64().unwrap();
                        let v = ev["v"].as_f64().unwrap();
                        let p: Vec<f64> = ev["point"]
                            .as_array()
                            .unwrap()
                            .iter()
                            .map(|x| x.as_f64().unwrap())
                            .collect();
                        match ours.point_at(u, v) {
                            Ok(q) => m.max(dist(q, &p)),
                            Err(_) => f64::INFINITY,
                        }
                    })
                })
                .fold(f64::INFINITY, f64::min);
            worst = worst.max(best);
            if best < 1e-6 {
                matched.1 += 1;
            }
        }
        if matched != total {
            failures += 1;
        }
        println!(
            "{}: ours {} entities; FreeCAD curves {}/{} surfaces {}/{} matched (worst {worst:.2e}); {}",
            path.file_name().unwrap().to_string_lossy(),
            doc.entities.len(),
            matched.0,
            total.0,
            matched.1,
            total.1,
            codes.join(" ")
        );
    }
    assert_eq!(failures, 0);
}
