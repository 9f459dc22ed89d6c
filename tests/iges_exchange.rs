//! IGES records <-> model: round trips, 124 chains, units, flags, per-entity errors.
//! Input files are built record by record by `iges_util` (not by the crate's writer).
// Test helpers outside #[test] functions may unwrap and panic too.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;
#[path = "../parsers/tests/iges_support/mod.rs"]
mod iges_util;

use iges_util::{Builder, De};
use nurbsx::exchange::{
    self, Diagnostic, Document, Entity, ExportOptions, Format, ImportOptions, LengthUnit, Meta,
    Severity, Source,
};
use nurbsx::nurbs::{Geometry, Grid, NurbsCurve, NurbsSurface};

fn global(flag: i64, name: &str) -> String {
    format!(
        ",,4Htest,8Hfile.igs,6Hnurbsx,3H0.1,32,38,6,308,15,,1.,{flag},{}H{name},1,0.01,15H20260101.120000,1.E-7,100.,,,11,0,15H20260101.120000,;",
        name.len()
    )
}

fn has(doc: &Document, code: &str) -> bool {
    doc.diagnostics.iter().any(|d| d.code == code)
}

fn find<'a>(doc: &'a Document, code: &str) -> &'a Diagnostic {
    doc.diagnostics
        .iter()
        .find(|d| d.code == code)
        .unwrap_or_else(|| panic!("no {code} in {:#?}", doc.diagnostics))
}

fn curve(doc: &Document, id: &str) -> NurbsCurve {
    match &doc.entities.iter().find(|e| e.id == id).unwrap().geometry {
        Geometry::Curve(c) => c.clone(),
        g => panic!("{g:?}"),
    }
}

fn entity(id: &str, g: Geometry) -> Entity {
    Entity {
        id: id.into(),
        geometry: g,
        source: Source::default(),
        meta: Meta::default(),
    }
}

fn export_options() -> ExportOptions {
    ExportOptions {
        timestamp: Some("2026-01-02T03:04:05".into()),
        ..ExportOptions::default()
    }
}

/// A rational quadratic quarter circle of radius 2 (weights 1, sqrt(2)/2, 1), a cubic
/// with an interior knot, a 2-D curve, and a non-square rational 4x3 surface.
fn sample_document() -> Document {
    let h = std::f64::consts::FRAC_1_SQRT_2;
    let arc = NurbsCurve::new(
        2,
        vec![0., 0., 0., 1., 1., 1.],
        vec![[2., 0., 0.], [2., 2., 0.], [0., 2., 0.]],
        Some(vec![1., h, 1.]),
    )
    .unwrap();
    let cubic = NurbsCurve::new(
        3,
        vec![0., 0., 0., 0., 0.3, 1., 1., 1., 1.],
        vec![
            [0.1, 0.2, 0.3],
            [1.0 / 3.0, 1., -1e-300],
            [2., -1., 5e10],
            [3., 0., 1.],
            [4., 1., 1.],
        ],
        None,
    )
    .unwrap();
    let flat = NurbsCurve::with_dimension(
        1,
        vec![0., 0., 0.5, 1., 1.],
        vec![[0., 0., 0.], [1., 0.5, 0.], [0.25, 1., 0.]],
        None,
        2,
    )
    .unwrap();
    let net = Grid::from_fn(4, 3, |i, j| {
        [
            i as f64 + 0.1 * j as f64,
            j as f64 * 0.7,
            (i * j) as f64 / 3.0,
        ]
    });
    let w = Grid::from_fn(4, 3, |i, j| 1.0 + (i + 4 * j) as f64 / 9.0);
    let surf = NurbsSurface::new(
        2,
        1,
        vec![0., 0., 0., 0.4, 1., 1., 1.],
        vec![0., 0., 0.5, 1., 1.],
        net,
        Some(w),
    )
    .unwrap();
    let mut doc = Document::new(Format::Step, LengthUnit::Mm);
    let mut arc_e = entity("arc", Geometry::Curve(arc));
    arc_e.meta.name = Some("ARC".into());
    doc.entities.push(arc_e);
    doc.entities.push(entity("cubic", Geometry::Curve(cubic)));
    doc.entities.push(entity("flat", Geometry::Curve(flat)));
    doc.entities.push(entity("surf", Geometry::Surface(surf)));
    doc
}

fn assert_bits_equal(a: &Geometry, b: &Geometry) {
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    match (a, b) {
        (Geometry::Curve(a), Geometry::Curve(b)) => {
            assert_eq!(a.degree(), b.degree());
            assert_eq!(a.dimension(), b.dimension());
            assert_eq!(bits(a.knots()), bits(b.knots()));
            assert_eq!(a.weights().map(bits), b.weights().map(bits));
            let pa: Vec<f64> = a.control_points().iter().flatten().copied().collect();
            let pb: Vec<f64> = b.control_points().iter().flatten().copied().collect();
            assert_eq!(bits(&pa), bits(&pb));
        }
        (Geometry::Surface(a), Geometry::Surface(b)) => {
            assert_eq!((a.degree_u(), a.degree_v()), (b.degree_u(), b.degree_v()));
            assert_eq!(bits(a.knots_u()), bits(b.knots_u()));
            assert_eq!(bits(a.knots_v()), bits(b.knots_v()));
            assert_eq!(
                a.weights().map(|w| bits(w.as_slice())),
                b.weights().map(|w| bits(w.as_slice()))
            );
            assert_eq!(a.control_points().nu(), b.control_points().nu());
            let pa: Vec<f64> = a
                .control_points()
                .as_slice()
                .iter()
                .flatten()
                .copied()
                .collect();
            let pb: Vec<f64> = b
                .control_points()
                .as_slice()
                .iter()
                .flatten()
                .copied()
                .collect();
            assert_eq!(bits(&pa), bits(&pb));
        }
        _ => panic!("geometry kinds differ"),
    }
}

