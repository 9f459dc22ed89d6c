//! Typed Part 42 / 41 / 43 records read by attribute name (pitfalls.md B.7, E.24).
// Helpers outside #[test] functions may fail loudly too: they only run under tests.
#![allow(clippy::expect_used, clippy::unwrap_used, clippy::panic)]

use nurbsx_parsers::Limits;
use nurbsx_parsers::step::schema::{
    At, BSplineCurve, BSplineSurface, CartesianPoint, KnotSpec, Logical, MeasureWithUnit,
    PerDirection, RepresentationContext, Unit,
};
use nurbsx_parsers::step::{Instance, StepString, parse};

fn instances(data: &str) -> Vec<Instance<'_>> {
    let text: &'static str = Box::leak(
        format!("ISO-10303-21;HEADER;ENDSEC;DATA;\n{data}\nENDSEC;END-ISO-10303-21;")
            .into_boxed_str(),
    );
    let p = parse(text, &Limits::default()).unwrap();
    let bad: Vec<_> = p
        .errors
        .iter()
        .filter(|e| {
            !matches!(
                e.kind,
                nurbsx_parsers::step::ParseErrorKind::DanglingReference(_)
            )
        })
        .collect();
    assert!(bad.is_empty(), "{bad:?}");
    p.exchange.instances().cloned().collect()
}

fn at(id: u64) -> At {
    At {
        id,
        line: 2,
        column: 1,
    }
}

#[test]
fn none_empty_and_complex_forms_read_the_same() {
    let forms = [
        "#1=B_SPLINE_CURVE_WITH_KNOTS('NONE',2,(#2,#3,#4),.UNSPECIFIED.,.F.,.U.,(3,3),(0.,1.),.PIECEWISE_BEZIER_KNOTS.);",
        "#1=B_SPLINE_CURVE_WITH_KNOTS('',2,(#2,#3,#4),.UNSPECIFIED.,.F.,.U.,(3,3),(0.,1.),.PIECEWISE_BEZIER_KNOTS.);",
        "#1=(BOUNDED_CURVE() B_SPLINE_CURVE(2,(#2,#3,#4),.UNSPECIFIED.,.F.,.U.) B_SPLINE_CURVE_WITH_KNOTS((3,3),(0.,1.),.PIECEWISE_BEZIER_KNOTS.) CURVE() GEOMETRIC_REPRESENTATION_ITEM() REPRESENTATION_ITEM('NONE'));",
        "#1=(REPRESENTATION_ITEM('NONE') B_SPLINE_CURVE_WITH_KNOTS((3,3),(0.,1.),.PIECEWISE_BEZIER_KNOTS.) CURVE() B_SPLINE_CURVE(2,(#2,#3,#4),.UNSPECIFIED.,.F.,.U.) GEOMETRIC_REPRESENTATION_ITEM() BOUNDED_CURVE());",
        "#1=(BNDCRV() BSPCR(2,(#2,#3,#4),.UNSPECIFIED.,.F.,.U.) BSCWK((3,3),(0.,1.),.PIECEWISE_BEZIER_KNOTS.) CURVE() GMRPIT() RPRITM('NONE'));",
    ];
    let mut records = Vec::new();
    for f in forms {
        let insts = instances(f);
        let r = BSplineCurve::from_instance(&insts[0], at(1)).unwrap();
        assert_eq!(r.degree, 2);
        assert_eq!(r.control_points, [2, 3, 4]);
        assert_eq!(r.closed_curve, Logical::False);
        assert_eq!(r.self_intersect, Logical::Unknown);
        assert_eq!(
            r.knots,
            KnotSpec::Explicit {
                multiplicities: PerDirection::curve(vec![3, 3]),
                knots: PerDirection::curve(vec![0., 1.]),
                knot_spec: "PIECEWISE_BEZIER_KNOTS"
            }
        );
        assert_eq!(r.weights, None);
        records.push(r);
    }
    assert_eq!(records[0].name, Some(StepString::new("NONE")));
    assert_eq!(records[1].name, Some(StepString::new("")));
    assert_eq!(records[2].name, Some(StepString::new("NONE")));
}

