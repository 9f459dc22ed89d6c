//! IGES 5.3 subfigures: a 308 Subfigure Definition holding one trimmed face (FreeCAD's
//! `trimmed_face.igs`, its 144 at D1) placed twice by 408 Singular Subfigure Instances, one
//! by a translation, one by a scale, a translation and a 124 rotation. The placed faces'
//! vertices are checked against the definition's vertices mapped by hand.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::path::PathBuf;

use nurbsx::exchange::{self, Document, ImportOptions, Severity};

fn sample() -> String {
    let p =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("samples/freecad/parts/trimmed_face.igs");
    std::fs::read_to_string(p).unwrap()
}

/// Appends entities (type, parameter data, transform DE, label) to an IGES file: two
/// Directory Entry lines and the parameter lines each, sequence numbers and the Terminate
/// section's counts updated (IGES 5.3 sections 2.2.4 - 2.2.6).
fn append(text: &str, entities: &[(i64, &str, usize, &str)]) -> String {
    let mut sections: [Vec<String>; 5] = Default::default();
    for line in text.lines() {
        let k = match line.as_bytes().get(72) {
            Some(b'S') => 0,
            Some(b'G') => 1,
            Some(b'D') => 2,
            Some(b'P') => 3,
            _ => 4,
        };
        sections[k].push(line.to_owned());
    }
    for &(t, data, transform, label) in entities {
        let de = sections[2].len() + 1;
        let first_p = sections[3].len() + 1;
        let chunks: Vec<String> = data
            .as_bytes()
            .chunks(64)
            .map(|c| String::from_utf8(c.to_vec()).unwrap())
            .collect();
        for c in &chunks {
            let seq = sections[3].len() + 1;
            sections[3].push(format!("{c:<64} {de:>7}P{seq:07}"));
        }
        sections[2].push(format!(
            "{t:>8}{first_p:>8}{:>8}{:>8}{:>8}{:>8}{transform:>8}{:>8}{:>8}D{de:07}",
            0, 0, 0, 0, 0, "00000000"
        ));
        sections[2].push(format!(
            "{t:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{label:>8}{:>8}D{:07}",
            0,
            0,
            chunks.len(),
            0,
            "",
            "",
            0,
            de + 1
        ));
    }
    let n = |k: usize| sections[k].len();
    let terminate = format!(
        "{:<72}T{:07}",
        format!("S{:>7}G{:>7}D{:>7}P{:>7}", n(0), n(1), n(2), n(3)),
        1
    );
    let mut out = String::new();
    for s in &sections[..4] {
        for l in s {
            out += l;
            out += "\n";
        }
    }
    out + &terminate + "\n"
}

fn read(text: &str) -> Document {
    exchange::read(text.as_bytes(), &ImportOptions::default()).unwrap()
}

/// The sample's face D1 in a 308 (D43) placed twice: D45, a 408 at (10, 0, 0); D47, a 408
/// scaled by 2, at (0, 0, 5), then the 124 D41 (a rotation by 90 degrees about z, then
/// (100, 0, 0)).
fn placed_twice() -> String {
    append(
        &sample(),
        &[
            (124, "124,0.,-1.,0.,100.,1.,0.,0.,0.,0.,0.,1.,0.;", 0, ""),
            (308, "308,0,4HFACE,1,1;", 0, ""),
            (408, "408,43,10.,0.,0.,1.;", 0, "INST1"),
            (408, "408,43,0.,0.,5.,2.;", 41, "INST2"),
        ],
    )
}

#[test]
fn a_subfigure_used_twice_is_placed_twice() {
    let original = read(&sample());
    let m0 = &original.topology.model;
    assert_eq!(m0.faces.len(), 1);
    let doc = read(&placed_twice());
    let errors: Vec<_> = doc
        .diagnostics
        .iter()
        .filter(|d| {
            d.severity == Severity::Error
                || d.code.starts_with("assembly") && d.severity != Severity::Info
        })
        .collect();
    assert!(errors.is_empty(), "{errors:#?}");
    assert!(
        !doc.diagnostics
            .iter()
            .any(|d| d.severity != Severity::Info && d.message.contains("408")),
        "{:#?}",
        doc.diagnostics
    );
    let m = &doc.topology.model;
    assert_eq!(m.faces.len(), 2, "one face per instance");
    let paths: Vec<&str> = doc
        .topology
        .instances
        .iter()
        .map(|i| i.path.as_str())
        .collect();
    assert_eq!(paths, ["INST1", "INST2"]);
    let ids: Vec<&str> = doc
        .topology
        .origins
        .faces
        .iter()
        .map(|o| o.id.as_str())
        .collect();
    assert_eq!(ids, ["D1@INST1", "D1@INST2"]);
    // The placements by hand: x + (10, 0, 0); and R (2 x + (0, 0, 5)) + (100, 0, 0) with R
    // the quarter turn about z, (x, y, z) -> (-y, x, z).
    let first = |x: [f64; 3]| [x[0] + 10.0, x[1], x[2]];
    let second = |x: [f64; 3]| [100.0 - 2.0 * x[1], 2.0 * x[0], 2.0 * x[2] + 5.0];
    let n = m0.vertices.len();
    assert!(n > 0);
    assert_eq!(m.vertices.len(), 2 * n);
    let near = |a: [f64; 3], b: [f64; 3]| (0..3).all(|k| (a[k] - b[k]).abs() < 1e-9 * 100.0);
    for v in &m0.vertices {
        for (map, half) in [(&first as &dyn Fn(_) -> _, 0..n), (&second, n..2 * n)] {
            let want = map(v.point);
            assert!(
                m.vertices[half].iter().any(|w| near(w.point, want)),
                "{:?} placed at {want:?} is not a vertex",
                v.point
            );
        }
    }
    // Areas: the translated face keeps its area, the one scaled by 2 has four times it.
    let a0 = m0.measure_face(&m0.faces[0]).unwrap().area;
    let a1 = m.measure_face(&m.faces[0]).unwrap().area;
    let a2 = m.measure_face(&m.faces[1]).unwrap().area;
    assert!(((a1 - a0) / a0).abs() < 1e-12, "{a1} vs {a0}");
    assert!(((a2 - 4.0 * a0) / a0).abs() < 1e-9, "{a2} vs 4 x {a0}");
}