#[test]
fn write_read_write_is_bit_identical() {
    let doc = sample_document();
    let text = exchange::iges::write(&doc, &export_options()).unwrap();
    let back = exchange::iges::read(&text, &ImportOptions::default()).unwrap();
    assert!(!back.has_errors(), "{:#?}", back.diagnostics);
    // No warnings: the flags we wrote agree with the data.
    assert!(
        back.diagnostics
            .iter()
            .all(|d| d.severity == Severity::Info),
        "{:#?}",
        back.diagnostics
    );
    assert_eq!(back.units, LengthUnit::Mm);
    assert_eq!(back.schema.as_deref(), Some("IGES 5.3"));
    assert_eq!(back.entities.len(), 4);
    for (a, b) in doc.entities.iter().zip(&back.entities) {
        assert_bits_equal(&a.geometry, &b.geometry);
    }
    assert_eq!(back.entities[0].meta.name.as_deref(), Some("ARC"));
    assert_eq!(back.entities[0].id, "D1");
    assert_eq!(back.entities[2].geometry.dimension(), 2);
    // The planar arc carries its normal (+Z); the 2-D curve too.
    assert_eq!(
        back.entities[0].meta.plane_normal.as_deref(),
        Some(&[0., 0., 1.])
    );
    assert_eq!(back.entities[1].meta.plane_normal, None);
    // The parameter range written is the domain.
    let r = back.entities[3]
        .meta
        .parameter_range
        .as_deref()
        .copied()
        .unwrap();
    assert_eq!((r.u, r.v), ((0., 1.), Some((0., 1.))));
    // Deterministic: writing the re-read document gives the same text.
    let again = exchange::iges::write(&back, &export_options()).unwrap();
    assert_eq!(again, text);
    // Every point of the arc is at radius 2 after the round trip.
    let c = curve(&back, "D1");
    for k in 0..=50 {
        let p = c.point_at(k as f64 / 50.0).unwrap();
        assert!(((p[0] * p[0] + p[1] * p[1]).sqrt() - 2.0).abs() < 1e-14);
    }
    // Keep a copy for the manual FreeCAD check described in the report.
    let _ = std::fs::write(
        std::env::temp_dir().join("nurbsx_iges_roundtrip.igs"),
        &text,
    );
}

#[test]
fn written_flags_and_global() {
    let doc = sample_document();
    let text = exchange::iges::write(&doc, &export_options()).unwrap();
    let file = nurbsx_parsers::iges::parse(&text).unwrap();
    let g = &file.global;
    assert_eq!(
        (g.units_flag, g.units_name.as_deref()),
        (Some(2), Some("MM"))
    );
    assert_eq!(g.date.as_deref(), Some("20260102.030405"));
    assert_eq!(g.version_flag, Some(11));
    assert_eq!(g.max_coordinate, Some(5e10));
    use nurbsx_parsers::iges::records::Curve126;
    let rec = |de: i64| {
        file.decode::<Curve126>(file.entry(de).unwrap())
            .record
            .unwrap()
    };
    let arc = rec(1);
    // planar, open, rational, non-periodic
    assert_eq!(
        (arc.planar, arc.closed, arc.polynomial, arc.periodic),
        (1, 0, 0, 0)
    );
    let cubic = rec(3);
    assert_eq!((cubic.planar, cubic.polynomial), (0, 1));
    assert_eq!(cubic.weights, vec![1.0; 5]);
    assert_eq!(file.entry(5).unwrap().status.use_flag, 5);
    assert_eq!(file.entry(1).unwrap().status.use_flag, 0);
    assert_eq!(file.entry(1).unwrap().label, "ARC");
}

#[test]
fn closed_and_periodic_flags_follow_the_data() {
    // A periodic-layout quadratic: the last 2 poles repeat the first 2, uniform knots.
    let pts = vec![
        [1., 0., 0.],
        [0., 1., 0.],
        [-1., 0., 0.],
        [0., -1., 0.],
        [1., 0., 0.],
        [0., 1., 0.],
    ];
    let periodic = NurbsCurve::new(2, (0..9).map(f64::from).collect(), pts, None).unwrap();
    // A clamped closed square-ish curve.
    let closed = NurbsCurve::new(
        1,
        vec![0., 0., 1., 2., 3., 3.],
        vec![[0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 0., 0.]],
        None,
    )
    .unwrap();
    let mut doc = Document::new(Format::Iges, LengthUnit::Mm);
    doc.entities.push(entity("p", Geometry::Curve(periodic)));
    doc.entities.push(entity("c", Geometry::Curve(closed)));
    let text = exchange::iges::write(&doc, &export_options()).unwrap();
    let file = nurbsx_parsers::iges::parse(&text).unwrap();
    use nurbsx_parsers::iges::records::Curve126;
    let p = file
        .decode::<Curve126>(file.entry(1).unwrap())
        .record
        .unwrap();
    assert_eq!((p.closed, p.periodic), (1, 1));
    assert_eq!((p.v0, p.v1), (Some(2.0), Some(6.0)));
    let c = file
        .decode::<Curve126>(file.entry(3).unwrap())
        .record
        .unwrap();
    assert_eq!((c.closed, c.periodic), (1, 0));
    let back = exchange::iges::read(&text, &ImportOptions::default()).unwrap();
    assert!(!has(&back, "flag_mismatch"), "{:#?}", back.diagnostics);
}