#[test]
fn rational_partials_in_any_order() {
    // ixmilia/step #17 shape: the seven partials, shuffled.
    let a = "#1=( BOUNDED_CURVE() B_SPLINE_CURVE(2,(#2,#3,#4),.CIRCULAR_ARC.,.F.,.F.) B_SPLINE_CURVE_WITH_KNOTS((3,3),(0.,1.),.UNSPECIFIED.) CURVE() GEOMETRIC_REPRESENTATION_ITEM() RATIONAL_B_SPLINE_CURVE((1.,0.7071067811865476,1.)) REPRESENTATION_ITEM('') );";
    let b = "#1=( RATIONAL_B_SPLINE_CURVE((1.,0.7071067811865476,1.)) CURVE() REPRESENTATION_ITEM('') B_SPLINE_CURVE_WITH_KNOTS((3,3),(0.,1.),.UNSPECIFIED.) GEOMETRIC_REPRESENTATION_ITEM() B_SPLINE_CURVE(2,(#2,#3,#4),.CIRCULAR_ARC.,.F.,.F.) BOUNDED_CURVE() );";
    let ra = BSplineCurve::from_instance(&instances(a)[0], at(1)).unwrap();
    let rb = BSplineCurve::from_instance(&instances(b)[0], at(1)).unwrap();
    assert_eq!(
        ra.weights,
        Some(vec![1., std::f64::consts::FRAC_1_SQRT_2, 1.])
    );
    assert_eq!(ra.curve_form, "CIRCULAR_ARC");
    assert_eq!(
        (ra.degree, &ra.control_points, &ra.knots, &ra.weights),
        (rb.degree, &rb.control_points, &rb.knots, &rb.weights)
    );
}

#[test]
fn implicit_subtypes_and_surfaces() {
    let c = "#1=QUASI_UNIFORM_CURVE('q',3,(#2,#3,#4,#5,#6),.UNSPECIFIED.,.F.,.F.);";
    let r = BSplineCurve::from_instance(&instances(c)[0], at(1)).unwrap();
    assert_eq!(r.knots, KnotSpec::QuasiUniform);
    let s = "#1=( BOUNDED_SURFACE() B_SPLINE_SURFACE(1,1,((#2,#3),(#4,#5)),.UNSPECIFIED.,.F.,.F.,.F.) BEZIER_SURFACE() GEOMETRIC_REPRESENTATION_ITEM() RATIONAL_B_SPLINE_SURFACE(((1.,2.),(3.,4.))) REPRESENTATION_ITEM('') SURFACE() );";
    let r = BSplineSurface::from_instance(&instances(s)[0], at(1)).unwrap();
    assert_eq!(r.knots, KnotSpec::Bezier);
    assert_eq!(r.control_points, vec![vec![2, 3], vec![4, 5]]);
    assert_eq!(r.weights, Some(vec![vec![1., 2.], vec![3., 4.]]));
    let s = "#1=B_SPLINE_SURFACE_WITH_KNOTS('',1,2,((#2,#3,#4),(#5,#6,#7)),.PLANE_SURF.,.F.,.T.,.F.,(2,2),(3,3),(0.,1.),(0.,2.),.UNSPECIFIED.);";
    let r = BSplineSurface::from_instance(&instances(s)[0], at(1)).unwrap();
    assert_eq!(
        (r.u_degree, r.v_degree, r.surface_form, r.v_closed),
        (1, 2, "PLANE_SURF", Logical::True)
    );
}

