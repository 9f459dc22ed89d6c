use super::*;
use crate::exchange::test_documents::random_document;
use crate::exchange::{Format, ImportOptions};
use crate::nurbs::Point3;
use nurbsx_parsers::step::{DataSection, Exchange, write_exchange};
use proptest::prelude::*;

// The reference writer: every instance as a `Parameter` tree in a `Builder`, formatted by
// `write_exchange`; `write` must produce exactly its bytes.

/// The straightforward writer: every instance as a [`Parameter`] tree in a [`Builder`],
/// formatted by [`write_exchange`]. [`write`] must produce exactly its bytes (tested).
fn write_reference(document: &Document, options: &ExportOptions) -> Result<String, Diagnostic> {
    let mut f = frame(document, options, None);
    let scale = f.scale;
    let b = &mut f.b;
    let mut curves3 = Vec::new();
    let mut curves2 = Vec::new();
    let mut surfaces = Vec::new();
    for e in &document.entities {
        let loc = Location::at_entity(e.id.clone());
        match &e.geometry {
            Geometry::Curve(c) => {
                let id = curve(b, c, e, scale, options)
                    .map_err(|m| Diagnostic::error("step.write", m, loc))?;
                if c.dimension() == 2 {
                    curves2.push(id);
                } else {
                    curves3.push(id);
                }
            }
            Geometry::Surface(sf) => {
                let id = surface(b, sf, e, scale, options)
                    .map_err(|m| Diagnostic::error("step.write", m, loc))?;
                surfaces.push(id);
            }
        }
    }
    let (set, rep_keyword) = geometric_set(&mut f.b, &curves3, &surfaces);
    let set: Vec<u64> = set.into_iter().collect();
    let header = finish(&mut f, options, rep_keyword, &set, &curves2);
    let b = std::mem::take(&mut f.b);
    let exchange = Exchange {
        header,
        data: vec![DataSection {
            params: Vec::new(),
            instances: b.into_instances(),
        }],
    };
    write_exchange(&exchange)
        .map_err(|e| Diagnostic::error("step.write", e.to_string(), Location::default()))
}

fn point(b: &mut Builder, p: crate::nurbs::Point3, dim: usize, scale: f64) -> u64 {
    let c: Vec<f64> = p.iter().take(dim).map(|x| x * scale).collect();
    b.simple("CARTESIAN_POINT", vec![s(""), Parameter::reals(&c)])
}

/// Distinct knots and multiplicities as STEP parameters.
fn knot_lists(knots: &[f64]) -> (Parameter<'static>, Parameter<'static>) {
    let (values, mults) = crate::nurbs::knots::to_distinct(knots);
    let mults: Vec<i64> = mults
        .iter()
        .map(|&m| i64::try_from(m).unwrap_or(i64::MAX))
        .collect();
    (Parameter::integers(&mults), Parameter::reals(&values))
}

fn form_param(e: &Entity) -> Parameter<'static> {
    Parameter::Enumeration(checked_form(e).unwrap_or("UNSPECIFIED"))
}

fn name_of(e: &Entity) -> Parameter<'static> {
    s(e.meta.name.as_deref().unwrap_or(""))
}

/// Writes one curve; returns its id.
fn curve(
    b: &mut Builder,
    c: &NurbsCurve,
    e: &Entity,
    scale: f64,
    options: &ExportOptions,
) -> Result<u64, String> {
    let dim = c.dimension();
    let pts: Vec<u64> = c
        .control_points()
        .iter()
        .map(|&p| point(b, p, dim, scale))
        .collect();
    let degree = i64::try_from(c.degree()).map_err(|_| "degree out of range".to_owned())?;
    let closed = curve_closed(c);
    let bspline = vec![
        Parameter::Integer(degree),
        Parameter::refs(&pts),
        form_param(e),
        Parameter::logical(closed),
        Parameter::logical(e.meta.self_intersect.unwrap_or(false)),
    ];
    let subtype = curve_subtype(c, options);
    let (mults, knots) = knot_lists(c.knots());
    let spec = Parameter::Enumeration(knot_form(c.degree(), c.knots()));
    let (sub_keyword, sub_params) = match subtype {
        Some(KnotForm::Bezier) => ("BEZIER_CURVE", vec![]),
        Some(KnotForm::Uniform) => ("UNIFORM_CURVE", vec![]),
        Some(KnotForm::QuasiUniform) => ("QUASI_UNIFORM_CURVE", vec![]),
        None => ("B_SPLINE_CURVE_WITH_KNOTS", vec![mults, knots, spec]),
    };
    Ok(match c.weights() {
        None => {
            let mut params = vec![name_of(e)];
            params.extend(bspline);
            params.extend(sub_params);
            b.simple(sub_keyword, params)
        }
        Some(w) => b.complex(vec![
            rec("BOUNDED_CURVE", vec![]),
            rec("B_SPLINE_CURVE", bspline),
            rec(sub_keyword, sub_params),
            rec("CURVE", vec![]),
            rec("GEOMETRIC_REPRESENTATION_ITEM", vec![]),
            rec("RATIONAL_B_SPLINE_CURVE", vec![Parameter::reals(w)]),
            rec("REPRESENTATION_ITEM", vec![name_of(e)]),
        ]),
    })
}

