//! Read -> write -> read: whatever reads must write, and what is written must read back
//! with bit-identical knots, weights and control points (same units, no ops in between).
//!
//! A whole part (a document with topology) is written as STEP and as IGES in both modes,
//! and each format is held to what it can carry:
//! - **STEP** carries everything: the same entities (an edge's curve may come back
//!   reversed, bit for bit the reversal of the one read, where a file gives an edge the
//!   other direction), and the same counts of faces, edges, vertices and solids (not of
//!   shells: STEP holds loose faces in an open shell of a SHELL_BASED_SURFACE_MODEL).
//! - **IGES B-rep (186)** carries the faces, the edges faces use, their vertices and the
//!   vertex loops' vertices, and the solids: those counts are the same. An edge in no face
//!   comes back as a free curve (IGES has no free edge).
//! - **IGES faces (144)** carries the faces; solids are the reader's: every closed shell
//!   comes back as a solid (a 144 file has no shells; nurbsx sews each 402 group of faces
//!   and closes what closes; a face written bounded by its surface's domain, as a sphere
//!   bounded only by a vertex loop is, comes back bounded by that domain's edges). Edges
//!   and vertices are the boundary's a 144 needs, which closes in the surface's
//!   parameters: a face that winds around its surface without a seam edge comes back with
//!   one, and a cone's apex or a sphere's pole with a vertex where the writer closed the
//!   boundary (the writer warns of the vertex loops it leaves out). So only faces and
//!   solids are counted.
//!
//! In both IGES modes every curve and surface read comes back (nothing is lost), and
//! everything read back is one of the read geometry (or an edge curve reversed, as a 142
//! runs its curves in the loop's direction), except in the 144 mode the seams and collapsed
//! sides the writer adds to close a boundary in the surface's parameters; a curve may come
//! back more than once (two halves of an edge split at a seam are two 126s over the one
//! curve).
//! An assembly written to IGES is written flattened: what comes back is the read model's
//! placed faces and edges.
#![no_main]

use libfuzzer_sys::fuzz_target;
use nurbsx::exchange::{self, ExportOptions, Format};
use nurbsx::nurbs::Geometry;
use nurbsx::topology::Model;

/// Faces, edges faces use, vertices of those edges and of vertex loops, solids.
fn counts(m: &Model) -> [usize; 4] {
    let mut edges = std::collections::BTreeSet::new();
    let mut vertices = std::collections::BTreeSet::new();
    for f in &m.faces {
        vertices.extend(f.vertex_loops.iter().map(|v| v.0));
        for c in f.loops.iter().flat_map(|l| &l.coedges) {
            edges.insert(c.edge.0);
            let e = &m.edges[c.edge.0];
            vertices.insert(e.start.0);
            vertices.insert(e.end.0);
        }
    }
    [m.faces.len(), edges.len(), vertices.len(), m.solids.len()]
}

/// Whether two curves or surfaces are the same bit for bit (a curve also reversed).
fn same(a: &Geometry, b: &Geometry) -> bool {
    match (a, b) {
        (Geometry::Curve(a), Geometry::Curve(b)) => a == b || a.reverse().is_ok_and(|r| &r == b),
        (a, b) => a == b,
    }
}

/// What the 144 writer adds to close a boundary in a face's (u, v), or the reader makes of
/// a face bounded by its surface's domain: a collapsed side (a line of two equal poles) or
/// an iso-curve at an end of the domain of a face's surface (either way round).
fn closing_curve(g: &Geometry, m: &Model) -> bool {
    let Geometry::Curve(c) = g else {
        return false;
    };
    let points = c.control_points();
    if c.degree() == 1 && points.len() == 2 && points[0] == points[1] {
        return true;
    }
    m.faces.iter().any(|f| {
        let ((u0, u1), (v0, v1)) = f.surface.domain();
        let s = &f.surface;
        [s.iso_u(u0), s.iso_u(u1), s.iso_v(v0), s.iso_v(v1)]
            .into_iter()
            .flatten()
            .any(|iso| same(&Geometry::Curve(iso), g))
    })
}