const LINE_126: &str = "126,3,2,0,0,1,0,0.,0.,0.,0.5,1.,1.,1.,1.,1.,1.,1.,0.,0.,0.,1.,0.,2.,2.,1.,-1.,3.,3.,0.5,0.,1.;";

#[test]
fn transform_chain_is_applied_to_the_poles() {
    // 126 -> 124 (rotation about z by 90 degrees + translation) -> 124 (scale 2, shift).
    let mut b = Builder::new(&global(2, "MM"));
    let outer = b.entity(
        De {
            ty: 124,
            ..De::default()
        },
        "124,2.,0.,0.,1.,0.,2.,0.,0.,0.,0.,2.,-3.;",
    );
    let inner = b.entity(
        De {
            ty: 124,
            transform: outer as i64,
            ..De::default()
        },
        "124,0.,-1.,0.,10.,1.,0.,0.,20.,0.,0.,1.,30.;",
    );
    let plain = b.entity(De::default(), LINE_126);
    let moved = b.entity(
        De {
            transform: inner as i64,
            ..De::default()
        },
        LINE_126,
    );
    let text = b.build();
    let doc = exchange::iges::read(&text, &ImportOptions::default()).unwrap();
    assert!(!doc.has_errors(), "{:#?}", doc.diagnostics);
    let c0 = curve(&doc, &format!("D{plain}"));
    let c1 = curve(&doc, &format!("D{moved}"));
    let e1 = doc
        .entities
        .iter()
        .find(|e| e.id == format!("D{moved}"))
        .unwrap();
    assert_eq!(
        e1.meta.transforms_applied,
        vec![format!("D{inner}"), format!("D{outer}")]
    );
    // Apply the maps by hand to points of the untransformed curve.
    let map = |p: [f64; 3]| {
        let q = [-p[1] + 10.0, p[0] + 20.0, p[2] + 30.0];
        [2.0 * q[0] + 1.0, 2.0 * q[1], 2.0 * q[2] - 3.0]
    };
    for k in 0..=40 {
        let t = k as f64 / 40.0;
        let want = map(c0.point_at(t).unwrap());
        let got = c1.point_at(t).unwrap();
        for d in 0..3 {
            assert!(
                (want[d] - got[d]).abs() < 1e-12,
                "t={t}: {want:?} vs {got:?}"
            );
        }
    }
}

#[test]
fn transform_cycle_is_an_entity_error() {
    let mut b = Builder::new(&global(2, "MM"));
    // DE 1 is a 124 pointing at itself.
    let t = b.entity(
        De {
            ty: 124,
            transform: 1,
            ..De::default()
        },
        "124,1.,0.,0.,0.,0.,1.,0.,0.,0.,0.,1.,0.;",
    );
    assert_eq!(t, 1);
    let bad = b.entity(
        De {
            transform: 1,
            ..De::default()
        },
        LINE_126,
    );
    let good = b.entity(De::default(), LINE_126);
    let doc = exchange::iges::read(&b.build(), &ImportOptions::default()).unwrap();
    let d = find(&doc, "transform.invalid");
    assert_eq!(d.severity, Severity::Error);
    assert_eq!(
        d.location.entity.as_deref(),
        Some(format!("D{bad}").as_str())
    );
    assert!(d.message.contains("loops"), "{}", d.message);
    assert_eq!(doc.entities.len(), 1);
    assert_eq!(doc.entities[0].id, format!("D{good}"));
}

#[test]
fn units_inch_and_metre_read_and_converted() {
    for (flag, name, unit, mm) in [
        (1, "INCH", LengthUnit::In, 25.4),
        (6, "M", LengthUnit::M, 1000.0),
    ] {
        let mut b = Builder::new(&global(flag, name));
        b.entity(De::default(), LINE_126);
        let text = b.build();
        let doc = exchange::iges::read(&text, &ImportOptions::default()).unwrap();
        assert_eq!(doc.units, unit);
        assert!(!has(&doc, "unit_conflict"));
        let c = curve(&doc, "D1");
        assert_eq!(c.control_points()[3], [3., 3., 0.5]);
        let opts = ImportOptions {
            target_units: Some(LengthUnit::Mm),
            ..ImportOptions::default()
        };
        let doc = exchange::iges::read(&text, &opts).unwrap();
        assert_eq!(doc.units, LengthUnit::Mm);
        assert_eq!(find(&doc, "units_converted").severity, Severity::Info);
        let c = curve(&doc, "D1");
        assert_eq!(c.control_points()[3], [3. * mm, 3. * mm, 0.5 * mm]);
        // Writing the mm document in the original unit gives the original numbers back.
        let out = exchange::iges::write(
            &doc,
            &ExportOptions {
                units: Some(unit),
                ..export_options()
            },
        )
        .unwrap();
        let again = exchange::iges::read(&out, &ImportOptions::default()).unwrap();
        assert_eq!(again.units, unit);
        let c = curve(&again, "D1");
        for (a, b) in c.control_points()[3].iter().zip([3., 3., 0.5]) {
            assert!((a - b).abs() < 1e-15);
        }
    }
}

