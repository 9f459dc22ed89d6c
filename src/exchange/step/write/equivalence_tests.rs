use super::*;
use crate::exchange::{Format, ImportOptions, Meta, Source};
use crate::nurbs::{Grid, Point3};
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

/// A small deterministic PRNG for the generated documents (proptest draws the seed).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        self.0 >> 11
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
    fn unit(&mut self) -> f64 {
        self.next() as f64 / (1u64 << 53) as f64
    }
    /// A coordinate: full precision mostly, odd values often.
    fn coord(&mut self) -> f64 {
        const ODD: [f64; 14] = [
            0.0,
            -0.0,
            1e-300,
            -1e300,
            1e300,
            5e-324,
            2.2250738585072e-310,
            0.5,
            -0.25,
            1e16,
            1e-5,
            9.5367431640625e-7,
            123_456_789.0,
            -3.0,
        ];
        match self.below(4) {
            0 => ODD[self.below(ODD.len())],
            1 => (self.unit() * 2000.0 - 1000.0).round() / 8.0,
            _ => self.unit() * 400.0 - 200.0,
        }
    }
}

fn knots(rng: &mut Rng, p: usize, n: usize) -> Vec<f64> {
    let m = n + p + 1;
    let scale = [1.0, 1e-300, 1e300, 7.3, 0.1][rng.below(5)];
    match rng.below(4) {
        // uniform (UNIFORM_ subtype when the scale is 1)
        0 => (0..m).map(|i| i as f64 * scale).collect(),
        // clamped with integer interior (QUASI_UNIFORM_, or BEZIER_ when n = p + 1)
        1 => {
            let spans = n - p;
            let mut k = vec![0.0; p + 1];
            k.extend((1..spans).map(|i| i as f64 * scale));
            k.extend(std::iter::repeat_n(spans as f64 * scale, p + 1));
            k
        }
        // clamped, random interior
        _ => {
            let mut inner: Vec<f64> = (1..n - p).map(|_| rng.unit() * scale).collect();
            inner.sort_by(f64::total_cmp);
            let mut k = vec![0.0; p + 1];
            k.extend(inner);
            k.extend(std::iter::repeat_n(scale, p + 1));
            k
        }
    }
}

fn weights(rng: &mut Rng, n: usize) -> Option<Vec<f64>> {
    match rng.below(3) {
        0 => None,
        1 => Some(vec![[1.0, 0.5, 2.0][rng.below(3)]; n]),
        _ => Some((0..n).map(|_| 0.25 + rng.unit() * 4.0).collect()),
    }
}

fn meta(rng: &mut Rng) -> Meta {
    Meta {
        name: [
            None,
            Some(""),
            Some("edge 1"),
            Some("it's"),
            Some("\u{fc}ber"),
        ][rng.below(5)]
        .map(str::to_owned),
        form: [
            None,
            Some("circular_arc"),
            Some("PLANE_SURF"),
            Some("bogus"),
        ][rng.below(4)]
        .map(str::to_owned),
        self_intersect: [None, Some(false), Some(true)][rng.below(3)],
        ..Meta::default()
    }
}

pub(super) fn random_document(seed: u64) -> Document {
    let mut rng = Rng(seed);
    let mut doc = Document::new(Format::Step, LengthUnit::Mm);
    let count = 1 + rng.below(5);
    for i in 0..count {
        let geometry = if rng.below(3) == 0 {
            let (pu, pv) = (1 + rng.below(3), 1 + rng.below(3));
            let (nu, nv) = (pu + 1 + rng.below(4), pv + 1 + rng.below(4));
            let (ku, kv) = (knots(&mut rng, pu, nu), knots(&mut rng, pv, nv));
            let pts = Grid::from_fn(nu, nv, |_, _| [rng.coord(), rng.coord(), rng.coord()]);
            let w = weights(&mut rng, nu * nv).map(|w| Grid::from_fn(nu, nv, |i, j| w[i * nv + j]));
            NurbsSurface::new(pu, pv, ku, kv, pts, w)
                .ok()
                .map(Geometry::Surface)
        } else {
            let p = 1 + rng.below(4);
            let n = p + 1 + rng.below(6);
            let k = knots(&mut rng, p, n);
            let dim = 2 + rng.below(2);
            let pts = (0..n)
                .map(|_| {
                    let z = if dim == 2 { 0.0 } else { rng.coord() };
                    [rng.coord(), rng.coord(), z]
                })
                .collect();
            let w = weights(&mut rng, n);
            NurbsCurve::with_dimension(p, k, pts, w, dim)
                .ok()
                .map(Geometry::Curve)
        };
        let Some(geometry) = geometry else { continue };
        doc.entities.push(Entity {
            id: format!("E{i}"),
            geometry,
            source: Source::default(),
            meta: meta(&mut rng),
        });
    }
    doc
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
        for e in random_document(seed).entities {
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
        let doc = random_document(seed);
        let options = &options_variants()[variant];
        assert_same(&doc, options, &format!("seed {seed}"));
    }
}