/// Writes one surface; returns its id.
fn surface(
    b: &mut Builder,
    sf: &NurbsSurface,
    e: &Entity,
    scale: f64,
    options: &ExportOptions,
) -> Result<u64, String> {
    let dim = sf.dimension();
    let net = sf.control_points();
    let nu = net.nu();
    let rows: Vec<Parameter<'static>> = (0..nu)
        .map(|i| {
            let ids: Vec<u64> = net
                .row(i)
                .iter()
                .map(|&p| point(b, p, dim, scale))
                .collect();
            Parameter::refs(&ids)
        })
        .collect();
    let du = i64::try_from(sf.degree_u()).map_err(|_| "degree out of range".to_owned())?;
    let dv = i64::try_from(sf.degree_v()).map_err(|_| "degree out of range".to_owned())?;
    let (closed_u, closed_v) = surface_closed(sf);
    let bspline = vec![
        Parameter::Integer(du),
        Parameter::Integer(dv),
        Parameter::List(rows),
        form_param(e),
        Parameter::logical(closed_u),
        Parameter::logical(closed_v),
        Parameter::logical(e.meta.self_intersect.unwrap_or(false)),
    ];
    let subtype = surface_subtype(sf, options);
    let (mu, ku) = knot_lists(sf.knots_u());
    let (mv, kv) = knot_lists(sf.knots_v());
    let fu = knot_form(sf.degree_u(), sf.knots_u());
    let fv = knot_form(sf.degree_v(), sf.knots_v());
    let spec = Parameter::Enumeration(if fu == fv { fu } else { "UNSPECIFIED" });
    let (sub_keyword, sub_params) = match subtype {
        Some(KnotForm::Bezier) => ("BEZIER_SURFACE", vec![]),
        Some(KnotForm::Uniform) => ("UNIFORM_SURFACE", vec![]),
        Some(KnotForm::QuasiUniform) => ("QUASI_UNIFORM_SURFACE", vec![]),
        None => ("B_SPLINE_SURFACE_WITH_KNOTS", vec![mu, mv, ku, kv, spec]),
    };
    Ok(match sf.weights() {
        None => {
            let mut params = vec![name_of(e)];
            params.extend(bspline);
            params.extend(sub_params);
            b.simple(sub_keyword, params)
        }
        Some(w) => {
            let wrows: Vec<Parameter<'static>> =
                (0..nu).map(|i| Parameter::reals(w.row(i))).collect();
            b.complex(vec![
                rec("BOUNDED_SURFACE", vec![]),
                rec("B_SPLINE_SURFACE", bspline),
                rec(sub_keyword, sub_params),
                rec("GEOMETRIC_REPRESENTATION_ITEM", vec![]),
                rec("RATIONAL_B_SPLINE_SURFACE", vec![Parameter::List(wrows)]),
                rec("REPRESENTATION_ITEM", vec![name_of(e)]),
                rec("SURFACE", vec![]),
            ])
        }
    })
}