#[test]
fn unit_flag_and_name_conflict() {
    let mut b = Builder::new(&global(1, "MM"));
    b.entity(De::default(), LINE_126);
    let doc = exchange::iges::read(&b.build(), &ImportOptions::default()).unwrap();
    assert_eq!(doc.units, LengthUnit::In); // the flag wins
    let d = find(&doc, "unit_conflict");
    assert_eq!(
        (d.severity, d.location.section),
        (Severity::Warning, Some('G'))
    );
    // Flag 3: the name decides.
    let mut b = Builder::new(&global(3, "CM"));
    b.entity(De::default(), LINE_126);
    let doc = exchange::iges::read(&b.build(), &ImportOptions::default()).unwrap();
    assert_eq!(doc.units, LengthUnit::Cm);
    assert!(!has(&doc, "unit_conflict"));
}

#[test]
fn one_broken_126_among_good_ones() {
    let mut b = Builder::new(&global(2, "MM"));
    let g1 = b.entity(De::default(), LINE_126);
    let bad = b.entity(De::default(), &LINE_126.replace("2.,2.,1.", "2.,2x,1."));
    let g2 = b.entity(De::default(), LINE_126);
    // Decreasing knots: valid syntax, invalid geometry.
    let bad2 = b.entity(De::default(), &LINE_126.replace("0.,0.5,1.", "0.,1.5,1."));
    let text = b.build();
    let doc = exchange::iges::read(&text, &ImportOptions::default()).unwrap();
    let ids: Vec<&str> = doc.entities.iter().map(|e| e.id.as_str()).collect();
    assert_eq!(ids, vec![format!("D{g1}"), format!("D{g2}")]);
    let d = find(&doc, "iges.entity");
    assert_eq!(d.severity, Severity::Error);
    assert_eq!(
        d.location.entity.as_deref(),
        Some(format!("D{bad}").as_str())
    );
    assert_eq!(d.location.section, Some('P'));
    // Locate "2x" in the file independently.
    let (line_no, line) = text
        .lines()
        .enumerate()
        .find(|(_, l)| l.contains("2x"))
        .unwrap();
    assert_eq!(d.location.line, Some(line_no + 1));
    assert_eq!(d.location.column, Some(line.find("2x").unwrap() + 1));
    assert_eq!(
        d.location.sequence,
        Some(line[73..].trim().parse().unwrap())
    );
    let d = find(&doc, "geometry.invalid");
    assert_eq!(
        d.location.entity.as_deref(),
        Some(format!("D{bad2}").as_str())
    );
    assert_eq!(d.location.section, Some('D'));
}

#[test]
fn prop3_policies() {
    let h = "0.70710678118654757";
    let unequal =
        format!("126,2,2,0,0,1,0,0.,0.,0.,1.,1.,1.,1.,{h},1.,1.,0.,0.,1.,1.,0.,0.,1.,0.,0.,1.;");
    let equal = "126,2,2,0,0,1,0,0.,0.,0.,1.,1.,1.,2.,2.,2.,1.,0.,0.,1.,1.,0.,0.,1.,0.,0.,1.;";
    let rational_equal = equal.replace("126,2,2,0,0,1,0", "126,2,2,0,0,0,0");
    let mut b = Builder::new(&global(2, "MM"));
    b.entity(De::default(), &unequal);
    b.entity(De::default(), equal);
    b.entity(De::default(), &rational_equal);
    let doc = exchange::iges::read(&b.build(), &ImportOptions::default()).unwrap();
    let d = find(&doc, "prop3_inconsistent");
    assert_eq!(
        (d.severity, d.location.entity.as_deref()),
        (Severity::Warning, Some("D1"))
    );
    let c = curve(&doc, "D1");
    assert_eq!(c.weights().unwrap()[1], std::f64::consts::FRAC_1_SQRT_2);
    // The kept weights make an exact circle arc of radius 1 about (0, 0, 0)... evaluated.
    let p = c.point_at(0.5).unwrap();
    assert!(((p[0] * p[0] + p[1] * p[1]).sqrt() - 1.0).abs() < 1e-15);
    assert_eq!(curve(&doc, "D3").weights(), None);
    assert_eq!(curve(&doc, "D5").weights(), Some(&[2.0, 2.0, 2.0][..]));
    assert!(has(&doc, "prop3_rational_equal_weights"));
}

#[test]
fn occt_periodic_flag_on_clamped_knots_is_reported_not_applied() {
    let mut b = Builder::new(&global(2, "MM"));
    b.entity(
        De::default(),
        &LINE_126.replace("126,3,2,0,0,1,0", "126,3,2,0,1,1,1"),
    );
    let doc = exchange::iges::read(&b.build(), &ImportOptions::default()).unwrap();
    let msgs: Vec<&str> = doc
        .diagnostics
        .iter()
        .filter(|d| d.code == "flag_mismatch")
        .map(|d| d.message.as_str())
        .collect();
    assert!(
        msgs.iter()
            .any(|m| m.contains("PROP4") && m.contains("clamped")),
        "{msgs:?}"
    );
    assert!(msgs.iter().any(|m| m.contains("PROP2")), "{msgs:?}");
    let c = curve(&doc, "D1");
    assert_eq!(c.knots(), &[0., 0., 0., 0.5, 1., 1., 1.]);
    let e = &doc.entities[0];
    assert_eq!(
        (e.meta.periodic_u, e.meta.closed_u),
        (Some(true), Some(true))
    );
}