#[test]
fn schema_errors_name_entity_attribute_and_found_value() {
    // The name left out by a hand-written fixture: the degree slot then holds a list.
    let c = "#9=B_SPLINE_CURVE_WITH_KNOTS(2,(#2,#3,#4),.UNSPECIFIED.,.F.,.F.,(3,3),(0.,1.),.UNSPECIFIED.);";
    let e = BSplineCurve::from_instance(&instances(c)[0], at(9)).unwrap_err();
    assert_eq!(e.entity, 9);
    assert_eq!(e.message, "expected 9 parameters, found 8");
    let c = "#9=B_SPLINE_CURVE_WITH_KNOTS('',2.5,(#2,#3,#4),.UNSPECIFIED.,.F.,.F.,(3,3),(0.,1.),.UNSPECIFIED.);";
    let e = BSplineCurve::from_instance(&instances(c)[0], at(9)).unwrap_err();
    assert_eq!(e.entity_type, "B_SPLINE_CURVE");
    assert_eq!(e.attribute, Some((2, "degree")));
    assert_eq!(e.message, "expected an integer, found a real");
    assert_eq!(
        e.to_string(),
        "line 2, column 1 (#9): B_SPLINE_CURVE parameter 2 `degree`: expected an integer, found a real"
    );
    let c = "#9=(B_SPLINE_CURVE(2,(#2,3,#4),.UNSPECIFIED.,.F.,.F.) B_SPLINE_CURVE_WITH_KNOTS((3,3),(0.,1.),.UNSPECIFIED.) REPRESENTATION_ITEM(''));";
    let e = BSplineCurve::from_instance(&instances(c)[0], at(9)).unwrap_err();
    assert_eq!(e.attribute, Some((2, "control_points_list")));
    assert_eq!(e.message, "element 2 : expected a reference, found 3");
    let c = "#9=B_SPLINE_CURVE('',2,(#2,#3,#4),.UNSPECIFIED.,.F.,.F.);";
    let e = BSplineCurve::from_instance(&instances(c)[0], at(9)).unwrap_err();
    assert!(
        e.message
            .starts_with("a B_SPLINE_CURVE must also be one of"),
        "{}",
        e.message
    );
    let c = "#9=(B_SPLINE_CURVE(2,(#2,#3,#4),.UNSPECIFIED.,.F.,.F.) B_SPLINE_CURVE_WITH_KNOTS((3,3),(0.,1.)) REPRESENTATION_ITEM(''));";
    let e = BSplineCurve::from_instance(&instances(c)[0], at(9)).unwrap_err();
    assert_eq!(
        e.message,
        "partial entity B_SPLINE_CURVE_WITH_KNOTS expects 3 parameters, found 2"
    );
}

#[test]
fn points_units_and_contexts() {
    let insts = instances(
        "#1=CARTESIAN_POINT('',(1.,2.));\n#2=( LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT(.MILLI.,.METRE.) );\n#3=SI_UNIT(*,$,.METRE.);\n#4=( CONVERSION_BASED_UNIT('INCH',#5) LENGTH_UNIT() NAMED_UNIT(#6) );\n#5=LENGTH_MEASURE_WITH_UNIT(LENGTH_MEASURE(25.4),#2);\n#7=( GEOMETRIC_REPRESENTATION_CONTEXT(3) GLOBAL_UNCERTAINTY_ASSIGNED_CONTEXT((#8)) GLOBAL_UNIT_ASSIGNED_CONTEXT((#2,#9)) REPRESENTATION_CONTEXT('',''));\n#8=UNCERTAINTY_MEASURE_WITH_UNIT(LENGTH_MEASURE(1.E-07),#2,'distance_accuracy_value','');",
    );
    let p = CartesianPoint::from_instance(&insts[0], at(1)).unwrap();
    assert_eq!(*p.coordinates, [1., 2.]);
    assert_eq!(
        Unit::from_instance(&insts[1], at(2)).unwrap(),
        Unit::Si {
            prefix: Some("MILLI"),
            name: "METRE",
            length: true
        }
    );
    assert_eq!(
        Unit::from_instance(&insts[2], at(3)).unwrap(),
        Unit::Si {
            prefix: None,
            name: "METRE",
            length: true
        }
    );
    let Unit::ConversionBased {
        name,
        conversion_factor,
        length,
        ..
    } = Unit::from_instance(&insts[3], at(4)).unwrap()
    else {
        panic!()
    };
    assert_eq!(
        (name.decode().unwrap().as_ref(), conversion_factor, length),
        ("INCH", 5, true)
    );
    let m = MeasureWithUnit::from_instance(&insts[4], at(5)).unwrap();
    assert_eq!(
        (m.value, m.measure_type, m.unit),
        (25.4, Some("LENGTH_MEASURE"), 2)
    );
    let c = RepresentationContext::from_instance(&insts[5], at(7))
        .unwrap()
        .unwrap();
    assert_eq!(
        (c.dimension, c.units, c.uncertainty),
        (Some(3), vec![2, 9], vec![8])
    );
    let m = MeasureWithUnit::from_instance(&insts[6], at(8)).unwrap();
    assert_eq!(m.value, 1e-7);
}

