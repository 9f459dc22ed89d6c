use super::*;
use crate::exchange::test_documents::random_document;
use crate::exchange::{Format, ImportOptions};
use crate::nurbs::Point3;
use proptest::prelude::*;

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
        let doc = crate::exchange::read(&bytes, &ImportOptions::default()).unwrap();
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