#[test]
fn surface_used_by_144_and_curve_in_142() {
    let surf = "128,1,1,1,1,0,0,1,0,0,0.,0.,1.,1.,0.,0.,1.,1.,1.,1.,1.,1.,0.,0.,0.,1.,0.,0.,0.,1.,0.,1.,1.,0.,0.,1.,0.,1.;";
    let mut b = Builder::new(&global(2, "MM"));
    let s = b.entity(
        De {
            ty: 128,
            status: "00010000",
            ..De::default()
        },
        surf,
    );
    let bt = b.entity(
        De {
            status: "00010500",
            ..De::default()
        },
        "126,1,1,1,0,1,0,0.,0.,1.,1.,1.,1.,0.,0.,0.,1.,1.,0.,0.,1.,0.,0.,1.;",
    );
    let cos = b.entity(
        De {
            ty: 142,
            ..De::default()
        },
        &format!("142,0,{s},{bt},0,1;"),
    );
    let trim = b.entity(
        De {
            ty: 144,
            ..De::default()
        },
        &format!("144,{s},1,0,{cos};"),
    );
    let text = b.build();
    let doc = exchange::iges::read(&text, &ImportOptions::default()).unwrap();
    assert!(!doc.has_errors(), "{:#?}", doc.diagnostics);
    let se = doc
        .entities
        .iter()
        .find(|e| e.id == format!("D{s}"))
        .unwrap();
    assert_eq!(se.meta.used_by, vec![format!("D{cos}"), format!("D{trim}")]);
    let d = find(&doc, "trim_ignored");
    assert_eq!(d.location.entity.as_deref(), Some(format!("D{s}").as_str()));
    let be = doc
        .entities
        .iter()
        .find(|e| e.id == format!("D{bt}"))
        .unwrap();
    assert_eq!(be.geometry.dimension(), 2); // use flag 05 and z = 0
    // The 142 and 144 belong to the topology pass (which reported `trim_ignored` above),
    // not to the list of entity types nurbsx skips.
    assert!(
        doc.diagnostics.iter().all(|d| d.code != "entities_skipped"),
        "{:#?}",
        doc.diagnostics
    );
    // The 4 corner points of the bilinear surface.
    let Geometry::Surface(sf) = &se.geometry else {
        panic!()
    };
    assert_eq!(sf.point_at(1.0, 0.0).unwrap(), [1., 0., 0.]);
    assert_eq!(sf.point_at(0.0, 1.0).unwrap(), [0., 1., 0.]);
}

#[test]
fn degree_limit_is_enforced() {
    let mut b = Builder::new(&global(2, "MM"));
    b.entity(De::default(), LINE_126);
    let opts = ImportOptions {
        limits: nurbsx_parsers::Limits {
            max_degree: 1,
            ..Default::default()
        },
        ..ImportOptions::default()
    };
    let doc = exchange::iges::read(&b.build(), &opts).unwrap();
    assert!(doc.entities.is_empty());
    assert_eq!(find(&doc, "limit.degree").severity, Severity::Error);
}

#[test]
fn unreadable_file_is_a_located_error() {
    let mut b = Builder::new(&global(2, "MM"));
    b.entity(De::default(), LINE_126);
    let text = b.build();
    let cut: String = text.lines().take(4).map(|l| format!("{l}\n")).collect();
    let e = exchange::iges::read(&cut, &ImportOptions::default()).unwrap_err();
    assert_eq!(e.code, "iges.syntax");
    assert_eq!(e.location.section, Some('P'));
    // And through the sniffing front door.
    let doc = exchange::read(text.as_bytes(), &ImportOptions::default()).unwrap();
    assert_eq!(doc.entities.len(), 1);
}

#[test]
fn freecad_file_matches_freecad_evaluations() {
    // See tests/data/iges/README.md for how the file was made.
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/iges/");
    let text = std::fs::read_to_string(format!("{dir}freecad_arc_surface.igs")).unwrap();
    let json: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(format!("{dir}freecad_arc_surface.json")).unwrap(),
    )
    .unwrap();
    let doc = exchange::iges::read(&text, &ImportOptions::default()).unwrap();
    assert!(!doc.has_errors(), "{:#?}", doc.diagnostics);
    assert_eq!(doc.units, LengthUnit::Mm);
    // The file's curve and surface, and the four sides of the domain that bounds its face
    // (a 144 with N1 = 0: the face's outer loop, `tests/iges_topology.rs`).
    let boundary = |e: &&nurbsx::exchange::Entity| e.source.entity == "144 (domain boundary)";
    assert_eq!(doc.entities.iter().filter(|e| !boundary(e)).count(), 2);
    assert_eq!(doc.entities.iter().filter(boundary).count(), 4);
    // OCCT writes 9 significant digits (weights 0.707106781): agreement to ~1e-8.
    let tol = 1e-7;
    let c = curve(&doc, "D7");
    assert!(c.is_rational());
    for row in json["curve"].as_array().unwrap() {
        let r: Vec<f64> = row
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect();
        let p = c.point_at(r[0]).unwrap();
        for d in 0..3 {
            assert!((p[d] - r[1 + d]).abs() < tol, "t={}: {p:?} vs {r:?}", r[0]);
        }
    }
    let se = doc.entities.iter().find(|e| e.id == "D5").unwrap();
    assert_eq!(se.meta.used_by, vec!["D3".to_owned()]);
    // The 144 (N1 = 0: bounded by the surface's own domain) is read as a face on that
    // surface bounded by the domain's four sides, so no trim is left unapplied.
    let faces = &doc.topology.model.faces;
    assert_eq!(faces.len(), 1);
    assert_eq!(faces[0].loops.len(), 1);
    assert_eq!(faces[0].loops[0].coedges.len(), 4);
    assert_eq!(doc.topology.origins.faces[0].id, "D3");
    assert_eq!(doc.topology.origins.faces[0].entity.as_deref(), Some("D5"));
    assert!(!doc.diagnostics.iter().any(|d| d.code == "trim_ignored"));
    let Geometry::Surface(s) = &se.geometry else {
        panic!("not a surface")
    };
    assert_eq!((s.control_points().nu(), s.control_points().nv()), (4, 3));
    for row in json["surface"].as_array().unwrap() {
        let r: Vec<f64> = row
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect();
        let p = s.point_at(r[0], r[1]).unwrap();
        for d in 0..3 {
            assert!(
                (p[d] - r[2 + d]).abs() < tol,
                "uv=({}, {}): {p:?} vs {r:?}",
                r[0],
                r[1]
            );
        }
    }
}