fn options_variants() -> Vec<ExportOptions> {
    let mut v = Vec::new();
    for (schema, units, implicit, name) in [
        (StepSchema::Ap214, None, false, "sample"),
        (StepSchema::Ap203, Some(LengthUnit::In), true, ""),
        (StepSchema::Ap242, Some(LengthUnit::M), true, "it's"),
    ] {
        v.push(ExportOptions {
            schema,
            units,
            use_implicit_knot_subtypes: implicit,
            timestamp: Some("2026-01-01T00:00:00".to_owned()),
            file_name: name.to_owned(),
            iges_brep: false,
            flatten_assemblies: false,
            cancel: Default::default(),
        });
    }
    v
}

fn assert_same(doc: &Document, options: &ExportOptions, what: &str) {
    let fast = write(doc, options);
    let reference = write_reference(doc, options);
    match (fast, reference) {
        (Ok(a), Ok(b)) => {
            if a != b {
                let at = a
                    .bytes()
                    .zip(b.bytes())
                    .position(|(x, y)| x != y)
                    .unwrap_or(a.len().min(b.len()));
                let from = at.saturating_sub(80);
                panic!(
                    "{what}: outputs differ at byte {at}:\nfast: {:?}\nref:  {:?}",
                    &a[from..(at + 80).min(a.len())],
                    &b[from..(at + 80).min(b.len())]
                );
            }
        }
        (Err(a), Err(b)) => assert_eq!(a.message, b.message, "{what}"),
        (a, b) => panic!("{what}: fast {:?} vs reference {:?}", a.err(), b.err()),
    }
}

#[test]
fn equals_reference_on_every_sample() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("samples/freecad");
    let mut count = 0;
    let mut paths: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| matches!(p.extension().and_then(|e| e.to_str()), Some("step" | "igs")))
        .collect();
    paths.sort();
    for path in paths {
        let bytes = std::fs::read(&path).unwrap();
        let mut doc = crate::exchange::read(&bytes, &ImportOptions::default()).unwrap();
        // The geometry writer's two paths are compared here; a document with topology is
        // written by the topology writer (tests/step_topology.rs checks that one).
        doc.topology = crate::exchange::Topology::default();
        assert!(!doc.entities.is_empty(), "{}", path.display());
        for options in options_variants() {
            assert_same(&doc, &options, &path.display().to_string());
        }
        count += 1;
    }
    assert!(count >= 100, "only {count} samples found");
}

#[test]
fn empty_document_equals_reference() {
    let doc = Document::new(Format::Step, LengthUnit::Mm);
    for options in options_variants() {
        assert_same(&doc, &options, "empty document");
    }
}

/// The generator reaches every case the equivalence test is meant to cover.
#[test]
fn generated_documents_cover_the_cases() {
    let (mut curves2, mut rational_curves, mut curves, mut rational_surfaces, mut surfaces) =
        (0, 0, 0, 0, 0);
    let mut odd = [false; 5];
    for seed in 0..300 {
        for e in random_document(seed, Format::Step).entities {
            let points: Vec<Point3> = match &e.geometry {
                Geometry::Curve(c) => {
                    curves += 1;
                    curves2 += usize::from(c.dimension() == 2);
                    rational_curves += usize::from(c.is_rational());
                    c.control_points().to_vec()
                }
                Geometry::Surface(s) => {
                    surfaces += 1;
                    rational_surfaces += usize::from(s.is_rational());
                    s.control_points().as_slice().to_vec()
                }
            };
            for x in points.iter().flatten() {
                odd[0] |= *x == 0.0 && x.is_sign_negative();
                odd[1] |= *x == 1e-300;
                odd[2] |= x.abs() == 1e300;
                odd[3] |= x.is_subnormal();
                odd[4] |= *x == 0.5 || *x == -0.25;
            }
        }
    }
    for (what, n) in [
        ("2-D curves", curves2),
        ("rational curves", rational_curves),
        ("polynomial curves", curves - rational_curves),
        ("rational surfaces", rational_surfaces),
        ("polynomial surfaces", surfaces - rational_surfaces),
    ] {
        assert!(n >= 20, "only {n} {what}");
    }
    assert_eq!(odd, [true; 5]);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(400))]
    #[test]
    fn equals_reference_on_random_documents(seed in any::<u64>(), variant in 0usize..3) {
        let doc = random_document(seed, Format::Step);
        let options = &options_variants()[variant];
        assert_same(&doc, options, &format!("seed {seed}"));
    }
}
