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

/// Samples whose topology nurbsx does not read in full yet, with the reason; for these the
/// tests check that the reader says so with an error diagnostic (never silently).
const KNOWN_GAPS: &[(&str, &str)] = &[
    // B-spline edge curves whose vertices lie inside the curve (the edge uses part of it):
    // bounding them needs the parameters of the vertices on the curve (point inversion on a
    // curve), not implemented; the edges are refused with topology.edge_vertex.
    ("face_trimmed_hole.step", "B-spline edges bounded inside their curve"),
    ("surf_periodic_u_trimmed_face.step", "B-spline edges bounded inside their curve"),
    ("trimmed_face.step", "B-spline edges bounded inside their curve"),
    // A sphere face bounded by a VERTEX_LOOP only: the closed-shell check finds no edge to
    // pair and refuses the closure (topology.shell_open), so the solid is refused.
    ("sphere.step", "closed shell of one face without edges"),
    // Product structure (NEXT_ASSEMBLY_USAGE_OCCURRENCE, MAPPED_ITEM) is not read: the
    // parts placed several times appear once (not reported yet: see the report).
    ("assembly_links.step", "assembly placements"),
];

/// Samples where Open CASCADE's reading adds edges the file does not have (ShapeFix splits
/// or completes the boundary of a single B-spline face): compared with the file's own
/// EDGE_CURVE count instead.
const OCCT_ADDS_EDGES: &[&str] = &[
    "import_export_named.step",
    "schema_ap203.step",
    "schema_ap242.step",
    "units_inch.step",
    "units_metre.step",
    "surf_sphere_nurbs.step",
];

fn name(path: &Path) -> String {
    path.file_name().unwrap().to_string_lossy().into_owned()
}

fn gap(path: &Path) -> Option<&'static str> {
    let n = name(path);
    KNOWN_GAPS.iter().find(|(f, _)| *f == n).map(|(_, why)| *why)
}

/// EDGE_CURVE instances in the file's text (an independent count).
fn edge_curves_in(path: &Path) -> usize {
    std::fs::read_to_string(path)
        .unwrap()
        .matches("EDGE_CURVE(")
        .count()
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
            .filter(|d| {
                d.severity == Severity::Error
                    || (d.severity == Severity::Warning && d.code.starts_with("assembly."))
            })
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
        if let Some(why) = gap(&path) {
            assert!(
                !errors.is_empty(),
                "{}: {why}, but no diagnostic says so",
                path.display()
            );
            continue;
        }
        let e = if OCCT_ADDS_EDGES.contains(&name(&path).as_str()) {
            edge_curves_in(&path)
        } else {
            e
        };
        if (got.0, got.1, got.3, got.4) != (f, e, sh, so) || v.is_some_and(|v| v != got.2) {
            failures.push(path.display().to_string());
        }
        // Euler-Poincare for a closed solid's boundary: V - E + F - (L - F) = 2 (S - G),
        // with L the loops (so L - F the inner loops); the genus G from the sample when
        // given, else 0. Edge-less faces (a VERTEX_LOOP sphere) are outside the formula.
        let m = &doc.topology.model;
        if m.solids.len() == 1 && m.shells.len() == 1 && m.faces.iter().all(|f| !f.loops.is_empty())
        {
            let loops: usize = m.faces.iter().map(|f| f.loops.len()).sum();
            // Genus: the parts' JSON gives it; of the analytic samples, the box with a
            // through hole and the torus have one handle (their descriptions), the rest none.
            let genus = json["genus"].as_i64().unwrap_or(
                match name(&path).as_str() {
                    "filleted_box_with_hole.step" | "torus.step" => 1,
                    _ => 0,
                },
            );
            let lhs = got.2 as i64 - got.1 as i64 + got.0 as i64 - (loops as i64 - got.0 as i64);
            // OCCT's own edge count (with its seams) is what the genus of the sample was
            // read with; a file without seam edges differs by them, so check only files
            // where every closed face has its seam (all of FreeCAD's here).
            if lhs != 2 * (1 - genus) {
                failures.push(format!(
                    "{}: V - E + F - inner loops = {lhs}, 2 (S - G) = {}",
                    path.display(),
                    2 * (1 - genus)
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