#[test]
fn missing_range_and_trim_option_are_reported() {
    // LINE_126 without its trailing V(0), V(1).
    let short = LINE_126.replace(",0.,1.;", ";");
    let mut b = Builder::new(&global(2, "MM"));
    b.entity(De::default(), &short);
    let opts = ImportOptions {
        trim_to_parameter_range: true,
        ..ImportOptions::default()
    };
    let doc = exchange::iges::read(&b.build(), &opts).unwrap();
    let d = find(&doc, "missing_param_range");
    assert_eq!(d.location.entity.as_deref(), Some("D1"));
    assert!(has(&doc, "trim_not_applied"));
    let e = &doc.entities[0];
    assert_eq!(e.meta.parameter_range, None);
    let c = curve(&doc, "D1");
    // Nothing shifted: the last pole is still (3, 3, 0.5) and the domain is the knots'.
    assert_eq!(c.control_points()[3], [3., 3., 0.5]);
    assert_eq!(c.domain(), (0.0, 1.0));
}

#[test]
fn long_transform_chains_are_refused() {
    // 70 chained identity 124s (above the default nesting limit of 64).
    let mut b = Builder::new(&global(2, "MM"));
    let mut prev = 0i64;
    for _ in 0..70 {
        prev = b.entity(
            De {
                ty: 124,
                transform: prev,
                ..De::default()
            },
            "124,1.,0.,0.,0.,0.,1.,0.,0.,0.,0.,1.,0.;",
        ) as i64;
    }
    let c = b.entity(
        De {
            transform: prev,
            ..De::default()
        },
        LINE_126,
    );
    let doc = exchange::iges::read(&b.build(), &ImportOptions::default()).unwrap();
    let d = find(&doc, "transform.invalid");
    assert!(
        d.message.contains("longer than the limit of 64"),
        "{}",
        d.message
    );
    assert_eq!(d.location.entity.as_deref(), Some(format!("D{c}").as_str()));
    assert!(doc.entities.is_empty());
}

#[test]
fn polynomial_flag_with_unusable_weights_reads_as_polynomial() {
    let zero_w = "126,2,2,0,0,1,0,0.,0.,0.,1.,1.,1.,0.,0.,1.,1.,0.,0.,1.,1.,0.,0.,1.,0.,0.,1.;";
    let mut b = Builder::new(&global(2, "MM"));
    b.entity(De::default(), zero_w);
    b.entity(
        De::default(),
        &zero_w.replace("126,2,2,0,0,1,0", "126,2,2,0,0,0,0"),
    );
    let doc = exchange::iges::read(&b.build(), &ImportOptions::default()).unwrap();
    assert_eq!(curve(&doc, "D1").weights(), None);
    assert!(has(&doc, "prop3_inconsistent"));
    // Flagged rational with a zero weight: invalid, located, not loaded.
    let d = find(&doc, "geometry.invalid");
    assert_eq!(d.location.entity.as_deref(), Some("D3"));
    assert_eq!(doc.entities.len(), 1);
}

