//! Read -> write -> read: whatever reads must write, and what is written must read back
//! with bit-identical knots, weights and control points (same units, no ops in between).
//!
//! A whole part (a document with topology) keeps its curves and surfaces too, with one
//! freedom: an edge's curve may come back reversed (bit for bit the reversal of the one
//! read), because an IGES 142 boundary runs its curves in the loop's direction where the
//! 504 edge list of a B-rep file, or a STEP EDGE_CURVE, has its own; and the topology keeps
//! its counts of faces, edges, vertices and solids (not of shells: STEP holds loose faces in
//! an open shell of a SHELL_BASED_SURFACE_MODEL). An assembly written to IGES is written
//! flattened: what comes back is the read model's placed faces and edges.
#![no_main]

use libfuzzer_sys::fuzz_target;
use nurbsx::exchange::{self, Document, ExportOptions, Format};
use nurbsx::nurbs::Geometry;

fn counts(doc: &Document) -> [usize; 4] {
    let m = &doc.topology.model;
    [
        m.faces.len(),
        m.edges.len(),
        m.vertices.len(),
        m.solids.len(),
    ]
}

fuzz_target!(|data: &[u8]| {
    let Ok(doc) = exchange::read(data, &Default::default()) else {
        return;
    };
    let options = ExportOptions {
        timestamp: Some("2026-01-01T00:00:00".into()),
        ..ExportOptions::default()
    };
    let part = !doc.topology.is_empty();
    for format in [Format::Step, Format::Iges] {
        let Ok(text) = exchange::write(&doc, format, &options) else {
            continue;
        };
        let back = exchange::read(text.as_bytes(), &Default::default())
            .unwrap_or_else(|e| panic!("nurbsx wrote a file it cannot read: {e}"));
        // An assembly is written to IGES flattened (the `assembly.flattened` warning): its
        // placed copies come back as entities of their own, each one the geometry of a face
        // or an edge of the read model (which holds the copies placed).
        let flattened = format == Format::Iges && !doc.topology.instances.is_empty();
        if !flattened {
            assert_eq!(
                back.entities.len(),
                doc.entities.len(),
                "entity count changed"
            );
        }
        if part {
            assert_eq!(
                counts(&back),
                counts(&doc),
                "topology changed in {format:?}"
            );
            let m = &doc.topology.model;
            let placed = m.faces.iter().map(|f| Geometry::Surface(f.surface.clone()));
            let placed = placed.chain(m.edges.iter().map(|e| Geometry::Curve(e.curve.clone())));
            let placed: Vec<Geometry> = if flattened {
                placed.collect()
            } else {
                Vec::new()
            };
            let mut before: Vec<&Geometry> = doc.entities.iter().map(|e| &e.geometry).collect();
            before.extend(&placed);
            for e in &back.entities {
                let k = before.iter().position(|g| match (g, &e.geometry) {
                    (Geometry::Curve(a), Geometry::Curve(b)) => {
                        a == b || a.reverse().is_ok_and(|r| &r == b)
                    }
                    (a, b) => *a == b,
                });
                let k = k.unwrap_or_else(|| {
                    panic!(
                        "{:?} of the {format:?} round trip is none of the read geometry",
                        e.id
                    )
                });
                before.swap_remove(k);
            }
            continue;
        }
        for (a, b) in doc.entities.iter().zip(&back.entities) {
            assert_eq!(
                a.geometry, b.geometry,
                "geometry changed in {format:?} round trip"
            );
        }
    }
});
