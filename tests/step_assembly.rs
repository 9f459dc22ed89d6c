//! STEP assemblies: the product structure of `assembly_links.step` (FreeCAD's App::Part
//! with 'Bracket' used twice and a rotated 'Pin') read with its placements applied, checked
//! against FreeCAD's in-memory shape before export (`assembly_links.source.json`: counts,
//! volumes, area, area-weighted face centroid, bound box), and hostile product structures
//! (cycles, nesting too deep, instances multiplying past the limit) refused with located
//! errors.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::path::PathBuf;

use nurbsx::exchange::{self, Document, ImportOptions, Severity};
use nurbsx::pipeline::{self, Settings};
use serde_json::Value;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn sample() -> String {
    std::fs::read_to_string(root().join("samples/freecad/parts/assembly_links.step")).unwrap()
}

fn source() -> Value {
    let p = root().join("samples/freecad/parts/assembly_links.source.json");
    serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()
}

fn read(text: &str) -> Document {
    exchange::read(text.as_bytes(), &ImportOptions::default()).unwrap()
}

fn f(v: &Value) -> f64 {
    v.as_f64().unwrap()
}

#[test]
fn placements_are_applied_as_freecad_places_them() {
    let doc = read(&sample());
    let src = source();
    let m = &doc.topology.model;
    assert_eq!(m.solids.len(), 3, "solids");
    assert_eq!(m.faces.len(), 17, "faces");
    assert_eq!(m.shells.len(), 3, "shells");
    assert_eq!(m.edges.len(), 33, "edges");
    assert_eq!(m.vertices.len(), 22, "vertices");
    assert!(
        !doc.diagnostics
            .iter()
            .any(|d| d.code.starts_with("assembly") && d.severity != Severity::Info),
        "{:#?}",
        doc.diagnostics
    );
    let totals = m.totals();
    assert_eq!(totals.unmeasured, 0);
    // Volumes: the parts' own measure. The faces' parameter-space curves are projections of
    // the 3-D edges within the edge tolerance (1e-7 of the part's size; the file's analytic
    // pcurves are not converted), which bounds how close the trimmed integrals come: the
    // largest deviation seen is 2.7e-8 relative (the pin's volume).
    for (i, want) in src["solids"].as_array().unwrap().iter().enumerate() {
        let got = *totals.volumes[i].as_ref().unwrap();
        let want = f(&want["volume"]);
        assert!(
            ((got - want) / want).abs() < 1e-7,
            "solid {i}: volume {got} vs FreeCAD {want}"
        );
    }
    let area = f(&src["totals"]["area"]);
    assert!(
        ((totals.area - area) / area).abs() < 1e-8,
        "area {} vs {area}",
        totals.area
    );
    // Where the parts are: the area-weighted centroid and the bound box of the placed part
    // within 1e-9 of its size. A placement applied the wrong way round (or not at all) moves
    // Bracket_2's and the Pin's faces by millimetres.
    let size = f(&src["size"]);
    let centroid = &src["totals"]["face_centroid"];
    for k in 0..3 {
        assert!(
            (totals.centroid[k] - f(&centroid[k])).abs() < 1e-9 * size,
            "centroid {:?} vs {centroid}",
            totals.centroid
        );
    }
    // The bound box of the faces is the box of their edges (on planes and cylinders the
    // extremes of a linear function lie on the boundary): every edge sampled finely.
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for e in &m.edges {
        const N: usize = 20_000;
        for k in 0..=N {
            let t = e.range.0 + (e.range.1 - e.range.0) * k as f64 / N as f64;
            let p = e.curve.point_at(t).unwrap();
            for d in 0..3 {
                lo[d] = lo[d].min(p[d]);
                hi[d] = hi[d].max(p[d]);
            }
        }
    }
    let bb = src["bound_box"].as_array().unwrap();
    for d in 0..3 {
        assert!(
            (lo[d] - f(&bb[d])).abs() < 1e-9 * size && (hi[d] - f(&bb[d + 3])).abs() < 1e-9 * size,
            "bound box {lo:?} {hi:?} vs {bb:?}"
        );
    }
    // A rigid placement changes no measure: the two brackets agree to rounding.
    let (v1, v2) = (
        *totals.volumes[0].as_ref().unwrap(),
        *totals.volumes[1].as_ref().unwrap(),
    );
    assert!(((v1 - v2) / v1).abs() < 1e-12, "{v1} vs {v2}");
}