/// Declared parameter ranges (`V(0), V(1)`, `U(0)..V(1)`) are written clipped to the knot
/// domain (IGES 5.3 sections 4.23, 4.24 want them inside); a range inside is written as
/// declared, one beyond the domain by rounding is clipped without a word, and every other
/// change is a `range_clipped` warning naming the entity. The expected ranges are the
/// intersections of the declared ranges with the domain [0, 1], worked by hand.
#[test]
fn declared_ranges_are_written_clipped_to_the_domain_and_reported() {
    use nurbsx::exchange::ParameterRange;
    let line = || {
        NurbsCurve::new(
            1,
            vec![0., 0., 1., 1.],
            vec![[0., 0., 0.], [1., 2., 3.]],
            None,
        )
        .unwrap()
    };
    let patch = NurbsSurface::new(
        1,
        1,
        vec![0., 0., 1., 1.],
        vec![0., 0., 1., 1.],
        Grid::from_u_major(
            2,
            2,
            vec![[0., 0., 0.], [0., 1., 0.], [1., 0., 0.], [1., 1., 1.]],
        )
        .unwrap(),
        None,
    )
    .unwrap();
    let ulp = f64::EPSILON;
    type Case = (&'static str, (f64, f64), (f64, f64), bool);
    let cases: [Case; 4] = [
        ("inside", (0.25, 0.75), (0.25, 0.75), false),
        ("overlapping", (-0.5, 0.5), (0.0, 0.5), true),
        ("rounding", (-ulp, 1.0 + 2.0 * ulp), (0.0, 1.0), false),
        ("disjoint", (2.0, 3.0), (0.0, 1.0), true),
    ];
    let mut doc = Document::new(Format::Iges, LengthUnit::Mm);
    for (id, range, _, _) in cases {
        let mut e = entity(id, Geometry::Curve(line()));
        e.meta.parameter_range = Some(Box::new(ParameterRange { u: range, v: None }));
        doc.entities.push(e);
    }
    let mut s = entity("surface", Geometry::Surface(patch));
    s.meta.parameter_range = Some(Box::new(ParameterRange {
        u: (0.125, 0.5),
        v: Some((0.5, 1.5)),
    }));
    doc.entities.push(s);
    let warnings = exchange::iges::range_warnings(&doc);
    let warned: Vec<&str> = warnings
        .iter()
        .filter(|d| d.code == "range_clipped" && d.severity == Severity::Warning)
        .filter_map(|d| d.location.entity.as_deref())
        .collect();
    let expected: Vec<&str> = cases
        .iter()
        .filter(|c| c.3)
        .map(|c| c.0)
        .chain(["surface"])
        .collect();
    assert_eq!(warned, expected, "{warnings:#?}");
    let text = exchange::iges::write(&doc, &export_options()).unwrap();
    let file = nurbsx_parsers::iges::parse(&text).unwrap();
    use nurbsx_parsers::iges::records::{Curve126, Surface128};
    for (k, (id, _, written, _)) in cases.iter().enumerate() {
        let de = 2 * k as i64 + 1;
        let rec = file
            .decode::<Curve126>(file.entry(de).unwrap())
            .record
            .unwrap();
        assert_eq!((rec.v0, rec.v1), (Some(written.0), Some(written.1)), "{id}");
    }
    let rec = file
        .decode::<Surface128>(file.entry(9).unwrap())
        .record
        .unwrap();
    assert_eq!(rec.range, Some([0.125, 0.5, 0.5, 1.0]));
}

/// IGES 126 forms 1-5 and 128 forms 1-8 (IGES 5.3 sections 4.23, 4.24) name the entity's
/// kind: read as `meta.shape` when the geometry passes that kind's check, so that a circle
/// stays a circle in STEP (`.CIRCULAR_ARC.`) and IGES (form 2) output; a form the geometry
/// does not have is a `form_mismatch` warning and no label. The 128 cylinder here has its
/// circles in v and its rulings in u (the transpose of nurbsx's own layout), which the
/// standard allows. A free curve whose declared `V(0), V(1)` is not its domain is a
/// `range_not_written` warning when written to STEP.
#[test]
fn iges_form_numbers_label_the_kind_when_the_geometry_agrees() {
    use nurbsx::exchange::Shape;
    let h = std::f64::consts::FRAC_1_SQRT_2;
    let arc = format!(
        "126,2,2,1,0,0,0,0.,0.,0.,1.,1.,1.,1.,{h},1.,1.,0.,0.,1.,1.,0.,0.,1.,0.,0.,1.,0.,0.,1.;"
    );
    let parabola =
        "126,2,2,1,0,1,0,0.,0.,0.,1.,1.,1.,1.,1.,1.,1.,0.,0.,1.,1.,0.,0.,1.,0.,0.,1.,0.,0.,1.;";
    // u: degree 1 along z (2 poles); v: the rational quarter circle (3 poles); u fastest.
    let mut cyl = String::from("128,1,2,1,2,0,0,0,0,0,0.,0.,1.,1.,0.,0.,0.,1.,1.,1.,");
    for w in [1.0, h, 1.0] {
        cyl += &format!("{w},{w},");
    }
    for p in [[1., 0.], [1., 1.], [0., 1.]] {
        for z in [0.0, 1.0] {
            cyl += &format!("{},{},{z},", p[0], p[1]);
        }
    }
    cyl += "0.,1.,0.,1.;";
    let mut b = Builder::new(&global(2, "MM"));
    let arc_de = b.entity(
        De {
            form: 2,
            ..De::default()
        },
        &arc,
    );
    let parabola_de = b.entity(
        De {
            form: 2,
            ..De::default()
        },
        parabola,
    );
    let cyl_de = b.entity(
        De {
            ty: 128,
            form: 2,
            ..De::default()
        },
        &cyl,
    );
    let short_de = b.entity(De::default(), &LINE_126.replace("0.,1.;", "0.25,1.;"));
    let text = b.build();
    let doc = exchange::iges::read(&text, &ImportOptions::default()).unwrap();
    assert!(!doc.has_errors(), "{:#?}", doc.diagnostics);
    let shape = |de: usize| {
        doc.entities
            .iter()
            .find(|e| e.id == format!("D{de}"))
            .unwrap()
            .meta
            .shape
    };
    assert_eq!(shape(arc_de), Some(Shape::CircularArc));
    assert_eq!(shape(parabola_de), None);
    assert_eq!(shape(cyl_de), Some(Shape::Cylinder));
    let mismatches: Vec<_> = doc
        .diagnostics
        .iter()
        .filter(|d| d.code == "form_mismatch")
        .map(|d| d.location.entity.clone())
        .collect();
    assert_eq!(mismatches, [Some(format!("D{parabola_de}"))]);
    // STEP: the labels become the forms; the short line's range is reported.
    let step = exchange::step::write(&doc, &export_options()).unwrap();
    assert_eq!(step.matches(".CIRCULAR_ARC.").count(), 1, "{step}");
    assert_eq!(step.matches(".CYLINDRICAL_SURF.").count(), 1, "{step}");
    assert!(exchange::step::form_warnings(&doc).is_empty());
    let ranges = exchange::step::range_warnings(&doc);
    let ranged: Vec<_> = ranges
        .iter()
        .map(|d| (d.code.as_str(), d.location.entity.clone()))
        .collect();
    assert_eq!(
        ranged,
        [("range_not_written", Some(format!("D{short_de}")))]
    );
    // IGES: forms 2 (arc), 0 (parabola), 2 (cylinder).
    let iges = exchange::iges::write(&doc, &export_options()).unwrap();
    let forms = entity_forms(&iges);
    assert_eq!(forms, [(126, 2), (126, 0), (128, 2), (126, 0)]);
}

/// A writer that prints 8 significant digits (SolidWorks, many others) writes a circle's
/// weight as `0.64278761` and its poles rounded: the arc is a circle only to that precision.
/// The form check follows the digits written (README "IGES form numbers"), so the 126 form 2
/// and 128 form 2 labels are kept, with no warning, and written again as IGES forms 2 and
/// STEP `.CIRCULAR_ARC.` / `.CYLINDRICAL_SURF.`, also for a copy under a 124 rotation (whose
/// recomputed poles carry the file's precision as `meta.shape_tolerance`). The same arc with
/// its weight off by 1e-4 (far beyond 8 digits) is still refused the label.
#[test]
fn form_checks_follow_the_digits_the_file_wrote() {
    use nurbsx::exchange::Shape;
    let eight = common::eight_digits;
    let (poles, w) = common::tilted_arc();
    let arc = |weight: f64| {
        let mut p = format!("126,2,2,0,0,0,0,0.,0.,0.,1.,1.,1.,1.,{},1.,", eight(weight));
        for q in &poles {
            p += &format!("{},{},{},", eight(q[0]), eight(q[1]), eight(q[2]));
        }
        p + "0.,1.,0.,0.,0.;"
    };
    // A quarter cylinder of radius 25 and height 40 about z: circles in u, rulings in v.
    let h = std::f64::consts::FRAC_1_SQRT_2;
    let mut cyl = format!(
        "128,2,1,2,1,0,0,0,0,0,0.,0.,0.,1.,1.,1.,0.,0.,1.,1.,1.,{},1.,1.,{},1.,",
        eight(h),
        eight(h)
    );
    for z in [0.0, 40.0] {
        for (x, y) in [(25.0, 0.0), (25.0, 25.0), (0.0, 25.0)] {
            cyl += &format!("{x}.,{y}.,{z}.,").replace("..", ".");
        }
    }
    cyl += "0.,1.,0.,1.;";
    let mut b = Builder::new(&global(2, "MM"));
    let form2 = |ty: i64| De {
        ty,
        form: 2,
        ..De::default()
    };
    let arc_de = b.entity(form2(126), &arc(w));
    let cyl_de = b.entity(form2(128), &cyl);
    let off_de = b.entity(form2(126), &arc(w * (1.0 + 1e-4)));
    // The arc again under a 124 turning it by 30 degrees about z: its poles recomputed in
    // full precision no longer show the 8 digits, which the label keeps as its precision.
    let (c, s30) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
    let turn = b.entity(
        De {
            ty: 124,
            ..De::default()
        },
        &format!("124,{c},{},0.,5.,{s30},{c},0.,-2.,0.,0.,1.,0.;", -s30),
    );
    let turned_de = b.entity(
        De {
            transform: turn as i64,
            ..form2(126)
        },
        &arc(w),
    );
    let doc = exchange::iges::read(&b.build(), &ImportOptions::default()).unwrap();
    assert!(!doc.has_errors(), "{:#?}", doc.diagnostics);
    let entity = |de: usize| {
        doc.entities
            .iter()
            .find(|e| e.id == format!("D{de}"))
            .unwrap()
    };
    assert_eq!(entity(arc_de).meta.shape, Some(Shape::CircularArc));
    assert_eq!(entity(cyl_de).meta.shape, Some(Shape::Cylinder));
    assert_eq!(entity(off_de).meta.shape, None);
    assert_eq!(entity(turned_de).meta.shape, Some(Shape::CircularArc));
    // Only the turned arc needed the file's digits beyond its own.
    assert_eq!(entity(arc_de).meta.shape_tolerance, None);
    assert!(entity(turned_de).meta.shape_tolerance.is_some());
    let warned: Vec<_> = doc
        .diagnostics
        .iter()
        .filter(|d| d.severity != Severity::Info)
        .map(|d| (d.code.as_str(), d.location.entity.clone()))
        .collect();
    assert_eq!(warned, [("form_mismatch", Some(format!("D{off_de}")))]);
    // The labels survive writing: no form warning, the forms written.
    assert!(exchange::iges::form_warnings(&doc).is_empty());
    assert!(exchange::step::form_warnings(&doc).is_empty());
    let step = exchange::step::write(&doc, &export_options()).unwrap();
    assert_eq!(step.matches(".CIRCULAR_ARC.").count(), 2, "{step}");
    assert_eq!(step.matches(".CYLINDRICAL_SURF.").count(), 1, "{step}");
    let iges = exchange::iges::write(&doc, &export_options()).unwrap();
    let forms = entity_forms(&iges);
    assert_eq!(forms, [(126, 2), (128, 2), (126, 0), (126, 2)]);
}

/// `(entity type, form)` of every directory entry of an IGES text, in order.
fn entity_forms(iges: &str) -> Vec<(i64, i64)> {
    let file = nurbsx_parsers::iges::parse(iges).unwrap();
    file.entries
        .iter()
        .flatten()
        .map(|e| (e.entity_type, e.form))
        .collect()
}