fuzz_target!(|data: &[u8]| {
    let Ok(doc) = exchange::read(data, &Default::default()) else {
        return;
    };
    let options = ExportOptions {
        timestamp: Some("2026-01-01T00:00:00".into()),
        ..ExportOptions::default()
    };
    let brep = ExportOptions {
        iges_brep: true,
        ..options.clone()
    };
    let part = !doc.topology.is_empty();
    let modes: &[(Format, &ExportOptions)] = if part {
        &[(Format::Step, &options), (Format::Iges, &brep), (Format::Iges, &options)]
    } else {
        &[(Format::Step, &options), (Format::Iges, &options)]
    };
    for &(format, options) in modes {
        let Ok(text) = exchange::write(&doc, format, options) else {
            continue;
        };
        let back = exchange::read(text.as_bytes(), &Default::default())
            .unwrap_or_else(|e| panic!("nurbsx wrote a file it cannot read: {e}"));
        let mode = format!("{format:?}{}", if options.iges_brep { " B-rep" } else { "" });
        if !part {
            assert_eq!(back.entities.len(), doc.entities.len(), "entity count changed");
            for (a, b) in doc.entities.iter().zip(&back.entities) {
                assert_eq!(a.geometry, b.geometry, "geometry changed in {mode} round trip");
            }
            continue;
        }
        // An assembly is written to IGES flattened (the `assembly.flattened` warning): its
        // placed copies come back as entities of their own, each one the geometry of a face
        // or an edge of the read model (which holds the copies placed).
        let flattened = format == Format::Iges && !doc.topology.instances.is_empty();
        let m = &doc.topology.model;
        let placed: Vec<Geometry> = if flattened {
            let faces = m.faces.iter().map(|f| Geometry::Surface(f.surface.clone()));
            faces
                .chain(m.edges.iter().map(|e| Geometry::Curve(e.curve.clone())))
                .collect()
        } else {
            Vec::new()
        };
        let mut read: Vec<&Geometry> = doc.entities.iter().map(|e| &e.geometry).collect();
        read.extend(&placed);
        let (a, b) = (counts(m), counts(&back.topology.model));
        if format == Format::Step {
            if !flattened {
                assert_eq!(back.entities.len(), doc.entities.len(), "entity count changed");
            }
            assert_eq!(
                [a[0], m.edges.len(), m.vertices.len(), a[3]],
                [
                    b[0],
                    back.topology.model.edges.len(),
                    back.topology.model.vertices.len(),
                    b[3]
                ],
                "topology changed in {mode}"
            );
            // Each read entity is matched once.
            for e in &back.entities {
                let k = read.iter().position(|g| same(g, &e.geometry));
                let k = k.unwrap_or_else(|| {
                    panic!("{:?} of the {mode} round trip is none of the read geometry", e.id)
                });
                read.swap_remove(k);
            }
            continue;
        }
        if options.iges_brep {
            assert_eq!(b, a, "faces, face edges, vertices, solids changed in {mode}");
        } else {
            // Closed shells (solids' outer shells and voids included).
            let closed = m.shells.iter().filter(|s| s.closed).count();
            assert_eq!(b[0], a[0], "faces changed in {mode}");
            assert_eq!(b[3], closed, "solids: one per closed shell in {mode}");
        }
        // Nothing read is lost: every read curve and surface comes back (a 2-D curve a
        // face's boundary uses comes back on its coedge; flattened, the faces and edges
        // come back placed, the rest as read).
        let back_geometry: Vec<&Geometry> = back.entities.iter().map(|e| &e.geometry).collect();
        let named = doc.topology.origins.entity_ids();
        for e in &doc.entities {
            let carried = e.geometry.dimension() == 2 && !e.meta.used_by.is_empty();
            let placed_instead = flattened && named.contains(e.id.as_str());
            assert!(
                carried || placed_instead || back_geometry.iter().any(|g| same(&e.geometry, g)),
                "{} of the read document did not come back from {mode}",
                e.id
            );
        }
        for g in &placed {
            assert!(
                back_geometry.iter().any(|b| same(g, b)),
                "a placed face or edge did not come back from {mode}"
            );
        }
        for e in &back.entities {
            assert!(
                read.iter().any(|g| same(g, &e.geometry))
                    || (!options.iges_brep && closing_curve(&e.geometry, m)),
                "{:?} of the {mode} round trip is none of the read geometry",
                e.id
            );
        }
    }
});