#[test]
fn info_lists_the_instances_with_their_placements() {
    let loaded = pipeline::load(sample().as_bytes(), None, &Settings::default()).unwrap();
    let report = serde_json::to_value(pipeline::info(&loaded)).unwrap();
    let s = &report["structure"];
    let inst = s["instances"].as_array().unwrap();
    let paths: Vec<&str> = inst.iter().map(|i| i["path"].as_str().unwrap()).collect();
    assert_eq!(paths, ["Bracket_1", "Bracket_2", "Pin_1"]);
    let products: Vec<&str> = inst
        .iter()
        .map(|i| i["product"].as_str().unwrap())
        .collect();
    assert_eq!(products, ["Bracket", "Bracket", "Pin"]);
    // Placements as FreeCAD built them (the source description): Bracket_1 at the origin;
    // Bracket_2 at (40, 0, 0) rotated 30 degrees about (1, 1, 0); Pin_1 at (10, 5, -5)
    // rotated 15 degrees about y. Rodrigues' formula, independent of the file's axes.
    let rot = |axis: [f64; 3], deg: f64, t: [f64; 3]| -> [[f64; 4]; 3] {
        let n = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt();
        let k = axis.map(|x| x / n);
        let (s, c) = deg.to_radians().sin_cos();
        let kx = [[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]];
        std::array::from_fn(|r| {
            let mut row = [0.0; 4];
            for col in 0..3 {
                let id = if r == col { 1.0 } else { 0.0 };
                row[col] = c * id + s * kx[r][col] + (1.0 - c) * k[r] * k[col];
            }
            row[3] = t[r];
            row
        })
    };
    let want = [
        rot([0.0, 0.0, 1.0], 0.0, [0.0; 3]),
        rot([1.0, 1.0, 0.0], 30.0, [40.0, 0.0, 0.0]),
        rot([0.0, 1.0, 0.0], 15.0, [10.0, 5.0, -5.0]),
    ];
    for (i, w) in inst.iter().zip(want) {
        for r in 0..3 {
            for c in 0..4 {
                let got = f(&i["placement"][r][c]);
                assert!(
                    (got - w[r][c]).abs() < 1e-9,
                    "{}: placement {} vs {w:?}",
                    i["path"],
                    i["placement"]
                );
            }
        }
        let places: Vec<&str> = i["places"]
            .as_array()
            .unwrap()
            .iter()
            .map(|p| p.as_str().unwrap())
            .collect();
        assert_eq!(places.len(), 1, "{}", i["path"]);
        // The placed solid is listed under that id.
        assert!(
            s["solids"]
                .as_array()
                .unwrap()
                .iter()
                .any(|x| x["id"] == places[0]),
            "{places:?}"
        );
        assert!(places[0].ends_with(&format!("@{}", i["path"].as_str().unwrap())));
    }
    // Every face id is distinct (the web page joins drawn meshes to these ids).
    let mut ids: Vec<&str> = s["faces"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x["id"].as_str().unwrap())
        .collect();
    let n = ids.len();
    ids.sort_unstable();
    ids.dedup();
    assert_eq!(ids.len(), n);
}

/// The product definitions of the sample, with more appended.
fn with_data(extra: &str) -> String {
    sample().replace("ENDSEC;\nEND-ISO", &format!("{extra}ENDSEC;\nEND-ISO"))
}

fn refused(doc: &Document) -> &exchange::Diagnostic {
    doc.diagnostics
        .iter()
        .find(|d| d.code == "assembly.refused")
        .unwrap_or_else(|| panic!("no assembly.refused in {:#?}", doc.diagnostics))
}

#[test]
fn a_cyclic_product_structure_is_a_located_error() {
    // 'Bracket' (#35) made to use 'Assembly' (#5), which uses it.
    let doc = read(&with_data(
        "#9000 = NEXT_ASSEMBLY_USAGE_OCCURRENCE('9','Loop','',#35,#5,$);\n",
    ));
    let d = refused(&doc);
    assert_eq!(d.severity, Severity::Error);
    assert!(d.message.contains("contain each other"), "{}", d.message);
    assert!(
        d.location.entity.is_some() && d.location.line.is_some(),
        "{d:?}"
    );
    // Nothing placed, nothing lost: each part once, in its own coordinates.
    assert_eq!(doc.topology.model.solids.len(), 2);
    assert!(doc.topology.instances.is_empty());
}