/// The record writers against the record readers: every B-spline and point record of every
/// FreeCAD sample, written by `write_bspline_curve` / `write_bspline_surface` /
/// `write_cartesian_point` and decoded again, is the same record (the instance shape, and
/// so `entity_type`, follows from the data: simple when polynomial, the canonical complex
/// instance when rational).
#[test]
fn record_writers_round_trip_every_sample_record() {
    use nurbsx_parsers::step::scan;
    use nurbsx_parsers::step::schema::BSpline;
    use nurbsx_parsers::step::writer::{
        write_bspline_curve, write_bspline_surface, write_cartesian_point,
    };
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../samples/freecad");
    let (mut splines, mut points) = (0, 0);
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|e| e != "step") {
            continue;
        }
        let text = std::fs::read_to_string(&path).unwrap();
        let s = scan(&text, &Limits::default()).unwrap();
        for raw in &s.instances {
            let mut out = String::new();
            let read = if let Ok(Some(b)) = s.bspline(raw) {
                match &b {
                    BSpline::Curve(c) => write_bspline_curve(&mut out, raw.id, c).unwrap(),
                    BSpline::Surface(sf) => write_bspline_surface(&mut out, raw.id, sf).unwrap(),
                }
                splines += 1;
                Some(b)
            } else if raw.keyword(s.text) == Some("CARTESIAN_POINT") {
                let inst = s.decode(raw).unwrap();
                let p = CartesianPoint::from_instance(&inst, at(raw.id)).unwrap();
                write_cartesian_point(&mut out, raw.id, &p).unwrap();
                let again =
                    format!("ISO-10303-21;HEADER;ENDSEC;DATA;\n{out}ENDSEC;END-ISO-10303-21;");
                let s2 = scan(&again, &Limits::default()).unwrap();
                let q = s2.cartesian_point(&s2.instances[0]).unwrap();
                assert_eq!(&q.0[..q.1], &*p.coordinates, "{}", path.display());
                points += 1;
                None
            } else {
                None
            };
            let Some(b) = read else { continue };
            let again = format!("ISO-10303-21;HEADER;ENDSEC;DATA;\n{out}ENDSEC;END-ISO-10303-21;");
            let s2 = scan(&again, &Limits::default()).unwrap();
            let back = s2.bspline(&s2.instances[0]).unwrap().unwrap();
            let strip = |b: BSpline<'_>| match b {
                BSpline::Curve(mut c) => {
                    c.entity_type = Default::default();
                    format!("{c:?}")
                }
                BSpline::Surface(mut sf) => {
                    sf.entity_type = Default::default();
                    format!("{sf:?}")
                }
            };
            assert_eq!(strip(back), strip(b), "{} #{}", path.display(), raw.id);
        }
    }
    assert!(
        splines > 100 && points > 1000,
        "{splines} splines, {points} points"
    );
}