#[test]
fn a_scaled_subfigure_instance_is_written_flattened_to_step_with_a_warning() {
    // INST1 a translation, INST2 a scale by 2, a translation and a rotation.
    let doc = read(&placed_twice());
    let options = exchange::ExportOptions::default();
    let said = exchange::step::assembly_warnings(&doc, &options);
    assert_eq!(said.len(), 1, "{said:#?}");
    let d = &said[0];
    assert_eq!(
        (d.code.as_str(), d.severity),
        ("assembly.instance_flattened", Severity::Warning)
    );
    assert!(
        d.message.contains("INST2") && d.message.contains("scales"),
        "{}",
        d.message
    );
    let step = exchange::write(&doc, exchange::Format::Step, &options).unwrap();
    // INST1 is an instance of the subfigure's product; INST2's face is written into the
    // file's product, placed.
    assert_eq!(step.matches("= NEXT_ASSEMBLY_USAGE_OCCURRENCE(").count(), 1);
    assert!(step.contains("'INST1'") && !step.contains("'INST2'"));
    let back = read(&step);
    let paths: Vec<&str> = back
        .topology
        .instances
        .iter()
        .map(|i| i.path.as_str())
        .collect();
    assert_eq!(paths, ["INST1"]);
    // Both placed faces, where the IGES file put them (their vertices within 1e-12 of the
    // part's size).
    let (m, n) = (&doc.topology.model, &back.topology.model);
    assert_eq!(n.faces.len(), 2);
    assert_eq!(n.vertices.len(), m.vertices.len());
    for v in &m.vertices {
        assert!(
            n.vertices
                .iter()
                .any(|w| (0..3).all(|k| (w.point[k] - v.point[k]).abs() < 1e-12 * 100.0)),
            "{:?} not written",
            v.point
        );
    }
    let areas = |m: &nurbsx::topology::Model| {
        let mut a: Vec<f64> = m
            .faces
            .iter()
            .map(|f| m.measure_face(f).unwrap().area)
            .collect();
        a.sort_by(f64::total_cmp);
        a
    };
    let flat = read(
        &exchange::write(
            &doc,
            exchange::Format::Step,
            &exchange::ExportOptions {
                flatten_assemblies: true,
                ..options
            },
        )
        .unwrap(),
    );
    // The areas as the flattened STEP output's (the same faces placed by the reader, not
    // by the file), and within 1e-8 of the IGES reading's: the pcurves of a STEP face are
    // those the IGES reader recomputed (projections within the edge tolerance), read back
    // as written, which moves the trimmed area by 2.1e-9 relative on the sample.
    let (a, b, c) = (areas(m), areas(n), areas(&flat.topology.model));
    assert_eq!((a.len(), b.len(), c.len()), (2, 2, 2));
    for k in 0..2 {
        assert!(((b[k] - c[k]) / c[k]).abs() < 1e-14, "{} vs {}", b[k], c[k]);
        assert!(((b[k] - a[k]) / a[k]).abs() < 1e-8, "{} vs {}", b[k], a[k]);
    }
}

/// The STEP writer returns the warning about the scaled instance with the text it wrote
/// by the plan that flattened it: what `assembly_warnings` says without writing.
#[test]
fn the_step_writer_returns_its_flattening_warning() {
    let doc = read(&placed_twice());
    let options = exchange::ExportOptions::default();
    let (step, said) = exchange::write_reporting(&doc, exchange::Format::Step, &options).unwrap();
    assert_eq!(said, exchange::step::assembly_warnings(&doc, &options));
    assert_eq!(
        said.iter().map(|d| d.code.as_str()).collect::<Vec<_>>(),
        ["assembly.instance_flattened"]
    );
    assert_eq!(step.matches("= NEXT_ASSEMBLY_USAGE_OCCURRENCE(").count(), 1);
}