/// `n` product definitions `L0 .. L(n-1)`, each using the next `uses` times; the last uses
/// the sample's 'Assembly' (#5).
fn chain(n: usize, uses: usize) -> String {
    let mut s = String::new();
    let pd = |i: usize| 10_000 + 10 * i as u64 + 2;
    for i in 0..n {
        let b = 10_000 + 10 * i as u64;
        s += &format!(
            "#{b} = PRODUCT('L{i}','L{i}','',(#8));\n#{} = PRODUCT_DEFINITION_FORMATION('','',#{b});\n#{} = PRODUCT_DEFINITION('design','',#{},#9);\n",
            b + 1,
            b + 2,
            b + 1
        );
        let child = if i + 1 == n { 5 } else { pd(i + 1) };
        for k in 0..uses {
            s += &format!(
                "#{} = NEXT_ASSEMBLY_USAGE_OCCURRENCE('{k}','L{i}_{k}','',#{},#{child},$);\n",
                b + 3 + k as u64,
                pd(i)
            );
        }
    }
    s
}

#[test]
fn nesting_deeper_than_the_limit_is_a_located_error() {
    let doc = read(&with_data(&chain(70, 1)));
    let d = refused(&doc);
    assert!(d.message.contains("levels"), "{}", d.message);
    assert!(d.location.entity.as_deref() == Some("#10002"), "{d:?}");
    assert_eq!(doc.topology.model.solids.len(), 2);
}

#[test]
fn instances_multiplying_past_the_limit_are_a_located_error() {
    // 2^20 copies of the assembly: refused before anything is copied.
    let t = std::time::Instant::now();
    let doc = read(&with_data(&chain(20, 2)));
    let d = refused(&doc);
    assert!(d.message.contains("instances"), "{}", d.message);
    assert!(d.location.entity.as_deref() == Some("#10002"), "{d:?}");
    assert_eq!(doc.topology.model.solids.len(), 2);
    assert!(t.elapsed().as_secs() < 60, "{:?}", t.elapsed());
}

/// A GEOMETRIC_CURVE_SET in the Pin's shape (a circle of radius 0.5 about (1, 2, 3) in the
/// Pin's xy plane, joined to its representation without transformation) is placed with the
/// Pin: one free edge, its circle about `R (1, 2, 3) + t` in the plane normal to `R z`, with
/// `R`, `t` the Pin's placement as FreeCAD built it (15 degrees about y, at (10, 5, -5); by
/// Rodrigues' formula, independent of the file), and no `assembly.geometry_not_placed`.
#[test]
fn free_curves_of_a_placed_product_are_placed_with_it() {
    let doc = read(&with_data(
        "#9001 = CARTESIAN_POINT('',(1.,2.,3.));\n\
         #9002 = DIRECTION('',(0.,0.,1.));\n\
         #9003 = DIRECTION('',(1.,0.,0.));\n\
         #9004 = AXIS2_PLACEMENT_3D('',#9001,#9002,#9003);\n\
         #9005 = CIRCLE('',#9004,0.5);\n\
         #9006 = GEOMETRIC_CURVE_SET('',(#9005));\n\
         #9007 = SHAPE_REPRESENTATION('',(#9006),#577);\n\
         #9008 = SHAPE_REPRESENTATION_RELATIONSHIP('','',#9007,#478);\n",
    ));
    assert!(
        !doc.diagnostics
            .iter()
            .any(|d| d.code == "assembly.geometry_not_placed"),
        "{:#?}",
        doc.diagnostics
    );
    let o = &doc.topology.origins;
    let m = &doc.topology.model;
    let circles: Vec<usize> = (0..o.edges.len())
        .filter(|&i| o.edges[i].id.starts_with("#9005"))
        .collect();
    assert_eq!(circles.len(), 1, "{:?}", o.edges);
    let edge = &m.edges[circles[0]];
    let (s, c) = 15f64.to_radians().sin_cos();
    // Rotation about y: x' = c x + s z, z' = -s x + c z.
    let r = |p: [f64; 3]| [c * p[0] + s * p[2], p[1], -s * p[0] + c * p[2]];
    let t = [10.0, 5.0, -5.0];
    let centre: [f64; 3] = std::array::from_fn(|k| r([1.0, 2.0, 3.0])[k] + t[k]);
    let normal = r([0.0, 0.0, 1.0]);
    for k in 0..=64 {
        let u = edge.range.0 + (edge.range.1 - edge.range.0) * f64::from(k) / 64.0;
        let p = edge.curve.point_at(u).unwrap();
        let d: [f64; 3] = std::array::from_fn(|j| p[j] - centre[j]);
        let radius = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        let off = d[0] * normal[0] + d[1] * normal[1] + d[2] * normal[2];
        // Within 1e-9, as the placements above: the file writes the Pin's axes rounded.
        assert!((radius - 0.5).abs() < 1e-9, "{p:?}: radius {radius}");
        assert!(off.abs() < 1e-9, "{p:?}: {off} off the plane");
    }
}
