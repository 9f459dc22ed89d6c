//! STEP boundary representation: read into `Document.topology`, checked against FreeCAD's
//! own reading of the same files (the sample JSONs: faces, edges without the degenerate
//! ones Open CASCADE adds at poles, vertices, shells, solids), against Euler-Poincare, and
//! written back.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::path::{Path, PathBuf};

use nurbsx::exchange::{self, Document, ImportOptions, Severity};
use serde_json::Value;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn read_path(path: &Path) -> Document {
    exchange::read(&std::fs::read(path).unwrap(), &ImportOptions::default()).unwrap()
}

/// FreeCAD's counts of a sample: (faces, edges without degenerate ones, vertices when
/// known, shells, solids).
fn freecad_counts(json: &Value) -> (usize, usize, Option<usize>, usize, usize) {
    let c = &json["counts"];
    let n = |k: &str| c[k].as_u64().unwrap_or(0) as usize;
    let degenerate = c["degenerated_edges"]
        .as_u64()
        .or_else(|| c["curve_types"]["None"].as_u64())
        .or_else(|| c["other_curves"]["None"].as_u64())
        .unwrap_or(0) as usize;
    (
        n("faces"),
        n("edges") - degenerate,
        c["vertices"].as_u64().map(|v| v as usize),
        n("shells"),
        n("solids"),
    )
}

fn ours(doc: &Document) -> (usize, usize, usize, usize, usize) {
    let m = &doc.topology.model;
    (
        m.faces.len(),
        m.edges.len(),
        m.vertices.len(),
        m.shells.len(),
        m.solids.len(),
    )
}

/// Every STEP sample with a face, with FreeCAD's reading.
fn samples() -> Vec<(PathBuf, Value)> {
    let mut out = Vec::new();
    let mut dirs = vec![root().join("samples/freecad"), root().join("samples/freecad/analytic")];
    dirs.push(
        std::env::var_os("NURBSX_PARTS_DIR")
            .map_or_else(|| root().join("samples/freecad/parts"), PathBuf::from),
    );
    for dir in dirs {
        let Ok(list) = std::fs::read_dir(&dir) else {
            eprintln!("step_topology: {} not found, its samples are not checked", dir.display());
            continue;
        };
        let mut files: Vec<PathBuf> = list
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|x| x == "step"))
            .collect();
        files.sort();
        for p in files {
            let json = PathBuf::from(format!("{}.json", p.display()));
            let Ok(text) = std::fs::read_to_string(&json) else { continue };
            let v: Value = serde_json::from_str(&text).unwrap();
            if v["counts"]["faces"].as_u64().unwrap_or(0) > 0 {
                out.push((p, v));
            }
        }
    }
    out
}

#[test]
fn counts_equal_freecads() {
    let mut failures = Vec::new();
    for (path, json) in samples() {
        let doc = read_path(&path);
        let (f, e, v, sh, so) = freecad_counts(&json);
        let got = ours(&doc);
        let errors: Vec<String> = doc
            .diagnostics
            .iter()
            .filter(|d| d.severity == Severity::Error)
            .map(|d| format!("{} {:?}: {}", d.code, d.location.entity, d.message))
            .collect();
        println!(
            "{:<40} faces {}/{f} edges {}/{e} vertices {}/{v:?} shells {}/{sh} solids {}/{so} errors {}",
            path.file_name().unwrap().to_string_lossy(),
            got.0,
            got.1,
            got.2,
            got.3,
            got.4,
            errors.len()
        );
        for e in errors.iter().take(3) {
            println!("    {e}");
        }
        if (got.0, got.1, got.3, got.4) != (f, e, sh, so) || v.is_some_and(|v| v != got.2) {
            failures.push(path.display().to_string());
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

